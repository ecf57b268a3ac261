#!/usr/bin/env bash
# Runs Wi-Fi RatSLAM on every IPIN 2023 Track 3 training log (single walks and all repetitions of
# each route as one multi-session run), with and without the compass, and prints a Markdown
# table. PDR-only is the dead-reckoning error of the same runs (odometry_ate_m).
# Usage: scripts/ipin_table.sh [DATA_DIR] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data/ipin2023-t3}
out=${2:-out/ipin-table}
bin=./build/apps/ratslam
mkdir -p "$out"
row() {  # name mode args...
  local name=$1 mode=$2; shift 2
  local dir="$out/$name-$mode"
  "$bin" replay --quiet --overwrite --config "configs/ipin2023-$mode.toml" "$@" --out "$dir" > /dev/null
  python3 - "$dir/summary.json" "$name" "$mode" <<'PY'
import json, sys
j = json.load(open(sys.argv[1])); r = j.get("match_rate_within_m", {})
f = lambda v: f"{v:.2f}"
print(f"| {sys.argv[2]} | {sys.argv[3]} | {j['frames']} | {j['templates']} | {j['matches']} | "
      f"{f(r.get('2',0))} | {f(r.get('5',0))} | {f(r.get('10',0))} | {f(r.get('20',0))} | "
      f"{j['floor_mistakes']} | {f(j['map_ate_m'])} | {f(j['odometry_ate_m'])} |")
PY
}
echo "| run | mode | frames | templates | matches | <=2 m | <=5 m | <=10 m | <=20 m | floor mistakes | map ATE m | PDR-only ATE m |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
for route in 01 02 03 21 22 23; do
  for mode in wifi wifi-compass; do
    row "route$route-rep01" "$mode" --data "$data/IPIN2023_T3_TrainingTrial${route}_repetition01.txt"
    args=()
    for rep in 01 02 03 04; do args+=(--data "$data/IPIN2023_T3_TrainingTrial${route}_repetition${rep}.txt"); done
    row "route$route-all4" "$mode" "${args[@]}"
  done
done
for mode in wifi wifi-compass; do
  row "route51-rep02" "$mode" --data "$data/IPIN2023_T3_TrainingTrial51_repetition02.txt"
done
