#!/usr/bin/env bash
# Nordland winter queries against the summer route with place descriptors computed outside the
# program (scripts/image_descriptors.py: histograms of oriented gradients on grids of 4x2, 8x4
# and 16x8 cells, a stand-in for a learnt descriptor), matched by `ratslam evaluate
# --map-descriptors/--query-descriptors` beside the images' own matcher in the same run. Prints
# a markdown table (docs/results/nordland.md holds its last output).
# Usage: scripts/nordland_descriptor_table.sh [build dir] [out dir] [data dir]
set -euo pipefail
build=${1:-build}
out=${2:-out/nordland-descriptor-table}
data=${3:-../shared/data/nordland-64x32}
ratslam="$build/apps/ratslam"
here=$(cd "$(dirname "$0")" && pwd)
py=/usr/bin/python3
mkdir -p "$out"
field() { "$py" "$(dirname "$0")/json_field.py" "$@"; }
echo "| descriptor | values | sequences of 10: recall@1 | recall at 100 % precision | single frame recall@1 | images (same run): sequences recall@1 | single frame recall@1 | descriptor matching (s) |"
echo "|---|---|---|---|---|---|---|---|"
for cells in 4x2 8x4 16x8; do
  for season in summer winter; do
    "$py" "$here/image_descriptors.py" "$data/$season" "$out/$season-$cells.npy" --cells "$cells" 2> /dev/null
  done
  "$ratslam" evaluate --quiet --overwrite --frame-tolerance 1 --map "$data/summer" \
    --query "$data/winter" --map-descriptors "$out/summer-$cells.npy" \
    --query-descriptors "$out/winter-$cells.npy" --out "$out/$cells" > /dev/null
  j="$out/$cells/evaluation.json"
  echo "| HOG, $cells cells x 9 bins | $(field "$j" descriptors.dimensions) |" \
       "$(field "$j" descriptors.recall_at_1 %) % | $(field "$j" descriptors.recall_at_100_precision %) % |" \
       "$(field "$j" descriptors.single_frame.recall_at_1 %) % | $(field "$j" recall_at_1 %) % |" \
       "$(field "$j" baselines.single_frame.recall_at_1 %) % | $(field "$j" descriptors.match_seconds x) |"
done
# Visual FABMAP on the same benchmark: single frames by visual words, the vocabulary, Chow-Liu
# tree and unknown world learnt from the summer images.
echo
echo "| FABMAP visual words | vocabulary | training images | words per image (summer, winter) | recall@1 | recall@5 | PR AUC |"
echo "|---|---|---|---|---|---|---|"
for features in "sift 1000 5" "sift 3000 1" "orb 100 1"; do
  set -- $features
  tag="fabmap-$1-$2"
  printf '[visual_words]\ndescriptor = "%s"\nfast_threshold = 5\n[vocabulary]\nwords = %d\n[visual_model]\ntraining_image_step = %d\n' \
    "$1" "$2" "$3" > "$out/$tag.toml"
  "$ratslam" evaluate --quiet --overwrite --config "$out/$tag.toml" --fabmap --frame-tolerance 1 \
    --map "$data/summer" --query "$data/winter" --out "$out/$tag" > /dev/null
  j="$out/$tag/evaluation.json"
  every="every ${3}th"
  [ "$3" = 1 ] && every="every"
  echo "| $1 | $2 | $every summer image | $(field "$j" baselines.fabmap.words_per_reference x), $(field "$j" baselines.fabmap.words_per_query x) |" \
       "$(field "$j" baselines.fabmap.recall_at_1 %) % | $(field "$j" baselines.fabmap.recall_at_5 %) % | $(field "$j" baselines.fabmap.pr_auc x) |"
done
