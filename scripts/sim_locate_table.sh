#!/usr/bin/env bash
# Phone localisation (Kudo and Miura, section IV) on the simulated worlds, where the truth is
# exact and the walls are known: a Gaussian-process Wi-Fi map from one simulation of a world
# (seed 1), then another simulation of it (seed 2: other noise, same route) located by the
# particle filter with the sum (eq. 13) and product likelihoods, with the world's walls and
# without them (wall_crossing_weight = 1), beside the weighted 3-NN fingerprint answer on the
# same map scans. Mean / median / p90 error in metres at every scan; a Markdown table.
# Usage: scripts/sim_locate_table.sh [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/sim-locate-table}
bin=./build/apps/ratslam
mkdir -p "$out"
printf '[particle_filter]\nlikelihood = "sum"\n' > "$out/sum.toml"
printf '[particle_filter]\nlikelihood = "product"\n' > "$out/product.toml"
printf '[particle_filter]\nlikelihood = "sum"\nwall_crossing_weight = 1.0\n' > "$out/sum-nowalls.toml"
printf '[particle_filter]\nlikelihood = "product"\nwall_crossing_weight = 1.0\n' > "$out/product-nowalls.toml"
echo "| world | scans | floors | walls | sum, walls | sum, no walls | product, walls | product, no walls | 3-NN |"
echo "|---|---|---|---|---|---|---|---|---|"
for world in office apartment circular aliased_floors day_night; do
  for seed in 1 2; do
    [[ -d "$out/$world-$seed" ]] || "$bin" simulate --quiet --world "$world" --seed "$seed" \
      --out "$out/$world-$seed"
  done
  "$bin" wifi-map --overwrite --data "$out/$world-1" --out "$out/$world.wifimap" > "$out/$world-wifimap.json"
  for c in sum sum-nowalls product product-nowalls; do
    "$bin" locate --quiet --overwrite --config "$out/$c.toml" --wifi-map "$out/$world.wifimap" \
      --data "$out/$world-2" --out "$out/$world-$c"
  done
  /usr/bin/python3 - "$out" "$world" <<'PY'
import json, sys
out, world = sys.argv[1:3]
m = json.load(open(f"{out}/{world}-wifimap.json"))
runs = {c: json.load(open(f"{out}/{world}-{c}/summary.json"))
        for c in ("sum", "sum-nowalls", "product", "product-nowalls")}
def row(j):
    if not j.get("count"):
        return "-"
    cells = " / ".join(f"{j[k]:.1f}" for k in ("mean_error_m", "median_error_m", "p90_error_m"))
    return cells + (f" ({j['wrong_floor']} wrong floor)" if j.get("wrong_floor") else "")
s = runs["sum"]
print(f"| {world} | {s['scans']} | {len(m['floors'])} | {m['walls']} | " +
      " | ".join(row(runs[c]) for c in ("sum", "sum-nowalls", "product", "product-nowalls")) +
      f" | {row(s['knn_baseline'])} |")
PY
done
