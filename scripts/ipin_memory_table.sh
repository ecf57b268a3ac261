#!/usr/bin/env bash
# Every IPIN Wi-Fi config on every training route (rep01 alone and all repetitions as one
# multi-session run) with [local_view] memory = "frames" and = "time". Prints per run:
# route mode walks | frames: templates matches injections map_ate odometry_ate | time: the same.
# Usage: scripts/ipin_memory_table.sh [ratslam binary] [out dir]
set -uo pipefail
cd "$(dirname "$0")/.."; root=$PWD
bin=$(realpath "${1:-build/apps/ratslam}"); out=${2:-out/ipin-memory}; mkdir -p "$out"; out=$(realpath "$out")
c=$root/configs; data=$root/../shared/data/ipin2023-t3
cd "$out"
get() { /usr/bin/python3 -c "import json; j=json.load(open('$1/summary.json')); print(j['templates'], j['matches'], j['view_injections'], round(j['map_ate_m'],2), round(j['odometry_ate_m'],2), sep=' ')"; }
for mode in wifi wifi-compass wifi-compass-tuned fabmap-wifi; do
  sed '/^memory = /d' $c/ipin2023-$mode.toml > frames-$mode.toml
  sed -e '/^memory = /d' -e 's/^\[local_view\]$/[local_view]\nmemory = "time"/' $c/ipin2023-$mode.toml > time-$mode.toml
done
for route in 01 02 03 21 22 23 51; do
  for mode in wifi wifi-compass wifi-compass-tuned fabmap-wifi; do
    for n in 1 4; do
      args=(); for rep in 01 02 03 04; do f=$data/IPIN2023_T3_TrainingTrial${route}_repetition${rep}.txt; [[ -f $f ]] && args+=(--data $f); [[ ${#args[@]} -ge $((2*n)) ]] && break; done
      line="$route $mode $n"
      for when in frames time; do
        "$bin" replay --quiet --overwrite --config $when-$mode.toml "${args[@]}" --out $when-$route-$mode-$n >/dev/null 2>&1 && line+=" | "$(get $when-$route-$mode-$n)
      done
      echo "$line"
    done
  done
done
