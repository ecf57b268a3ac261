#!/usr/bin/env bash
# Configures and builds into BUILD_DIR (default build/); BUILD_TARGET limits the build to one
# target (default: everything). Extra arguments go to CMake.
# Warnings are errors here, as in CI.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${BUILD_DIR:-build}
source scripts/ccache_env.sh
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DRATSLAM_WERROR=ON "${ccache_args[@]}" "$@"
target=()
[[ -n "${BUILD_TARGET:-}" ]] && target=(--target "$BUILD_TARGET")
cmake --build "$build_dir" --parallel "$(nproc)" "${target[@]}"
