#!/usr/bin/env bash
# Phone localisation (Kudo and Miura, section IV) on the IPIN 2023 Track 3 training routes: a
# Gaussian-process Wi-Fi map from repetitions 01 and 02 of a route (ground-truth positions),
# then every repetition 03 and 04 (another phone) located in it by the particle filter, with the
# paper's sum likelihood (eq. 13) and the product alternative, beside the weighted 3-NN
# fingerprint answer per scan on the same map scans, and the sum likelihood on a map made from a
# RatSLAM run of repetitions 01 and 02 instead (configs/ipin2023-wifi-compass.toml; positions from
# the run's final map, scored after its alignment onto the truth). Errors in metres at the scans
# with ground truth; a Markdown table (docs/results/wifi-sequence.md). The last columns: the sum likelihood with
# [particle_filter] online_rssi_offset = true (the located phone's offset to the map's scans
# estimated from its own scans) and the offset it removed at the end (dB).
# Usage: scripts/ipin_locate_table.sh [DATA_DIR] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data/ipin2023-t3}
out=${2:-out/ipin-locate-table}
bin=./build/apps/ratslam
mkdir -p "$out"
printf '[particle_filter]\nlikelihood = "product"\n' > "$out/product.toml"
printf '[particle_filter]\nonline_rssi_offset = true\n' > "$out/online.toml"
echo "| route | phone log | scans with truth | sum (eq. 13) mean / median / p75 / p90 m | product mean / median / p75 / p90 m | 3-NN mean / median / p75 / p90 m | sum on a run's map, mean / median m | sum, online offset: mean / median / p75 / p90 m | offset dB |"
echo "|---|---|---|---|---|---|---|---|---|"
for route in 01 02 03 21 22 23; do
  log() { echo "$data/IPIN2023_T3_TrainingTrial${route}_repetition$1.txt"; }
  "$bin" wifi-map --overwrite --data "$(log 01)" --data "$(log 02)" --out "$out/route$route.wifimap" > /dev/null
  "$bin" replay --quiet --overwrite --config configs/ipin2023-wifi-compass.toml --data "$(log 01)" \
    --data "$(log 02)" --out "$out/route$route-run" > /dev/null
  "$bin" wifi-map --overwrite --run "$out/route$route-run" --data "$(log 01)" --data "$(log 02)" \
    --out "$out/route$route-run.wifimap" > /dev/null
  for rep in 03 04; do
    "$bin" locate --quiet --overwrite --wifi-map "$out/route$route.wifimap" --data "$(log $rep)" \
      --out "$out/route$route-rep$rep-sum"
    "$bin" locate --quiet --overwrite --config "$out/product.toml" --wifi-map "$out/route$route.wifimap" \
      --data "$(log $rep)" --out "$out/route$route-rep$rep-product"
    "$bin" locate --quiet --overwrite --wifi-map "$out/route$route-run.wifimap" --data "$(log $rep)" \
      --out "$out/route$route-rep$rep-run"
    "$bin" locate --quiet --overwrite --config "$out/online.toml" --wifi-map "$out/route$route.wifimap" \
      --data "$(log $rep)" --out "$out/route$route-rep$rep-online"
    /usr/bin/python3 - "$out/route$route-rep$rep-sum/summary.json" \
      "$out/route$route-rep$rep-product/summary.json" "$out/route$route-rep$rep-run/summary.json" \
      "$out/route$route-rep$rep-online/summary.json" "$route" "$rep" <<'PY'
import json, sys
s, p, r, o = (json.load(open(f)) for f in sys.argv[1:5])
def row(j):
    if not j.get("count"):
        return "-"
    return " / ".join(f"{j[k]:.1f}" for k in ("mean_error_m", "median_error_m", "p75_error_m", "p90_error_m"))
run = f"{r['mean_error_m']:.1f} / {r['median_error_m']:.1f}" if r.get("count") else "-"
print(f"| {sys.argv[5]} | rep{sys.argv[6]} | {s.get('count', 0)} | {row(s)} | {row(p)} | "
      f"{row(s.get('knn_baseline', {}))} | {run} | {row(o)} | {o['rssi_offset_db']:.1f} |")
PY
  done
done
