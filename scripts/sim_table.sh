#!/usr/bin/env bash
# Every mode on every built-in simulated world: RatSLAM with the b_out front end (sensor
# combinations of configs/sim-fused.toml) and FABMAP (the modes of configs/sim-fabmap.toml, the
# first session mapping, the others querying). Prints markdown tables.
# Usage: scripts/sim_table.sh [build dir] [out dir]
set -euo pipefail
build=${1:-build}
out=${2:-out/sim-table}
ratslam="$build/apps/ratslam"
mkdir -p "$out"
out=$(cd "$out" && pwd)  # absolute: paths inside a config are read relative to the config file
worlds=(office circular day_night aliased_floors apartment)
for w in "${worlds[@]}"; do
  [[ -f "$out/sim-$w/manifest.toml" ]] || "$ratslam" simulate --quiet --world "$w" --out "$out/sim-$w"
done

echo "#### RatSLAM (b_out front end): map ATE m / matches within 5 m / floor mistakes"
echo
printf "| world | dead reckoning |"
modes=("camera:true:false:false" "wifi:false:true:false" "wifi + compass:false:true:true"
       "camera + compass:true:false:true" "camera + wifi:true:true:false" "camera + wifi + compass:true:true:true")
for m in "${modes[@]}"; do printf " %s |" "${m%%:*}"; done
echo
printf "|---|---|"; for m in "${modes[@]}"; do printf "%s" "---|"; done; echo
for w in "${worlds[@]}"; do
  row="| $w |"
  first=1
  for m in "${modes[@]}"; do
    IFS=: read -r name cam wifi comp <<< "$m"
    tag="$w-${name// /}"
    sed -e "s/^use_camera = .*/use_camera = $cam/" -e "s/^use_wifi = .*/use_wifi = $wifi/" \
        -e "s/^use_compass = .*/use_compass = $comp/" configs/sim-fused.toml > "$out/$tag.toml"
    "$ratslam" replay --quiet --overwrite --config "$out/$tag.toml" --data "$out/sim-$w" --out "$out/replay-$tag" > /dev/null
    cell=$(python3 - "$out/replay-$tag/summary.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
within = j["match_rate_within_m"]["5"] if j.get("matches") else 0.0
print(f"{j['map_ate_m']:.2f} / {100 * within:.0f} % of {j.get('matches', 0)} / {j.get('floor_mistakes', 0)}|{j['odometry_ate_m']:.2f}")
PY
)
    if [[ $first == 1 ]]; then row="$row ${cell#*|} |"; first=0; fi
    row="$row ${cell%|*} |"
  done
  echo "$row"
done
echo

echo "#### FABMAP: correct within 5 m / misplaced beyond 5 m / rejected / floor mistakes (%)"
echo
fab_modes=(vision wifi early late wifi_guided wifi_check)
printf "| world |"; for m in "${fab_modes[@]}"; do printf " %s |" "$m"; done; echo
printf "|---|"; for m in "${fab_modes[@]}"; do printf "%s" "---|"; done; echo
model="$out/visual_model.bin"
for w in day_night aliased_floors apartment; do
  row="| $w |"
  for m in "${fab_modes[@]}"; do
    cfg="$out/fabmap-$w-$m.toml"
    sed -e "s/^mode = .*/mode = \"$m\"/" \
      -e "s|^training_images = .*|training_images = \"$out/sim-office/images\"|" \
      configs/sim-fabmap.toml > "$cfg"
    if [[ -f "$model" ]]; then
      sed -i -e "s|^training_images = .*|file = \"$model\"|" "$cfg"
    fi
    "$ratslam" evaluate --quiet --overwrite --config "$cfg" --map "$out/sim-$w" --query "$out/sim-$w" --out "$out/evaluate-$w-$m" > /dev/null
    [[ -f "$model" ]] || cp "$out/evaluate-$w-$m/visual_model.bin" "$model"
    cell=$(python3 - "$out/evaluate-$w-$m/evaluation.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
p = lambda x: f"{100 * x:.1f}"
print(f"{p(j['correct_within_m']['5'])} / {p(j['misplaced_beyond_m']['5'])} / {p(j['rejection_rate'])} / {p(j['floor_mistake_rate'])}")
PY
)
    row="$row $cell |"
  done
  echo "$row"
done
