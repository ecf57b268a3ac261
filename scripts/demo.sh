#!/usr/bin/env bash
# Fresh Debian 12 machine -> installs packages, builds, and runs the main job: the demo simulates
# the built-in day/night world and maps it with camera + Wi-Fi + compass fusion into out/demo.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
BUILD_TARGET=ratslam bash scripts/build.sh
./build/apps/ratslam demo --overwrite --out "${1:-out/demo}"
