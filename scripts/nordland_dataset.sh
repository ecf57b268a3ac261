#!/usr/bin/env bash
# Nordland (../shared/data/nordland-64x32) as two replay data sets, summer and winter, for
# `ratslam replay --data OUT/summer --data OUT/winter` (two sessions of one map). Each is a
# manifest, an images.csv (sample k of the journey, every 10th video frame, at k seconds) and a
# copy of the images. No odometry.csv and no ground truth: how the GPS logs line up with the
# frames is not established (docs/results/nordland.md), so the run takes visual odometry from
# the images ([visual_odometry] in configs/nordland-replay.toml); the same file name in both
# seasons is the same place, which is what the replay's summary scores.
# Usage: scripts/nordland_dataset.sh [data dir] [out dir]
set -euo pipefail
data=${1:-../shared/data/nordland-64x32}
out=${2:-out/nordland-dataset}
for season in summer winter; do
  [[ -d "$data/$season" ]] || { echo "nordland_dataset.sh: $data/$season: no such folder" >&2; exit 1; }
  dir="$out/$season"
  rm -rf "$dir"
  mkdir -p "$dir/images"
  cp "$data/$season"/images-*.png "$dir/images/"
  cat > "$dir/manifest.toml" <<TOML
format = "ratslam-replay"
format_version = 1
name = "nordland-$season"

[streams]
images = "images.csv"
image_folder = "images"
TOML
  {
    echo "time_s,file"
    k=0
    for f in $(cd "$dir/images" && ls images-*.png | sort); do
      k=$((k + 1))
      echo "$k,$f"
    done
  } > "$dir/images.csv"
done
echo "$out/summer $out/winter"
