#!/usr/bin/env bash
# Coverage-guided fuzzing of every reader with libFuzzer (Debian's clang-14 and libfuzzer-14-dev,
# with address and undefined-behaviour sanitizers). Builds into build-fuzz/, starts each harness
# from its built-in seeds, the committed regression inputs and (where ../shared/data has them)
# excerpts of real files, and runs it FUZZ_SECONDS seconds (default 30; run 600 before a
# release), two harnesses at a time. Prints executions, coverage and findings per harness and
# writes them to build-fuzz/fuzz-summary.txt. A crash fails the script: the input is kept in
# build-fuzz/findings/<harness>/; fix it and copy it to fuzz/regressions/<harness>/ so ctest
# replays it for ever.
#   FUZZ_SECONDS=600 bash scripts/fuzz.sh            # all harnesses, ten minutes each
#   FUZZ_SECONDS=60 bash scripts/fuzz.sh map_file_fuzzer
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
seconds=${FUZZ_SECONDS:-30}
build=$root/build-fuzz
shared=$root/../shared/data

bash scripts/setup.sh clang-14 libfuzzer-14-dev

harnesses=(config_fuzzer ini_fuzzer map_file_fuzzer visual_model_fuzzer dataset_fuzzer
           ipin_log_fuzzer msft_log_fuzzer ujiindoorloc_fuzzer uji_long_term_fuzzer world_fuzzer sweep_file_fuzzer sweep_folder_fuzzer wifi_map_fuzzer
           run_folder_fuzzer output_list_fuzzer rosbag_fuzzer ros2_bag_fuzzer ros2_cdr_fuzzer video_log_fuzzer
           descriptor_fuzzer command_line_fuzzer)
if (($#)); then harnesses=("$@"); fi

source scripts/ccache_env.sh
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
CC=clang-14 CXX=clang++-14 cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DRATSLAM_FUZZ=ON -DRATSLAM_BUILD_TESTS=OFF -DRATSLAM_BUILD_BENCHMARKS=OFF -DRATSLAM_WERROR=ON "${ccache_args[@]}" >/dev/null
targets=()
for h in "${harnesses[@]}"; do targets+=("$h" "${h}_replay"); done
cmake --build "$build" --parallel "$(nproc)" --target "${targets[@]}"

# Excerpts of real files (never committed: the data sets have their own licences).
excerpt() {  # harness, file, lines
  [[ -f $2 ]] || return 0
  head -n "$3" "$2" >"$build/corpus/$1/excerpt-$(basename "$2")"
}

rm -rf "$build/findings" "$build/logs"
mkdir -p "$build/corpus" "$build/findings" "$build/logs"
for h in "${harnesses[@]}"; do
  mkdir -p "$build/corpus/$h" "$build/findings/$h"
  "$build/fuzz/${h}_replay" --seeds "$build/corpus/$h" >/dev/null
  if [[ -d fuzz/regressions/$h ]]; then
    find "fuzz/regressions/$h" -type f ! -name README.md -exec cp {} "$build/corpus/$h/" \;
  fi
done
[[ -d $build/corpus/config_fuzzer ]] && cp configs/*.toml "$build/corpus/config_fuzzer/" 2>/dev/null || true
[[ -d $build/corpus/sweep_file_fuzzer ]] && cp configs/sweeps/*.toml "$build/corpus/sweep_file_fuzzer/" 2>/dev/null || true
for f in "$shared"/ipin2023-t3/*TrainingTrial0[12]_repetition01.txt; do
  [[ -d $build/corpus/ipin_log_fuzzer ]] && excerpt ipin_log_fuzzer "$f" 400
done
for f in $(find "$shared/msft-ilc20-site1" -name '*.txt' 2>/dev/null | sort | head -n 2); do
  [[ -d $build/corpus/msft_log_fuzzer ]] && excerpt msft_log_fuzzer "$f" 400
done
# ROS 2 bags from the independent writers the tests use (skipped where node or npm is missing).
if [[ -d $build/corpus/ros2_bag_fuzzer ]] && bash scripts/ros2_fixtures.sh "$build/ros2-seeds" 2>/dev/null; then
  cp "$build"/ros2-seeds/raw*.mcap "$build"/ros2-seeds/raw_db3/*.db3 "$build/corpus/ros2_bag_fuzzer/"
fi
[[ -d $build/corpus/ujiindoorloc_fuzzer ]] &&
  excerpt ujiindoorloc_fuzzer "$shared/ujiindoorloc/trainingData.csv" 8

# The harnesses write each input (and the data sets they read back) to scratch folders under
# TMPDIR, and the writers flush every file to disk, which on a disk costs most of an execution:
# a RAM disk where there is one (the files are thrown away).
if [[ -z ${TMPDIR:-} && -d /dev/shm && -w /dev/shm ]]; then export TMPDIR=/dev/shm; fi

run_one() {
  local h=$1
  local log=$build/logs/$h.log
  local dict=()  # tokens a harness's mutations rarely make by chance (fuzz/<harness>.dict)
  [[ -f fuzz/$h.dict ]] && dict=(-dict="fuzz/$h.dict")
  ASAN_OPTIONS=detect_leaks=0 "$build/fuzz/$h" "$build/corpus/$h" "${dict[@]}" -max_total_time="$seconds" \
    -seed="${FUZZ_SEED:-1}" -timeout=60 -report_slow_units=30 -rss_limit_mb=4096 -max_len=262144 -print_final_stats=1 \
    -artifact_prefix="$build/findings/$h/" >"$log" 2>&1 || true
}
export -f run_one
export build seconds
echo "fuzz: ${#harnesses[@]} harnesses, ${seconds} s each, two at a time"
printf '%s\n' "${harnesses[@]}" | xargs -P 2 -I{} bash -c 'run_one {}'

# The table goes to the summary file first and is shown after: a status set inside a pipeline
# (`{ ... } | tee`) would be lost with its subshell, and a finding would not fail the script.
status=0
printf '%-22s %12s %8s %8s %s\n' harness executions cov ft findings >"$build/fuzz-summary.txt"
for h in "${harnesses[@]}"; do
  log=$build/logs/$h.log
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -n 1 | grep -o '[0-9]*' || echo 0)
  ft=$(grep -o 'ft: [0-9]*' "$log" | tail -n 1 | grep -o '[0-9]*' || echo 0)
  # Crashes, timeouts, leaks and out-of-memory inputs; slow units are only reported.
  found=$(find "$build/findings/$h" -type f ! -name 'slow-unit-*' | wc -l)
  printf '%-22s %12s %8s %8s %s\n' "$h" "${runs:-0}" "${cov:-0}" "${ft:-0}" "$found" \
    >>"$build/fuzz-summary.txt"
  if ((found > 0)) || ! grep -q 'Done [0-9]* runs' "$log"; then status=1; fi
done
cat "$build/fuzz-summary.txt"
if ((status)); then
  echo "fuzz: a harness crashed or stopped early; logs in $build/logs, inputs in $build/findings" >&2
  for h in "${harnesses[@]}"; do
    if ! grep -q 'Done [0-9]* runs' "$build/logs/$h.log"; then tail -n 30 "$build/logs/$h.log" >&2; fi
  done
fi
exit $status
