#!/usr/bin/env bash
# The GNU parallel recipe of configs/README.md ("Sweeps on plain SSH hosts"), checked on this
# machine: a 6-task sweep whose tasks GNU parallel hands out through its SSH-login interface
# (":" is this host; on real hosts list them with -S host1,host2 and share DIR), then collect.
#   bash scripts/parallel_sweep_check.sh [path/to/ratslam]
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
program=$(realpath "${1:-build/apps/ratslam}")
if ! command -v parallel >/dev/null; then
  bash scripts/setup.sh parallel >/dev/null 2>&1 ||
    { echo "parallel check: SKIPPED: GNU parallel could not be installed"; exit 0; }
fi
work=$(mktemp -d /tmp/ratslam-parallel.XXXXXX)
trap 'rm -rf "$work"' EXIT
"$program" synthesize --out "$work/data" --laps 1 >/dev/null 2>&1
cat >"$work/sweep.toml" <<TOML
[sweep]
base_config = "$root/configs/synthetic.toml"
objective = "map_ate_m"
[[datasets]]
data = ["data"]
[parameters]
"camera.match_threshold" = [0.02, 0.03, 0.04]
"camera.shift_px" = [3, 5]
TOML
"$program" sweep plan "$work/sweep.toml" --out "$work/sweep" >/dev/null
tasks=$(($(wc -l <"$work/sweep/tasks.csv") - 1))
# The recipe: one `sweep task` per index, two at a time.
seq 0 $((tasks - 1)) | parallel --will-cite -j 2 -S : "$program" sweep task "$work/sweep" --index {} >/dev/null
"$program" sweep collect "$work/sweep" --format png,pdf
for plot in objective_by_parameter heatmap pareto; do
  for ext in png pdf; do
    [[ -s $work/sweep/plots/$plot.$ext ]] || { echo "parallel check: FAILED: no plots/$plot.$ext" >&2; exit 1; }
  done
done
head -c 5 "$work/sweep/plots/pareto.pdf" | grep -q '%PDF-' || { echo "parallel check: FAILED: pareto.pdf is no PDF" >&2; exit 1; }
ok=$(grep -c '"status": "ok"' "$work/sweep/results.json" || true)
if ((ok != tasks)); then
  echo "parallel check: FAILED: $ok of $tasks tasks succeeded" >&2
  exit 1
fi
echo "parallel check: PASSED ($tasks tasks through GNU parallel)"
