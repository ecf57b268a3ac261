#!/usr/bin/env bash
# Localisation on a saved map from real phone logs (IPIN 2023 Track 3 training routes): repetition
# 01 of a route is mapped with the config (`replay --save-map`), then repetitions 02 (the same
# phone), 03 and 04 (another phone) are each localised on that map without changing it
# (`replay --load-map --localise`). Per log: the share of frames lost (no recognised place, or
# dead reckoned more than lost_after_m from it), relocalisations, and the median error of the
# frames not lost (after the rigid fit onto the truth that summary.json describes). Beside it, in
# the same run, the weighted 3-NN fingerprint answer per scan on a Wi-Fi map of repetition 01's
# scans at their true positions (`locate`'s knn_baseline): a map with perfect positions, so a
# hard baseline for the error, and one that never reports itself lost.
# Prints a Markdown table (docs/cli.md).
# Usage: scripts/ipin_localise_table.sh [config] [out dir]
set -euo pipefail
cd "$(dirname "$0")/.."
config=${1:-configs/ipin2023-wifi-compass.toml}
out=${2:-out/ipin-localise-table}
data=../shared/data/ipin2023-t3
bin=./build/apps/ratslam
mkdir -p "$out"
echo "| route | log | map ATE m | frames | lost | relocalisations | median error m | 3-NN median error m |"
echo "|---|---|---|---|---|---|---|---|"
for route in 01 02 03 21 22 23; do
  log() { echo "$data/IPIN2023_T3_TrainingTrial${route}_repetition$1.txt"; }
  "$bin" replay --quiet --overwrite --config "$config" --data "$(log 01)" \
    --out "$out/route$route-map" --save-map "$out/route$route.map" > /dev/null
  "$bin" wifi-map --overwrite --data "$(log 01)" --out "$out/route$route.wifimap" > /dev/null
  for rep in 02 03 04; do
    "$bin" replay --quiet --overwrite --config "$config" --data "$(log $rep)" \
      --load-map "$out/route$route.map" --localise --out "$out/route$route-rep$rep" > /dev/null
    "$bin" locate --quiet --overwrite --wifi-map "$out/route$route.wifimap" --data "$(log $rep)" \
      --out "$out/route$route-rep$rep-locate" > /dev/null
    /usr/bin/python3 - "$out/route$route-map/summary.json" "$out/route$route-rep$rep/summary.json" \
      "$out/route$route-rep$rep-locate/summary.json" "$route" "$rep" <<'PY'
import json, sys
m, r, k = (json.load(open(f)) for f in sys.argv[1:4])
l = r["localisation"]
knn = k.get("knn_baseline", {})
med = f"{l['median_error_m']:.1f}" if "median_error_m" in l else "-"
kmed = f"{knn['median_error_m']:.1f}" if knn.get("count") else "-"
print(f"| {sys.argv[4]} | rep{sys.argv[5]} | {m.get('map_ate_m', float('nan')):.2f} | {l['frames']} | "
      f"{100 * l['lost_fraction']:.0f} % | {l['relocalisations']} | {med} | {kmed} |")
PY
  done
done
