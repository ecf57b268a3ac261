#!/usr/bin/env bash
# The IPIN table of docs/results/ipin.md: Wi-Fi RatSLAM on the IPIN 2023 Track 3 training logs (the four
# repetitions of each route as one multi-session run, Wi-Fi alone and with the compass; two single
# walks; route 51 with and without the barometer), with the shipped configs and, for comparison,
# without the online RSSI offset ([fused] online_rssi_offset = false), and as they were before those
# two changes: also OpenRatSLAM's frame memory ([local_view] memory line removed) and then also
# the calibration gesture counted as steps ([pdr] min_orientation_steadiness = 0).
# PDR-only is the dead-reckoning error of the same runs (odometry_ate_m).
# Usage: scripts/ipin_table.sh [DATA_DIR] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data/ipin2023-t3}
out=${2:-out/ipin-table}
bin=./build/apps/ratslam
mkdir -p "$out"
for mode in wifi wifi-compass; do
  sed 's/^use_barometer = true$/use_barometer = false/' "configs/ipin2023-$mode.toml" \
    > "$out/nobaro-$mode.toml"
done
old_configs() {  # config name: without the offset, then frame memory, then the gesture counted
  sed 's/^online_rssi_offset = true$/online_rssi_offset = false/' "$1" > "$out/$2-nooffset.toml"
  sed '/^memory = /d' "$out/$2-nooffset.toml" > "$out/$2-frames.toml"
  printf '\n[pdr]\nmin_orientation_steadiness = 0\n' | cat "$out/$2-frames.toml" - \
    > "$out/$2-gesture.toml"
}
run() {  # config dir args...
  local config=$1 dir=$2; shift 2
  "$bin" replay --quiet --overwrite --config "$config" "$@" --out "$dir" > /dev/null
}
row() {  # name mode label past(yes/no: the history columns) args...
  local name=$1 mode=$2 label=$3 past=$4 shipped=configs/ipin2023-$2.toml; shift 4
  [ "$name" = "${name%nobaro}" ] || shipped=$out/nobaro-$mode.toml
  run "$shipped" "$out/$name-$mode" "$@"
  local dirs=("$out/$name-$mode")
  if [ "$past" = yes ]; then
    old_configs "$shipped" "$name-$mode"
    run "$out/$name-$mode-nooffset.toml" "$out/$name-$mode-nooffset" "$@"
    run "$out/$name-$mode-frames.toml" "$out/$name-$mode-frames" "$@"
    run "$out/$name-$mode-gesture.toml" "$out/$name-$mode-gesture" "$@"
    dirs+=("$out/$name-$mode-nooffset" "$out/$name-$mode-frames" "$out/$name-$mode-gesture")
  fi
  /usr/bin/python3 - "$label" "$mode" "${dirs[@]}" <<'PY'
import json, sys
label, mode, dirs = sys.argv[1], sys.argv[2], sys.argv[3:]
s = [json.load(open(d + "/summary.json")) for d in dirs]
f = lambda v: f"{v:.2f}"
j = s[0]
matches = str(j["matches"])
if j.get("floor_unverified_matches"): matches += f" ({j['floor_unverified_matches']} unverified)"
cells = [label, "Wi-Fi + compass" if mode == "wifi-compass" else "Wi-Fi", matches,
         str(j["view_injections"]), f(j.get("match_rate_within_m", {}).get("5", 0)),
         str(j["floor_mistakes"]), f(j["map_ate_m"]), f(j["odometry_ate_m"])]
if len(s) == 4:
    cells += [f(s[1].get("match_rate_within_m", {}).get("5", 0)), f(s[1]["map_ate_m"]),
              f(s[2]["map_ate_m"]), str(s[2]["view_injections"]), f(s[3]["map_ate_m"]),
              f(s[3]["odometry_ate_m"])]
else:
    cells += ["-"] * 6
print("| " + " | ".join(cells) + " |")
PY
}
echo "| run | mode | matches | injections | <=5 m | floor mistakes | map ATE m | PDR-only ATE m | <=5 m, no RSSI offset | map ATE, no RSSI offset | map ATE, frame memory | injections, frame memory | map ATE, frame memory and gesture counted | PDR-only, gesture counted |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for route in 01 02 03 21 22 23; do
  args=()
  for rep in 01 02 03 04; do args+=(--data "$data/IPIN2023_T3_TrainingTrial${route}_repetition${rep}.txt"); done
  for mode in wifi wifi-compass; do
    row "route$route-all4" "$mode" "route$route all4" yes "${args[@]}"
  done
done
for route in 01 02; do
  row "route$route-rep01" wifi-compass "route$route rep01" yes \
    --data "$data/IPIN2023_T3_TrainingTrial${route}_repetition01.txt"
done
route51=(--data "$data/IPIN2023_T3_TrainingTrial51_repetition02.txt")
row route51-rep02 wifi-compass "route51 rep02 (3 floors), barometer" no "${route51[@]}"
row route51-rep02-nobaro wifi-compass "route51 rep02 (3 floors), no barometer" yes "${route51[@]}"
