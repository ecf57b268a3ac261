#!/usr/bin/env bash
# RatSLAM over Nordland summer then winter (two sessions of one map): the share of winter frames
# that land on a summer template of their own place, with sequence recognition in front of the
# classic camera and the fused front ends and, in the same run, each front end alone. Prints a
# markdown table (docs/results/nordland.md holds its last output).
# Usage: scripts/nordland_replay_table.sh [build dir] [out dir] [data dir]
set -euo pipefail
build=${1:-build}
out=${2:-out/nordland-replay-table}
data=${3:-../shared/data/nordland-64x32}
ratslam="$build/apps/ratslam"
py=/usr/bin/python3
mkdir -p "$out"
bash "$(dirname "$0")/nordland_dataset.sh" "$data" "$out/data" > /dev/null
echo "| front end | sequence recognition | winter frames on a summer template | right within 0 frames | within 2 | precision within 2 | templates | wall (s) |"
echo "|---|---|---|---|---|---|---|---|"
for config in configs/nordland-replay.toml configs/nordland-replay-fused.toml; do
  for recognise in true false; do
    tag="$(basename "$config" .toml)-$recognise"
    sed "s/^recognise_views = true$/recognise_views = $recognise/" "$config" > "$out/$tag.toml"
    "$ratslam" replay --quiet --overwrite --config "$out/$tag.toml" --data "$out/data/summer" \
      --data "$out/data/winter" --out "$out/$tag" > /dev/null
    "$py" - "$out/$tag/summary.json" "$recognise" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
p = j["cross_session_places"]
kind = "fused (12x9 camera)" if "fused" in j["config"] else "classic camera"
pct = lambda v: f"{100 * v:.1f} %"
print(f"| {kind} | {'on' if sys.argv[2] == 'true' else 'off'} | {pct(p['matched_share'])} |"
      f" {pct(p['correct_share_within_frames']['0'])} | {pct(p['correct_share_within_frames']['2'])} |"
      f" {pct(p['precision_within_frames']['2'])} | {j['templates']} | {j['wall_seconds']:.1f} |")
PY
  done
done
