#!/usr/bin/env bash
# Phone localisation (Kudo and Miura, section IV) across the five floors of Microsoft ILC 2.0
# site 1: one Gaussian-process Wi-Fi map from walks 2-12 of every floor (ground-truth
# positions), then walk 1 of each floor located in it by the particle filter, beside the weighted
# 3-NN fingerprint answer on the same map scans. The filter must also find the floor. Errors in
# metres at the scans with ground truth on the right floor; a Markdown table.
# Usage: scripts/msft_locate_table.sh [DATA_DIR] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data/msft-ilc20-site1}
out=${2:-out/msft-locate-table}
bin=./build/apps/ratslam
floors=(B1 F1 F2 F3 F4)
mkdir -p "$out"
map_args=()
for f in "${floors[@]}"; do
  mapfile -t walks < <(ls "$data/$f/path_data_files" | sort)
  for w in "${walks[@]:1}"; do map_args+=(--data "$data/$f/path_data_files/$w"); done
done
"$bin" wifi-map --overwrite "${map_args[@]}" --out "$out/site1.wifimap" > "$out/site1-wifimap.json"
echo "| floor | walk | scans (with truth) | filter mean / median / p90 m (wrong floor) | 3-NN mean / median / p90 m (wrong floor) |"
echo "|---|---|---|---|---|"
for f in "${floors[@]}"; do
  w=$(ls "$data/$f/path_data_files" | sort | head -1)
  "$bin" locate --quiet --overwrite --wifi-map "$out/site1.wifimap" --data "$data/$f/path_data_files/$w" \
    --out "$out/$f"
  /usr/bin/python3 - "$out/$f/summary.json" "$f" "$w" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
def row(x):
    if not x.get("count"):
        return f"- ({x.get('wrong_floor', 0)})"
    return " / ".join(f"{x[k]:.1f}" for k in ("mean_error_m", "median_error_m", "p90_error_m")) + f" ({x['wrong_floor']})"
n = j.get("count", 0) + j.get("wrong_floor", 0)
print(f"| {sys.argv[2]} | {sys.argv[3][:8]} | {j['scans']} ({n}) | {row(j)} | {row(j['knn_baseline'])} |")
PY
done
