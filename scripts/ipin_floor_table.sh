#!/usr/bin/env bash
# Floors in matching ([barometer] use_barometer) on the IPIN 2023 Track 3 training logs, with and
# without the barometer, for the fused (Wi-Fi + compass) and FABMAP (Wi-Fi) front ends, as a
# Markdown table: route 51 (floors 0, -1, -2) alone, and multi-session
# runs mixing it with routes 21 (floor -2) and 01 (floor 0) in two orders, so that later walks
# start on another floor than the first. Floor mistakes and match rates count matches whose two
# ends have a known ground-truth floor; "unverified" are matches with an end between two points
# on different floors (the stairs). "offsets" are the per-session floor offsets the run found
# (truth: route 21 is two floors below route 51's start, route 01 level with it).
# Usage: scripts/ipin_floor_table.sh [DATA_DIR] [OUT_DIR]   (about 10 s)
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data/ipin2023-t3}
out=${2:-out/ipin-floor-table}
bin=./build/apps/ratslam
py=/usr/bin/python3
mkdir -p "$out"
row() {  # front end, name, runs...
  local front=$1 name=$2; shift 2
  local args=()
  for r in "$@"; do args+=(--data "$data/IPIN2023_T3_TrainingTrial${r%-*}_repetition${r#*-}.txt"); done
  for barometer in without with; do
    local config=configs/ipin2023-$front.toml
    if [ "$barometer" = without ]; then
      config=$out/$front-without.toml
      sed 's/^use_barometer = true/use_barometer = false/' "configs/ipin2023-$front.toml" > "$config"
    fi
    local dir="$out/$front-$name-$barometer"
    "$bin" replay --quiet --overwrite --config "$config" "${args[@]}" --out "$dir" > /dev/null
    "$py" - "$dir/summary.json" "$name" "$barometer" "$front" <<'PY'
import json, sys
j = json.load(open(sys.argv[1])); r = j.get("match_rate_within_m", {}); b = j.get("barometer", {})
offsets = " ".join(str(o) for o in b.get("session_floor_offsets", [])) or "-"
print(f"| {sys.argv[4]} | {sys.argv[2]} | {sys.argv[3]} | {j['templates']} | {j['matches']} | "
      f"{j['floor_unverified_matches']} | {j['floor_mistakes']} | {r.get('5', 0):.2f} | "
      f"{j.get('cross_session_matches', '-')} | {j['map_ate_m']:.2f} | {j['odometry_ate_m']:.2f} | "
      f"{b.get('frames_floor_unknown', '-')} | {offsets} |")
PY
  done
}
echo "| config | run | barometer | templates | matches | unverified | floor mistakes | <=5 m | cross-session | map ATE m | PDR-only ATE m | frames on stairs | offsets |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for front in wifi-compass fabmap-wifi; do
  row $front "51-02" 51-02
  row $front "51-02 21-01 21-02 01-01 01-02" 51-02 21-01 21-02 01-01 01-02
  row $front "21-01 51-02 01-01 21-02 01-02" 21-01 51-02 01-01 21-02 01-02
done
