#!/usr/bin/env bash
# Installs every Debian 12 package that the build, the tests, the benchmarks and the demo need,
# and any packages named as arguments (scripts/fuzz.sh adds clang-14 and libfuzzer-14-dev).
# Idempotent: packages already present are left alone. Run as root (or through sudo).
set -euo pipefail

packages=(
  build-essential cmake ninja-build ccache pkg-config git clang-format python3
  libboost-dev libboost-graph-dev libeigen3-dev
  libopencv-dev libosmesa6-dev libtomlplusplus-dev nlohmann-json3-dev libcli11-dev zlib1g-dev
  libcairo2-dev fonts-dejavu-core
  libgtest-dev libgmock-dev googletest libbenchmark-dev
  pybind11-dev python3-pybind11 python3-numpy python3-dev
  librosbag-storage-dev libsensor-msgs-dev libnav-msgs-dev
  libzstd-dev liblz4-dev libsqlite3-dev
  "$@"
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]})); then
  sudo_cmd=()
  if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi
  echo "setup: installing ${missing[*]}"
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "setup: all ${#packages[@]} packages already installed"
fi
