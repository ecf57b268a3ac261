#!/usr/bin/env bash
# Phone localisation (Kudo and Miura, section IV) on the IPIN 2023 Track 3 training routes: a
# Gaussian-process Wi-Fi map from repetitions 01 and 02 of a route (ground-truth positions),
# then every repetition 03 and 04 (another phone) located in it by the particle filter, with the
# paper's sum likelihood (eq. 13) and the product alternative, beside the weighted 3-NN
# fingerprint answer per scan on the same map scans. Errors in metres at the scans with ground
# truth; a Markdown table (the README's).
# Usage: scripts/ipin_locate_table.sh [DATA_DIR] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data/ipin2023-t3}
out=${2:-out/ipin-locate-table}
bin=./build/apps/ratslam
mkdir -p "$out"
printf '[particle_filter]\nlikelihood = "product"\n' > "$out/product.toml"
echo "| route | phone log | scans with truth | sum (eq. 13) mean / median / p75 / p90 m | product mean / median / p75 / p90 m | 3-NN mean / median / p75 / p90 m |"
echo "|---|---|---|---|---|---|"
for route in 01 02 03 21 22 23; do
  log() { echo "$data/IPIN2023_T3_TrainingTrial${route}_repetition$1.txt"; }
  "$bin" wifi-map --data "$(log 01)" --data "$(log 02)" --out "$out/route$route.wifimap" > /dev/null
  for rep in 03 04; do
    "$bin" locate --quiet --wifi-map "$out/route$route.wifimap" --data "$(log $rep)" \
      --out "$out/route$route-rep$rep-sum"
    "$bin" locate --quiet --config "$out/product.toml" --wifi-map "$out/route$route.wifimap" \
      --data "$(log $rep)" --out "$out/route$route-rep$rep-product"
    /usr/bin/python3 - "$out/route$route-rep$rep-sum/summary.json" \
      "$out/route$route-rep$rep-product/summary.json" "$route" "$rep" <<'PY'
import json, sys
s, p = (json.load(open(f)) for f in sys.argv[1:3])
def row(j):
    if not j.get("count"):
        return "-"
    return " / ".join(f"{j[k]:.1f}" for k in ("mean_error_m", "median_error_m", "p75_error_m", "p90_error_m"))
print(f"| {sys.argv[3]} | rep{sys.argv[4]} | {s.get('count', 0)} | {row(s)} | {row(p)} | {row(s.get('knn_baseline', {}))} |")
PY
  done
done
