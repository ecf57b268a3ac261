#!/usr/bin/env bash
# [wifi] unmapped_aps_neutral on the IPIN 2023 Track 3 training logs: every repetition of a route
# in one multi-session run with configs/ipin2023-wifi-compass.toml, without and with the option,
# as a Markdown table (templates, matches, share within 5 m, cross-session matches, floor
# mistakes, map and dead-reckoning ATE).
# Usage: scripts/ipin_unmapped_aps.sh [DATA_DIR] [OUT_DIR]   (about 5 s)
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data/ipin2023-t3}
out=${2:-out/ipin-unmapped-aps}
bin=./build/apps/ratslam
mkdir -p "$out"
cp configs/ipin2023-wifi-compass.toml "$out/false.toml"
/usr/bin/python3 - configs/ipin2023-wifi-compass.toml > "$out/true.toml" <<'PY'
import sys
s = open(sys.argv[1]).read()
if "[wifi]\n" in s:
    s = s.replace("[wifi]\n", "[wifi]\nunmapped_aps_neutral = true\n", 1)
else:
    s += "\n[wifi]\nunmapped_aps_neutral = true\n"
print(s, end="")
PY
echo "| route | unmapped_aps_neutral | templates | matches | <=5 m | cross-session | floor mistakes | map ATE m | PDR ATE m |"
echo "|---|---|---|---|---|---|---|---|---|"
for route in 01 02 03 21 22 23 51; do
  args=()
  for f in "$data"/IPIN2023_T3_TrainingTrial${route}_repetition0*.txt; do args+=(--data "$f"); done
  [[ ${#args[@]} -gt 0 ]] || continue
  for neutral in false true; do
    dir="$out/$route-$neutral"
    "$bin" replay --quiet --overwrite --config "$out/$neutral.toml" "${args[@]}" --out "$dir" > /dev/null
    /usr/bin/python3 - "$dir/summary.json" "$route" "$neutral" <<'PY'
import json, sys
j = json.load(open(sys.argv[1])); r = j.get("match_rate_within_m", {})
print(f"| {sys.argv[2]} | {sys.argv[3]} | {j['templates']} | {j['matches']} | {r.get('5', 0):.2f} | "
      f"{j.get('cross_session_matches', '-')} | {j['floor_mistakes']} | {j['map_ate_m']:.2f} | "
      f"{j['odometry_ate_m']:.2f} |")
PY
  done
done
