#!/usr/bin/env bash
# Installs the build into a scratch prefix and builds a separate CMake project against it, as a
# user's project would: find_package(ratslam), every exported library linked, and one source
# file that includes every installed header (include/ratslam/<folder>/<file>.h, included as
# "<folder>/<file>.h"). Fails when an installed header includes one that is not installed, when
# the package's dependencies are not found again, or when the program does not run.
# Usage: install_consumer_test.sh BUILD_DIR
set -euo pipefail
build_dir=$1
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
cmake --install "$build_dir" --prefix "$scratch/prefix" >/dev/null
headers=$(cd "$scratch/prefix/include/ratslam" && find . -name '*.h' | sed 's|^\./||' | sort)
[[ -n $headers ]] || { echo "no header installed under include/ratslam"; exit 1; }
mkdir -p "$scratch/consumer"
{
  for h in $headers; do echo "#include \"$h\""; done
  echo '#include <cstdio>'
  echo 'int main() {'
  echo '  std::printf("%s\n", ratslam::Status::Error("installed").message().c_str());'
  echo '  return 0;'
  echo '}'
} >"$scratch/consumer/main.cc"
cat >"$scratch/consumer/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.20)
project(consumer CXX)
set(CMAKE_CXX_STANDARD 20)
find_package(ratslam REQUIRED)
add_executable(consumer main.cc)
target_link_libraries(consumer ratslam::session ratslam::sweep ratslam::viewer ratslam::sim)
CMAKE
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
cmake -S "$scratch/consumer" -B "$scratch/consumer/build" "${generator[@]}" \
  -DCMAKE_PREFIX_PATH="$scratch/prefix" >"$scratch/configure.log" 2>&1 ||
  { cat "$scratch/configure.log"; exit 1; }
cmake --build "$scratch/consumer/build" >"$scratch/build.log" 2>&1 || { cat "$scratch/build.log"; exit 1; }
out=$("$scratch/consumer/build/consumer")
[[ $out == installed ]] || { echo "the consumer printed '$out'"; exit 1; }
echo "$(wc -w <<<"$headers") installed headers compile in a project of their own"
