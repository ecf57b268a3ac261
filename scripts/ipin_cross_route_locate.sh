#!/usr/bin/env bash
# Phone localisation across routes (Kudo and Miura, section IV): IPIN 2023 Track 3 routes 01-03
# share floor 0 and routes 21-23 floor -2 of one building. Per floor, one Wi-Fi map from
# repetitions 01 and 02 of all three routes, in which repetitions 03 and 04 of each are located;
# then, for each route, a map from the *other two* routes only (so the phone walks partly where
# the map has no scan) and the same repetitions located in it; and one map of
# both floors from every route's repetitions 01-02, in which route 51 (which also visits floor
# -1, never mapped) is located. Sum likelihood and the weighted 3-NN answer on the same map
# scans; mean / median / p90 m on the right floor, and the scans on another floor.
# Usage: scripts/ipin_cross_route_locate.sh [DATA_DIR] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data/ipin2023-t3}
out=${2:-out/ipin-cross-route}
bin=./build/apps/ratslam
mkdir -p "$out"
log() { echo "$data/IPIN2023_T3_TrainingTrial$1_repetition$2.txt"; }
row() {  # summary.json, label
  /usr/bin/python3 - "$1" "$2" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
def cell(x):
    if not x.get("count"):
        return f"- ({x.get('wrong_floor', 0)} other floor)"
    return (" / ".join(f"{x[k]:.1f}" for k in ("mean_error_m", "median_error_m", "p90_error_m")) +
            f" ({x['wrong_floor']} other floor)")
print(f"| {sys.argv[2]} | {j.get('count', 0) + j.get('wrong_floor', 0)} | {cell(j)} | {cell(j['knn_baseline'])} |")
PY
}
map_of() {  # output map, routes...: a map from repetitions 01 and 02 of the routes
  local map=$1 a=() r
  shift
  for r in "$@"; do a+=(--data "$(log "$r" 01)" --data "$(log "$r" 02)"); done
  "$bin" wifi-map --overwrite "${a[@]}" --out "$map" > /dev/null
}
locate_row() {  # map, route, repetition, output folder, label
  "$bin" locate --quiet --overwrite --wifi-map "$1" --data "$(log "$2" "$3")" --out "$4"
  row "$4/summary.json" "$5"
}
echo "| located (map) | scans with truth | filter mean / median / p90 m | 3-NN mean / median / p90 m |"
echo "|---|---|---|---|"
for group in "01 02 03" "21 22 23"; do
  read -r -a routes <<< "$group"
  map_of "$out/floor${routes[0]}.wifimap" "${routes[@]}"
  for r in "${routes[@]}"; do
    for rep in 03 04; do
      locate_row "$out/floor${routes[0]}.wifimap" "$r" "$rep" "$out/floor-route$r-rep$rep" \
        "route $r rep$rep (map: routes ${routes[*]})"
    done
  done
done
for group in "01 02 03" "21 22 23"; do
  read -r -a routes <<< "$group"
  for r in "${routes[@]}"; do
    others=()
    for o in "${routes[@]}"; do [[ $o == "$r" ]] || others+=("$o"); done
    map_of "$out/without$r.wifimap" "${others[@]}"
    for rep in 03 04; do
      locate_row "$out/without$r.wifimap" "$r" "$rep" "$out/route$r-rep$rep" \
        "route $r rep$rep (map: routes ${others[*]})"
    done
  done
done
map_of "$out/both-floors.wifimap" 01 02 03 21 22 23
locate_row "$out/both-floors.wifimap" 51 02 "$out/route51" \
  "route 51 rep02, floors 0, -1, -2 (map: all six routes, floors 0 and -2)"
