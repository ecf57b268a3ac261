#!/usr/bin/env bash
# Dead-reckoned distance of every IPIN 2023 training log against its true path length, with the
# PDR orientation test off (before) and at the config's value (after): before the first
# ground-truth point (the calibration gesture and standing still) and during the walk (first to
# last ground-truth point; true length = the polyline through the points).
# Usage: scripts/pdr_distance.sh [build dir] [out dir] [config]
set -euo pipefail
build=${1:-build}
out=${2:-out/pdr-distance}
config=${3:-}
data=../shared/data/ipin2023-t3
mkdir -p "$out"
printf '[pdr]\nmin_orientation_steadiness = 0.0\n' > "$out/off.toml"
for f in "$data"/IPIN2023_T3_TrainingTrial*.txt; do
  name=$(basename "$f" .txt)
  "$build/apps/ratslam" import --overwrite --config "$out/off.toml" --data "$f" --out "$out/before/$name" > /dev/null 2>&1
  "$build/apps/ratslam" import --overwrite ${config:+--config "$config"} --data "$f" --out "$out/after/$name" > /dev/null 2>&1
done
/usr/bin/python3 - "$out" <<'PY'
import csv, glob, math, os, sys
out = sys.argv[1]
def rows(path):
    return list(csv.DictReader(open(path)))
def travel(path, t0, t1):
    # Odometry rows hold their speed from the previous row's time to their own.
    od = rows(path)
    before = during = 0.0
    for a, b in zip(od, od[1:]):
        t = float(b["time_s"])
        d = float(b["forward_speed_m_per_s"]) * (t - float(a["time_s"]))
        if t <= t0: before += d
        elif t <= t1: during += d
    return before, during
print("| log | true path m | before walk: off | on | walk: off | on |")
print("|---|---|---|---|---|---|")
total = [0.0] * 5
for d in sorted(glob.glob(os.path.join(out, "before", "*"))):
    name = os.path.basename(d)
    gt = rows(os.path.join(d, "ground_truth.csv"))
    t0, t1 = float(gt[0]["time_s"]), float(gt[-1]["time_s"])
    true = sum(math.hypot(float(b["x_m"]) - float(a["x_m"]), float(b["y_m"]) - float(a["y_m"]))
               for a, b in zip(gt, gt[1:]))
    off = travel(os.path.join(d, "odometry.csv"), t0, t1)
    on = travel(os.path.join(out, "after", name, "odometry.csv"), t0, t1)
    values = [true, off[0], on[0], off[1], on[1]]
    total = [a + b for a, b in zip(total, values)]
    label = name.replace("IPIN2023_T3_TrainingTrial", "").replace("_repetition", "-")
    print(f"| {label} | " + " | ".join(f"{v:.1f}" for v in values) + " |")
print("| all | " + " | ".join(f"{v:.1f}" for v in total) + " |")
PY
