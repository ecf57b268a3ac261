#!/usr/bin/env bash
# FABMAP's answer as the arg-max place or as the posterior vote of the most probable places
# ([evaluation] answer), beside k-NN of the same run, on UJIIndoorLoc split by node, by position
# and by user, and on the Microsoft walks. Prints a markdown table (percent of all queries).
# Usage: scripts/fabmap_answer_table.sh [build dir] [out dir]
set -euo pipefail
build=${1:-build}
out=${2:-out/fabmap-answer-table}
data=../shared/data
uji=$data/ujiindoorloc/trainingData.csv
msft=$data/msft-ilc20-site1
mkdir -p "$out"
echo "| data | answer | within 2 m | 5 m | 10 m | 20 m | median error m | rejected | floor mistakes |"
echo "|---|---|---|---|---|---|---|---|---|"
run() {  # name config data answer places temperature
  local name=$1 config=$2 path=$3 answer=$4 places=$5 temperature=$6
  local dir="$out/$name-$answer-$places-$temperature"
  mkdir -p "$dir"
  # The base config with the answer keys replaced (or added to its [evaluation] table).
  /usr/bin/python3 - "$config" "$dir/input.toml" "$answer" "$places" "$temperature" <<'PY'
import re, sys
src, dst, answer, places, temperature = sys.argv[1:]
text = re.sub(r"(?m)^answer(_places|_temperature)? = .*\n", "", open(src).read())
text = text.replace("[evaluation]\n", f'[evaluation]\nanswer = "{answer}"\n'
                    f"answer_places = {places}\nanswer_temperature = {temperature}\n", 1)
open(dst, "w").write(text)
PY
  "$build/apps/ratslam" evaluate --overwrite --quiet --config "$dir/input.toml" --map "$path" \
    --query "$path" --out "$dir" > /dev/null
  local label="$answer"
  [[ $answer == posterior ]] && label="posterior, $places places, T = $temperature"
  row "$dir" "$name" "$label"
  [[ $answer == best_place ]] && row "$dir" "$name" "k-NN (baseline)" knn
  return 0
}
row() {  # dir, data name, answer label, [baseline]
  /usr/bin/python3 - "$@" <<'PY'
import csv, json, math, sys
d, name, label = sys.argv[1:4]
j = json.load(open(f"{d}/evaluation.json"))
if len(sys.argv) > 4:
    j = j["baselines"][sys.argv[4]]
    median = ""
else:
    # The median over every query: rejections and other floors count as infinitely wrong.
    errors = []
    for r in csv.DictReader(open(f"{d}/queries.csv")):
        errors.append(float(r["error_m"]) if r["status"] == "located" else math.inf)
    errors.sort()
    m = errors[len(errors) // 2]
    median = f"{m:.1f}" if math.isfinite(m) else "inf"
pct = lambda x: f"{100 * x:.1f}"
c = [pct(j["correct_within_m"][k]) for k in ("2", "5", "10", "20")]
print(f"| {name} | {label} | " + " | ".join(c) +
      f" | {median} | {pct(j['rejection_rate'])} | {pct(j['floor_mistake_rate'])} |")
PY
}
for set in "UJIIndoorLoc by position|configs/ujiindoorloc-wifi-by-position.toml|$uji" \
           "UJIIndoorLoc by node|configs/ujiindoorloc-wifi.toml|$uji" \
           "UJIIndoorLoc by user|configs/ujiindoorloc-wifi-by-user.toml|$uji" \
           "Microsoft site 1|configs/msft-ilc20-wifi.toml|$msft"; do
  IFS='|' read -r name config path <<< "$set"
  run "$name" "$config" "$path" best_place 5 10
  for pt in "3 10" "5 10" "10 10" "5 3" "5 100"; do
    read -r places temperature <<< "$pt"
    run "$name" "$config" "$path" posterior "$places" "$temperature"
  done
done
