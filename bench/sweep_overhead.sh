#!/usr/bin/env bash
# Per-run overhead of `ratslam sweep run` over bare `ratslam replay` calls: the same N runs
# (the IPIN training walks, one configuration each) both ways, one at a time, repeated R times;
# prints the median wall time of each and their ratio. A timed script, not a test.
#   bash bench/sweep_overhead.sh [path/to/ratslam] [R]
set -euo pipefail
cd "$(dirname "$0")/.."
program=$(realpath "${1:-build/apps/ratslam}")
repeats=${2:-3}
data=$PWD/../shared/data/ipin2023-t3
[[ -d $data ]] || { echo "missing $data" >&2; exit 1; }
work=$(mktemp -d /tmp/ratslam-sweep-bench.XXXXXX)
trap 'rm -rf "$work"' EXIT
cat >"$work/sweep.toml" <<TOML
[sweep]
base_config = "$PWD/configs/ipin2023-wifi-compass.toml"
objective = "map_ate_m"
[[datasets]]
glob = "$data/*.txt"
TOML
median() { sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
now() { date +%s.%N; }
calc() { awk "BEGIN { printf \"%.4g\", $1 }"; }  # no bc on a fresh machine
sweep_times=() bare_times=()
for ((r = 0; r < repeats; r++)); do
  rm -rf "$work/s" "$work/bare"
  "$program" sweep plan "$work/sweep.toml" --out "$work/s" >/dev/null
  start=$(now)
  "$program" sweep run "$work/s" --jobs 1 --quiet >/dev/null
  sweep_times+=("$(calc "$(now) - $start")")
  mkdir -p "$work/bare"
  start=$(now)
  i=0
  for f in "$data"/*.txt; do
    "$program" replay --config "$work/s/runs/00000/config.toml" --data "$f" \
      --out "$work/bare/$i" --overwrite --quiet >/dev/null 2>&1
    i=$((i + 1))
  done
  bare_times+=("$(calc "$(now) - $start")")
done
runs=$(ls "$data"/*.txt | wc -l)
s=$(printf '%s\n' "${sweep_times[@]}" | median)
b=$(printf '%s\n' "${bare_times[@]}" | median)
echo "runs per repeat: $runs; repeats: $repeats"
echo "sweep run --jobs 1: median $s s ($(calc "$s / $runs") s per run)"
echo "bare replay loop:   median $b s ($(calc "$b / $runs") s per run)"
echo "overhead: $(calc "($s / $b - 1) * 100") %"
