#!/usr/bin/env bash
# The FABMAP front end of `replay` on the IPIN training logs (all repetitions of a route in one
# run, configs/ipin2023-fabmap-wifi.toml and variants of it) deciding by its posterior (0.5), by
# the best mapped place's log odds at several thresholds for every place, and with earlier
# sessions apart (apart-T, as shipped with T = 30: the current session's places at 0 nats,
# earlier sessions' at -T; earlier_sessions_apart); then with the Wi-Fi sequence loop closer on,
# earlier sessions at -T (seq-T), and with their threshold learnt from its verified revisits
# starting from -T (learn-T; learn_earlier_session_log_odds); and learnt in a first pass of its
# own, then mapped with in a second (calibrated: the shipped config, whose second pass has the
# loop closer off). The variants are made from the shipped config without calibration.
# Prints per run: rule route templates matches injections map_ate_m odometry_ate_m
# within_5m cross_session_matches floor_mistakes earlier_session_log_odds verified_revisits.
# Usage: scripts/fabmap_log_odds_table.sh [ratslam binary] [out dir]   (about 70 s)
set -uo pipefail
cd "$(dirname "$0")/.."; root=$PWD
bin=$(realpath "${1:-build/apps/ratslam}"); out=${2:-out/fabmap-log-odds}; mkdir -p "$out"
out=$(realpath "$out"); data=$root/../shared/data/ipin2023-t3
cd "$out"
shipped=$root/configs/ipin2023-fabmap-wifi.toml
config=$out/by-hand.toml
sed 's/^calibrate_earlier_session_log_odds = true$/calibrate_earlier_session_log_odds = false/' \
  "$shipped" > "$config"
cmp -s "$shipped" "$config" && { echo "the shipped config does not calibrate" >&2; exit 1; }
for t in posterior 0 -10 -20 -30 apart-20 apart-30 seq-30 seq-0 learn-0 learn-30 calibrated; do
  case $t in
    posterior) rule='s/^decide_by_log_odds = true$/decide_by_log_odds = false/;
                     s/^earlier_sessions_apart = true$/earlier_sessions_apart = false/' ;;
    apart-*) rule="s/^earlier_session_log_odds = .*/earlier_session_log_odds = -${t#apart-}.0/" ;;
    seq-*) rule="s/^earlier_session_log_odds = .*/earlier_session_log_odds = $((-${t#seq-})).0/" ;;
    learn-*) rule="s/^earlier_session_log_odds = .*/earlier_session_log_odds = $((-${t#learn-})).0\\n"
             rule+="learn_earlier_session_log_odds = true/" ;;
    calibrated) rule='s/^calibrate_earlier_session_log_odds = false$/calibrate_earlier_session_log_odds = true/' ;;
    *) rule="s/^earlier_sessions_apart = true$/earlier_sessions_apart = false/;
             s/^match_log_odds = .*/match_log_odds = $t.0/" ;;
  esac
  sed "$rule" "$config" > cfg-$t.toml
  cmp -s "$config" cfg-$t.toml && [[ $t != apart-30 && $t != seq-30 ]] &&
    { echo "$t: config unchanged" >&2; exit 1; }
  [[ $t == seq-* || $t == learn-* ]] && printf '\n[wifi_sequence]\nenabled = true\n' >> cfg-$t.toml
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
      j.get("floor_mistakes"), j.get("fabmap_earlier_session_log_odds"),
      j.get("fabmap_verified_revisits"))
PY
  done
done
