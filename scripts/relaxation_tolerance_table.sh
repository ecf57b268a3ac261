#!/usr/bin/env bash
# What the incremental relaxation's tolerances trade: link updates (its cost) against map error.
# Replays the synthetic loop x10 (12,114 frames) at OpenRatSLAM's map size ([camera]
# match_threshold 0.015: about 1,900 templates and experiences, as bench/replay_benchmark) for
# three seeds, with the full scheme (the baseline) and the incremental scheme at tolerances of
# 1 (the default), 2, 5 and 10 mm (and 1e-4 rad scaled alike); prints a markdown table of link
# updates per frame and the map's and trajectory's ATE against ground truth per seed.
# Usage: scripts/relaxation_tolerance_table.sh [out dir] [ratslam binary]   (SEEDS="1 2 3")
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/relaxation-tolerance}
ratslam=${2:-build/apps/ratslam}
seeds=${SEEDS:-1 2 3}
mkdir -p "$out"

config() {  # name, scheme, tolerance m, tolerance rad
  sed -e 's/^match_threshold = 0.03$/match_threshold = 0.015/' \
    -e "s/^relaxation_scheme = .*/relaxation_scheme = \"$2\"/" \
    -e "s/^relaxation_tolerance_m = .*/relaxation_tolerance_m = $3/" \
    -e "s/^relaxation_tolerance_rad = .*/relaxation_tolerance_rad = $4/" \
    configs/synthetic.toml > "$out/$1.toml"
  grep -q '^match_threshold = 0.015$' "$out/$1.toml" || { echo "threshold not set" >&2; exit 1; }
  grep -q "^relaxation_tolerance_m = $3\$" "$out/$1.toml" || { echo "tolerance not set" >&2; exit 1; }
}
config full full 0.001 1e-04
config 1mm incremental 0.001 1e-04
config 2mm incremental 0.002 2e-04
config 5mm incremental 0.005 5e-04
config 10mm incremental 0.01 1e-03
names=(full 1mm 2mm 5mm 10mm)

for seed in $seeds; do
  "$ratslam" synthesize --laps 10 --seed "$seed" --out "$out/data-$seed" --overwrite > /dev/null
  for name in "${names[@]}"; do
    "$ratslam" replay --quiet --overwrite --config "$out/$name.toml" --data "$out/data-$seed" \
      --out "$out/run-$seed-$name" > /dev/null
  done
done

/usr/bin/python3 - "$out" "${names[*]}" $seeds <<'EOF'
import json, sys
out, names, seeds = sys.argv[1], sys.argv[2].split(), sys.argv[3:]
print("| relaxation | seed | experiences | link updates per frame | map ATE m | trajectory ATE m |")
print("|---|---|---|---|---|---|")
for name in names:
    for seed in seeds:
        s = json.load(open(f"{out}/run-{seed}-{name}/summary.json"))
        label = "full (baseline)" if name == "full" else f"incremental, {name}"
        print(f"| {label} | {seed} | {s['experiences']} | "
              f"{s['relaxation_link_updates'] / s['frames']:.0f} | {s['map_ate_m']:.2f} | "
              f"{s['trajectory_ate_m']:.2f} |")
EOF
