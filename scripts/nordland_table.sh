#!/usr/bin/env bash
# Nordland winter queries against the summer route (../shared/data/nordland-64x32): recall@1,
# recall@5, PR AUC and recall at 100 % precision of the sequence matcher for several sequence
# lengths and frame tolerances, the online search (each query by the frames ending at it) beside
# the centred one ([sequence] centred), the online one with blank frames matched like any other
# ([sequence] blank_contrast = 0), with the single-frame baseline of the same run. Lengths 10
# and 11: OpenSeqSLAM's ds = 10 spans 11 query frames. Prints a markdown table
# (docs/results/nordland.md holds its last output).
# Usage: scripts/nordland_table.sh [build dir] [out dir] [data dir]
set -euo pipefail
build=${1:-build}
out=${2:-out/nordland-table}
data=${3:-../shared/data/nordland-64x32}
ratslam="$build/apps/ratslam"
mkdir -p "$out"
py=/usr/bin/python3
field() { "$py" "$(dirname "$0")/json_field.py" "$@"; }
echo "| sequence length | tolerance (frames) | recall@1 | recall@5 | PR AUC | recall at 100 % precision | centred: recall@1 | recall at 100 % precision | single frame recall@1 | blanks matched: recall@1 | single frame recall@1 | matching (s) |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
for tolerance in 0 1 2; do
  for length in 5 10 11 20; do
    tag="len$length-tol$tolerance"
    printf "[sequence]\nsequence_length = %d\n" "$length" > "$out/$tag.toml"
    "$ratslam" evaluate --quiet --overwrite --config "$out/$tag.toml" --frame-tolerance "$tolerance" \
      --map "$data/summer" --query "$data/winter" --out "$out/$tag" > /dev/null
    printf "[sequence]\nsequence_length = %d\ncentred = true\n" "$length" > "$out/$tag-centred.toml"
    "$ratslam" evaluate --quiet --overwrite --config "$out/$tag-centred.toml" \
      --frame-tolerance "$tolerance" --map "$data/summer" --query "$data/winter" \
      --out "$out/$tag-centred" > /dev/null
    printf "[sequence]\nsequence_length = %d\nblank_contrast = 0\n" "$length" > "$out/$tag-blanks.toml"
    "$ratslam" evaluate --quiet --overwrite --config "$out/$tag-blanks.toml" \
      --frame-tolerance "$tolerance" --map "$data/summer" --query "$data/winter" \
      --out "$out/$tag-blanks" > /dev/null
    j="$out/$tag/evaluation.json"
    c="$out/$tag-centred/evaluation.json"
    b="$out/$tag-blanks/evaluation.json"
    echo "| $length | $tolerance | $(field "$j" recall_at_1 %) % | $(field "$j" recall_at_5 %) % |" \
         "$(field "$j" pr_auc x) | $(field "$j" recall_at_100_precision %) % |" \
         "$(field "$c" recall_at_1 %) % | $(field "$c" recall_at_100_precision %) % |" \
         "$(field "$j" baselines.single_frame.recall_at_1 %) % |" \
         "$(field "$b" recall_at_1 %) % | $(field "$b" baselines.single_frame.recall_at_1 %) % |" \
         "$(field "$j" match_seconds x) |"
  done
done
