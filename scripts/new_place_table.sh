#!/usr/bin/env bash
# The new-place decision on queries near the map and far from it, as a
# Markdown table: Wi-Fi-only FABMAP with its own arg-max and with the threshold learnt from the
# map's sessions ([evaluation] calibrate_new_place) by each new_place_rule, beside the k-NN and
# eq. 6 fingerprint baselines of the same run, on the Microsoft walks (split by walk) and on
# UJIIndoorLoc split by user and phone (no pair on both sides) and by node. "near": a map place
# on the query's floor within 5 m; "far": none within 10 m.
# Percentages of all queries, or of the group.
# Usage: scripts/new_place_table.sh [DATA_DIR] [OUT_DIR]   (about 50 s)
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data}
out=${2:-out/new-place-table}
bin=./build/apps/ratslam
mkdir -p "$out"
echo "| data | method | within 5 m | rejected | floor mistakes | near: queries | rejected | floor mistakes | far: queries | rejected | floor mistakes |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
run() {  # name, base config, data path, sed edit of the config (or "")
  local name=$1 base=$2 path=$3 edit=$4
  for rule in none near_recall youden; do
    local dir="$out/$name-$rule" calibrate=true
    [[ $rule == none ]] && calibrate=false
    mkdir -p "$dir"
    local edits=(-e "/^calibrate_new_place/d" -e "/^new_place_rule/d")
    [[ -n $edit ]] && edits+=(-e "$edit")
    sed "${edits[@]}" "$base" > "$dir/input.toml"
    sed -i "s/^\[evaluation\]/[evaluation]\ncalibrate_new_place = $calibrate\nnew_place_rule = \"$rule\"/" \
      "$dir/input.toml"
    [[ $rule == none ]] && sed -i "/^new_place_rule/d" "$dir/input.toml"
    "$bin" evaluate --quiet --overwrite --config "$dir/input.toml" --map "$path" --query "$path" \
      --out "$dir" > /dev/null
    /usr/bin/python3 - "$dir/evaluation.json" "$name" "$rule" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
p = lambda x: f"{100 * x:.1f}"
label = {"none": "FABMAP, arg-max", "near_recall": "FABMAP, learnt threshold (near recall 0.95)",
         "youden": "FABMAP, learnt threshold (Youden's J)"}[sys.argv[3]]
methods = [(label, j)]
if sys.argv[3] == "none":
    methods += [(f"{k} (baseline)", b) for k, b in j["baselines"].items()]
for name, m in methods:
    d = m["by_map_distance"]
    print(f"| {sys.argv[2]} | {name} | {p(m['correct_within_m']['5'])} | {p(m['rejection_rate'])} | "
          f"{p(m['floor_mistake_rate'])} | {d['near']['queries']} | {p(d['near']['rejection_rate'])} | "
          f"{p(d['near']['floor_mistake_rate'])} | {d['far']['queries']} | {p(d['far']['rejection_rate'])} | "
          f"{p(d['far']['floor_mistake_rate'])} |")
PY
  done
}
run "Microsoft site 1" configs/msft-ilc20-wifi.toml "$data/msft-ilc20-site1" ""
run "UJIIndoorLoc by user" configs/ujiindoorloc-wifi-by-user.toml \
  "$data/ujiindoorloc/trainingData.csv" ""
run "UJIIndoorLoc by node" configs/ujiindoorloc-wifi.toml "$data/ujiindoorloc/trainingData.csv" ""
