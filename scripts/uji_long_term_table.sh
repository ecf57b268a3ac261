#!/usr/bin/env bash
# The long-term UJI library benchmark (Mendoza-Silva et al., Data 3(1), 2018; not in
# ../shared/data): the map is month 01's training set, the queries each month's test set, as a
# Markdown table of FABMAP (the config's mode) against the k-NN and eq. 6 fingerprint baselines
# of the same run: within 5 m, rejected and floor mistakes, in percent of the month's queries.
# Usage: scripts/uji_long_term_table.sh DB_DIR [CONFIG] [TEST_SET] [OUT_DIR]
#   DB_DIR    the data set's db/ folder (01/, 02/, ... inside)
#   CONFIG    default configs/ujiindoorloc-wifi.toml
#   TEST_SET  default tst01 (the set the data set's paper evaluates month by month)
set -euo pipefail
cd "$(dirname "$0")/.."
db=${1:?usage: scripts/uji_long_term_table.sh DB_DIR [CONFIG] [TEST_SET] [OUT_DIR]}
config=${2:-configs/ujiindoorloc-wifi.toml}
set_name=${3:-tst01}
out=${4:-out/uji-long-term}
bin=./build/apps/ratslam
py=/usr/bin/python3
map=$db/01/trn01rss.csv
[[ -f $map ]] || { echo "no map set: $map" >&2; exit 1; }
mkdir -p "$out"
echo "| month | queries | FABMAP 5 m | rejected | floor mistakes | k-NN 5 m | floor mistakes | fingerprint 5 m | rejected | floor mistakes |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for dir in "$db"/*/; do
  month=$(basename "$dir")
  query=$dir${set_name}rss.csv
  [[ -f $query ]] || continue
  "$bin" evaluate --quiet --overwrite --config "$config" --map "$map" --query "$query" --out "$out/$month" \
    > /dev/null
  "$py" - "$out/$month/evaluation.json" "$month" <<'PY'
import json, sys
j = json.load(open(sys.argv[1])); b = j["baselines"]
p = lambda x: f"{100 * x:.1f}"
print(f"| {sys.argv[2]} | {j['queries']} | {p(j['correct_within_m']['5'])} | {p(j['rejection_rate'])} | "
      f"{p(j['floor_mistake_rate'])} | {p(b['knn']['correct_within_m']['5'])} | "
      f"{p(b['knn']['floor_mistake_rate'])} | {p(b['fingerprint']['correct_within_m']['5'])} | "
      f"{p(b['fingerprint']['rejection_rate'])} | {p(b['fingerprint']['floor_mistake_rate'])} |")
PY
done
