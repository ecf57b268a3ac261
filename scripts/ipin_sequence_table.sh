#!/usr/bin/env bash
# Wi-Fi sequence loop closure (Kudo and Miura, section III) on every IPIN 2023 Track 3 training
# route: single walks and all repetitions as one multi-session run, in four modes, as a Markdown
# table (docs/results/wifi-sequence.md). Modes:
#   pdr+compass  front end none, no loop closure: dead reckoning with compass facings (baseline)
#   seq alone    configs/ipin2023-wifi-sequence-alone.toml
#   b_out        configs/ipin2023-wifi-compass.toml (RatSLAM's own Wi-Fi loop closure)
#   b_out+seq    configs/ipin2023-wifi-sequence.toml
# Correspondence errors are the paper's table I: verified pairs of accepted loops, mean/std/max in
# metres (true positions of the two scans) and in poses (to the truly nearest scan of the same
# past visit); "raw" is every DP pair before verification.
# Usage: scripts/ipin_sequence_table.sh [DATA_DIR] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data/ipin2023-t3}
out=${2:-out/ipin-sequence-table}
bin=./build/apps/ratslam
mkdir -p "$out"
sed 's/^enabled = true/enabled = false/' configs/ipin2023-wifi-sequence-alone.toml > "$out/pdr-compass.toml"
row() {  # name mode config args...
  local name=$1 mode=$2 config=$3; shift 3
  local dir="$out/$name-${mode//[+ ]/-}"
  "$bin" replay --quiet --overwrite --config "$config" "$@" --out "$dir" > /dev/null
  /usr/bin/python3 - "$dir/summary.json" "$name" "$mode" <<'PY'
import json, sys
j = json.load(open(sys.argv[1])); w = j.get("wifi_sequence")
def stats(d):
    return f"{d['mean']:.2f} / {d['std']:.2f} / {d['max']:.1f}" if d and d["count"] else "-"
if w and w["loops_matched"]:
    loops = f"{w['loops_accepted']}/{w['loops_matched']}"
    links, err_m, err_p = w["links"], stats(w.get("verified_error_m")), stats(w.get("verified_error_poses"))
    raw = f"{w['unverified_error_m']['mean']:.2f}" if w.get("unverified_error_m", {}).get("count") else "-"
else:
    loops, links, err_m, err_p, raw = ("0" if w else "-"), (0 if w else "-"), "-", "-", "-"
print(f"| {sys.argv[2]} | {sys.argv[3]} | {loops} | {links} | {j['loop_closures']} | {err_m} | "
      f"{err_p} | {raw} | {j['map_ate_m']:.2f} | {j['odometry_ate_m']:.2f} |")
PY
}
modes() {  # name args...
  local name=$1; shift
  row "$name" "pdr+compass" "$out/pdr-compass.toml" "$@"
  row "$name" "seq alone" configs/ipin2023-wifi-sequence-alone.toml "$@"
  row "$name" "b_out" configs/ipin2023-wifi-compass.toml "$@"
  row "$name" "b_out+seq" configs/ipin2023-wifi-sequence.toml "$@"
}
echo "| run | mode | loops accepted/matched | sequence links | RatSLAM loop closures | verified error m (mean / std / max) | verified error poses (mean / std / max) | raw DP error m (mean) | map ATE m | PDR-only ATE m |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for route in 01 02 03 21 22 23; do
  modes "route$route-rep01" --data "$data/IPIN2023_T3_TrainingTrial${route}_repetition01.txt"
  args=()
  for rep in 01 02 03 04; do args+=(--data "$data/IPIN2023_T3_TrainingTrial${route}_repetition${rep}.txt"); done
  modes "route$route-all4" "${args[@]}"
done
modes "route51-rep02" --data "$data/IPIN2023_T3_TrainingTrial51_repetition02.txt"
