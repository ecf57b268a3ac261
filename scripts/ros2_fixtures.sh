#!/usr/bin/env bash
# Makes ROS 2 bags with independent writers (tests/ros2/make_fixtures.mjs: Foxglove's MCAP writer
# and ROS 2 CDR serialiser, SQLite as WebAssembly) for the tests of our ROS 2 readers.
#
#   scripts/ros2_fixtures.sh OUT_DIR [REPLAY_FOLDER]
#
# The npm packages (versions pinned in tests/ros2/package.json) are installed once into
# ${RATSLAM_NPM_DIR:-~/.cache/ratslam-npm}, outside the clone, so CI and later sessions reuse them.
# Exit 77 (and a line on stderr saying why) when node or npm is missing or the registry cannot be
# reached: the tests then skip with that message.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${1:?usage: ros2_fixtures.sh OUT_DIR [REPLAY_FOLDER]}
data=${2:-}
cache=${RATSLAM_NPM_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/ratslam-npm}

if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  echo "ros2_fixtures: node and npm are needed to write the ROS 2 test bags (not installed)" >&2
  exit 77
fi
mkdir -p "$cache"
# Installs under a lock (tests run in parallel) when the pinned versions are not there yet.
(
  flock 9
  if ! cmp -s "$here/tests/ros2/package.json" "$cache/package.json" ||
     [[ ! -d "$cache/node_modules/@mcap/core" ]]; then
    cp "$here/tests/ros2/package.json" "$cache/package.json"
    if ! (cd "$cache" && timeout 300 npm install --no-audit --no-fund --loglevel=error >"$cache/npm.log" 2>&1); then
      rm -f "$cache/package.json"
      echo "ros2_fixtures: npm install failed (registry unreachable?); see $cache/npm.log" >&2
      exit 77
    fi
  fi
) 9>"$cache/.lock"
args=(--modules "$cache/node_modules" --out "$out")
if [[ -n $data ]]; then args+=(--data "$data"); fi
node "$here/tests/ros2/make_fixtures.mjs" "${args[@]}"
