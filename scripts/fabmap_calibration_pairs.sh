#!/usr/bin/env bash
# The FABMAP front end's calibrated earlier-session threshold on two-walk runs of the IPIN
# training routes (walks 1+2, 2+3, 3+4 and 1+4 of routes 01-03 and 21-23): the shipped config
# (configs/ipin2023-fabmap-wifi.toml, calibrate_earlier_session_log_odds) against the same config
# with the hand-set -30 nats. Two walks give the first pass few verified revisits, so this is
# where calibration most often falls back to the configured value.
# Prints per run: route walks, then per config map_ate_m verified_revisits threshold
# odometry_ate_m; and the means.
# Usage: scripts/fabmap_calibration_pairs.sh [ratslam binary] [out dir]   (about 20 s)
set -euo pipefail
cd "$(dirname "$0")/.."; root=$PWD
bin=$(realpath "${1:-build/apps/ratslam}"); out=${2:-out/fabmap-calibration-pairs}
mkdir -p "$out"; out=$(realpath "$out"); data=$root/../shared/data/ipin2023-t3
shipped=$root/configs/ipin2023-fabmap-wifi.toml
sed 's/^calibrate_earlier_session_log_odds = true$/calibrate_earlier_session_log_odds = false/' \
  "$shipped" > "$out/by-hand.toml"
cmp -s "$shipped" "$out/by-hand.toml" && { echo "the shipped config does not calibrate" >&2; exit 1; }
echo "route walks | by hand: map_ate_m revisits threshold odometry_ate_m | calibrated: the same"
for route in 01 02 03 21 22 23; do
  for pair in "01 02" "02 03" "03 04" "01 04"; do
    read -r a b <<< "$pair"
    logs=("$data/IPIN2023_T3_TrainingTrial${route}_repetition$a.txt"
          "$data/IPIN2023_T3_TrainingTrial${route}_repetition$b.txt")
    [[ -f ${logs[0]} && -f ${logs[1]} ]] || { echo "missing ${logs[*]}" >&2; continue; }
    line="$route $a+$b"
    for config in by-hand shipped; do
      c=$out/by-hand.toml
      [[ $config == shipped ]] && c=$shipped
      "$bin" replay --quiet --overwrite --config "$c" --data "${logs[0]}" --data "${logs[1]}" \
        --out "$out/run-$config-$route-$a$b" > /dev/null
      line+=" | $(/usr/bin/python3 - "$out/run-$config-$route-$a$b/summary.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
print(round(j["map_ate_m"], 2), j.get("fabmap_verified_revisits", "-"),
      round(j["fabmap_earlier_session_log_odds"], 1), round(j["odometry_ate_m"], 2))
PY
)"
    done
    echo "$line"
  done
done | tee "$out/table.txt"
awk -F'|' '{split($2, h, " "); split($3, c, " "); n++; hs += h[1]; cs += c[1];
            if (c[2] != "-" && c[3] != "-30.0") learnt++}
           END {printf "mean map ATE over %d runs: by hand %.2f m, calibrated %.2f m; learnt in %d\n",
                n, hs / n, cs / n, learnt}' "$out/table.txt"
