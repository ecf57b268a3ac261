#!/usr/bin/env bash
# The fusion paper's table 5 layout on real data: Wi-Fi-only FABMAP for b in {1,4,8,12,16,20}
# words per access point, exclusive and incremental, on UJIIndoorLoc and the Microsoft walks.
# Prints a markdown table per data set. Usage: scripts/fabmap_table.sh [build dir] [out dir]
set -euo pipefail
build=${1:-build}
out=${2:-out/fabmap-table}
data=../shared/data
mkdir -p "$out"
run_set() {  # name base-config data-path
  local name=$1 base=$2 path=$3
  echo "### $name"
  echo
  echo "| b | encoding | correct 2 m | 5 m | 10 m | 20 m | misplaced 2 m | 5 m | 10 m | 20 m | rejected | floor mistakes |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
  for b in 1 4 8 12 16 20; do
    for enc in exclusive incremental; do
      if [[ $b == 1 && $enc == incremental ]]; then continue; fi  # b = 1: the same words
      local dir="$out/$name-b$b-$enc"
      mkdir -p "$dir"
      # FABMAP's own arg-max decides, as in the paper (the new-place calibration has its own
      # table: scripts/new_place_table.sh).
      sed -e "s/^bins = .*/bins = $b/" -e "s/^encoding = .*/encoding = \"$enc\"/" \
        -e "s/^calibrate_new_place = .*/calibrate_new_place = false/" "$base" > "$dir/input.toml"
      "$build/apps/ratslam" evaluate --overwrite --config "$dir/input.toml" --map "$path" --query "$path" \
        --out "$dir" --quiet > /dev/null
      row "$dir/evaluation.json" "$b" "$enc"
    done
  done
  # The baselines do not depend on the words: report them once, from the last run.
  for baseline in knn fingerprint; do
    row "$dir/evaluation.json" "$baseline" "(baseline)" "$baseline"
  done
  echo
}
row() {  # evaluation.json, first column, second column, [baseline name]
  /usr/bin/python3 - "$@" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
if len(sys.argv) > 4:
    j = j["baselines"][sys.argv[4]]
pct = lambda x: f"{100 * x:.1f}"
c = [pct(j["correct_within_m"][d]) for d in ("2", "5", "10", "20")]
m = [pct(j["misplaced_beyond_m"][d]) for d in ("2", "5", "10", "20")]
print(f"| {sys.argv[2]} | {sys.argv[3]} | " + " | ".join(c + m) +
      f" | {pct(j['rejection_rate'])} | {pct(j['floor_mistake_rate'])} |")
PY
}
run_set "UJIIndoorLoc" configs/ujiindoorloc-wifi.toml "$data/ujiindoorloc/trainingData.csv"
run_set "Microsoft ILC 2.0 site 1" configs/msft-ilc20-wifi.toml "$data/msft-ilc20-site1"
