#!/usr/bin/env bash
# The online RSSI offset learnt from every scan of a later session (as shipped) against learnt
# from walking scans only ([fused] rssi_offset_walking_only = true: a scan counts when the PDR
# made a step within its max_step_interval_s before it, so the calibration gesture and standing
# are left out), on the IPIN 2023 routes (four repetitions of each as one multi-session run,
# configs/ipin2023-wifi-compass.toml and configs/ipin2023-wifi.toml). Beside them an oracle
# offset: each later repetition's scans paired with repetition 01's scans within 2 m by ground
# truth (POSI points, linearly interpolated, same floor: scripts/ipin_nearest_scan.py's reader),
# the median over pairs of the median RSSI difference over their common APs (at least 5). The
# oracle pairs only scans between the first and last POSI point, so it is the walking offset.
# Usage: scripts/ipin_walking_offset.sh [DATA_DIR] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data/ipin2023-t3}
out=${2:-out/ipin-walking-offset}
bin=./build/apps/ratslam
mkdir -p "$out"
for mode in wifi wifi-compass; do
  cp "configs/ipin2023-$mode.toml" "$out/$mode-all.toml"
  sed 's/^online_rssi_offset = true$/online_rssi_offset = true\nrssi_offset_walking_only = true/' \
    "configs/ipin2023-$mode.toml" > "$out/$mode-walking.toml"
  grep -q '^rssi_offset_walking_only = true$' "$out/$mode-walking.toml"
done
for route in 01 02 03 21 22 23; do
  args=()
  for rep in 01 02 03 04; do args+=(--data "$data/IPIN2023_T3_TrainingTrial${route}_repetition${rep}.txt"); done
  for mode in wifi wifi-compass; do
    for variant in all walking; do
      "$bin" replay --quiet --overwrite --config "$out/$mode-$variant.toml" "${args[@]}" \
        --out "$out/$route-$mode-$variant" > /dev/null
    done
  done
done
/usr/bin/python3 - "$data" "$out" <<'PY'
import json, math, statistics, sys
data, out = sys.argv[1], sys.argv[2]
routes = ["01", "02", "03", "21", "22", "23"]

sys.path.insert(0, "scripts")
from ipin_nearest_scan import load  # scans with interpolated ground truth, stairs left out


def scans_with_truth(route, rep):
    path = f"{data}/IPIN2023_T3_TrainingTrial{route}_repetition{rep}.txt"
    return [(x, y, floor, readings) for _, (x, y), floor, readings in load(path)]

def oracle(route, rep):
    reference = scans_with_truth(route, "01")
    pairs = []
    for x, y, floor, s in scans_with_truth(route, rep):
        for rx, ry, rfloor, r in reference:
            if rfloor == floor and math.hypot(x - rx, y - ry) <= 2.0:
                common = [s[k] - r[k] for k in s if k in r]
                if len(common) >= 5:
                    pairs.append(statistics.median(common))
    return statistics.median(pairs) if pairs else float("nan")

def fmt(v):
    return f"{v:+.1f}"

print("| route | oracle dB (2 / 3 / 4) | mode | all scans: offsets dB | error dB | <=5 m | map ATE m | walking only: offsets dB | error dB | <=5 m | map ATE m |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
totals = {}
for route in routes:
    truth = [oracle(route, rep) for rep in ("02", "03", "04")]
    for mode in ("wifi", "wifi-compass"):
        cells = [route, " / ".join(fmt(v) for v in truth), "Wi-Fi + compass" if mode == "wifi-compass" else "Wi-Fi"]
        for variant in ("all", "walking"):
            j = json.load(open(f"{out}/{route}-{mode}-{variant}/summary.json"))
            offsets = j["wifi_rssi_offsets_db"][1:]
            error = sum(abs(o - t) for o, t in zip(offsets, truth))
            within = j.get("match_rate_within_m", {}).get("5", 0)
            t = totals.setdefault((mode, variant), [0.0, 0.0, 0.0])
            t[0] += error; t[1] += within / len(routes); t[2] += j["map_ate_m"] / len(routes)
            cells += [" / ".join(fmt(o) for o in offsets), f"{error:.1f}", f"{within:.2f}", f"{j['map_ate_m']:.2f}"]
        print("| " + " | ".join(cells) + " |")
for mode in ("wifi", "wifi-compass"):
    a, w = totals[(mode, "all")], totals[(mode, "walking")]
    print(f"| all six | | {mode} | | {a[0]:.1f} | {a[1]:.2f} | {a[2]:.2f} | | {w[0]:.1f} | {w[1]:.2f} | {w[2]:.2f} |")
PY
