#!/usr/bin/env bash
# Does a long run stay flat? Replays the synthetic loop x10 (12,114 frames) with OpenRatSLAM's
# camera match threshold 0.004, at which every frame makes a new template and experience, and
# compares the second half's wall time with the first's. Each binary runs the whole replay, the
# first half (--until) and no frame at all (start-up), REPEAT times, alternating binaries so that
# machine load hits them alike; prints each run and the medians as a markdown table.
# Usage: scripts/long_run_halves.sh [out dir] [ratslam binary ...]   (REPEAT=5 by default)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/long-run-halves}
shift || true
binaries=("$@")
((${#binaries[@]})) || binaries=(build/apps/ratslam)
repeat=${REPEAT:-5}
mkdir -p "$out"
"${binaries[0]}" synthesize --laps 10 --out "$out/data" --overwrite > /dev/null
sed 's/^match_threshold = 0.03$/match_threshold = 0.004/' configs/synthetic.toml > "$out/config.toml"
grep -q '^match_threshold = 0.004$' "$out/config.toml" || { echo "threshold not set" >&2; exit 1; }
half=$(awk -F, 'NR > 1 { t = $1 } END { printf "%.2f", t / 2 }' "$out/data/images.csv")

seconds() {  # binary, extra arguments...: wall seconds of one replay
  local b=$1
  shift
  local start end
  start=$(date +%s.%N)
  "$b" replay --quiet --overwrite --config "$out/config.toml" --data "$out/data" --out "$out/run" \
    "$@" > /dev/null
  end=$(date +%s.%N)
  echo "$end - $start" | bc -l
}

declare -A runs
for ((i = 0; i < repeat; ++i)); do
  for b in "${binaries[@]}"; do
    whole=$(seconds "$b")
    first=$(seconds "$b" --until "$half")
    none=$(seconds "$b" --until 0)
    runs[$b]+="$whole $first $none"$'\n'
  done
done
echo "| binary | runs | whole run (s) | first half (s) | second half (s) | second / first |"
echo "|---|---|---|---|---|---|"
for b in "${binaries[@]}"; do
  printf '%s' "${runs[$b]}" | /usr/bin/python3 -c '
import statistics, sys
rows = [list(map(float, l.split())) for l in sys.stdin if l.strip()]
first = [f - n for w, f, n in rows]   # frames of the first half, start-up taken off
second = [w - f for w, f, n in rows]
ratio = [s / f for s, f in zip(second, first)]
med = statistics.median
print(f"| {sys.argv[1]} | {len(rows)} | {med(r[0] for r in rows):.2f} | {med(first):.2f} |"
      f" {med(second):.2f} | {med(ratio):.2f} (runs {min(ratio):.2f}-{max(ratio):.2f}) |")
' "$b"
done
