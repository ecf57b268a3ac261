#!/usr/bin/env bash
# The FABMAP front end of `replay` on the IPIN training logs (all repetitions of a route in one
# run, configs/ipin2023-fabmap-wifi.toml) deciding by its posterior (shipped, 0.5) and by the
# best mapped place's log odds at several thresholds ([fabmap_front_end] decide_by_log_odds), and
# with earlier sessions apart (apart-T: the current session's places at 0 nats, earlier sessions'
# at T; earlier_sessions_apart).
# Prints per run: rule route templates matches injections map_ate_m odometry_ate_m
# within_5m cross_session_matches floor_mistakes.
# Usage: scripts/fabmap_log_odds_table.sh [ratslam binary] [out dir]   (about 40 s)
set -uo pipefail
cd "$(dirname "$0")/.."; root=$PWD
bin=$(realpath "${1:-build/apps/ratslam}"); out=${2:-out/fabmap-log-odds}; mkdir -p "$out"
out=$(realpath "$out"); data=$root/../shared/data/ipin2023-t3
cd "$out"
for t in posterior 0 -10 -20 -30 apart-20 apart-30; do
  if [[ $t == posterior ]]; then
    cp "$root/configs/ipin2023-fabmap-wifi.toml" cfg-$t.toml
  elif [[ $t == apart-* ]]; then
    sed "s/^\[fabmap_front_end\]$/[fabmap_front_end]\ndecide_by_log_odds = true\nmatch_log_odds = 0.0\nearlier_sessions_apart = true\nearlier_session_log_odds = -${t#apart-}/" \
      "$root/configs/ipin2023-fabmap-wifi.toml" > cfg-$t.toml
  else
    sed "s/^\[fabmap_front_end\]$/[fabmap_front_end]\ndecide_by_log_odds = true\nmatch_log_odds = $t/" \
      "$root/configs/ipin2023-fabmap-wifi.toml" > cfg-$t.toml
  fi
  for route in 01 02 03 21 22 23 51; do
    args=()
    for rep in 01 02 03 04; do
      f=$data/IPIN2023_T3_TrainingTrial${route}_repetition${rep}.txt
      [[ -f $f ]] && args+=(--data "$f")
    done
    [[ ${#args[@]} -eq 0 ]] && { echo "missing $data route $route" >&2; continue; }
    "$bin" replay --quiet --overwrite --config cfg-$t.toml "${args[@]}" --out run-$t-$route \
      > /dev/null 2>&1 || { echo "$t $route failed" >&2; continue; }
    /usr/bin/python3 - run-$t-$route/summary.json "$t" "$route" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
print(sys.argv[2], sys.argv[3], j["templates"], j["matches"], j["view_injections"],
      round(j["map_ate_m"], 2), round(j["odometry_ate_m"], 2),
      round(j["match_rate_within_m"]["5"], 2), j.get("cross_session_matches"),
      j.get("floor_mistakes"))
PY
  done
done
