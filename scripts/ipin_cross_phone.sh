#!/usr/bin/env bash
# Cross-phone matches on the IPIN 2023 training routes: repetitions 01-02 were recorded with one
# phone (SM-A520F), 03-04 with another (SM-G930F). Runs the four repetitions of each route as one
# multi-session run with a config without its online_rssi_offset lines (off), with that plus
# [wifi] offset_invariant = true, and with [fused] online_rssi_offset = true (the second phone's
# offset estimated online; the shipped fused IPIN configs), and prints
# per route: template matches between the two phones' sessions, the share of them
# within 5 m and 10 m of where the matched template was stored, and map ATE. With a FABMAP front-end
# config (a [fabmap_front_end] section) the variants are the config and the config plus
# [fabmap_front_end] online_rssi_offset = true (offset invariance is an eq. 6 option).
# Usage: scripts/ipin_cross_phone.sh [config] [out dir]
set -euo pipefail
cd "$(dirname "$0")/.."
config=${1:-configs/ipin2023-wifi-compass.toml}
out=${2:-out/ipin-cross-phone}
data=../shared/data/ipin2023-t3
bin=./build/apps/ratslam
mkdir -p "$out"
# "plain" is the config without the online offset (the shipped IPIN fused configs have it on).
sed '/^online_rssi_offset = /d' "$config" > "$out/plain.toml"
config=$out/plain.toml
variants=(plain invariant online)
if grep -q '^\[fabmap_front_end\]' "$config"; then
  variants=(plain online)
  sed 's/^\[fabmap_front_end\]$/[fabmap_front_end]\nonline_rssi_offset = true/' "$config" \
    > "$out/online.toml"
  echo "| route | cross-phone matches | <=5 m | <=10 m | map ATE m | online offset: matches | <=5 m | <=10 m | map ATE m | offsets dB |"
  echo "|---|---|---|---|---|---|---|---|---|---|"
else
  grep -q '^\[wifi\]' "$config" || { echo "$config has no [wifi] section" >&2; exit 1; }
  sed 's/^\[wifi\]$/[wifi]\noffset_invariant = true/' "$config" > "$out/invariant.toml"
  grep -q '^\[fused\]' "$config" || { echo "$config has no [fused] section" >&2; exit 1; }
  sed 's/^\[fused\]$/[fused]\nonline_rssi_offset = true/' "$config" > "$out/online.toml"
  echo "| route | cross-phone matches | <=5 m | <=10 m | map ATE m | offset-invariant: matches | <=5 m | <=10 m | map ATE m | online offset: matches | <=5 m | <=10 m | map ATE m | offsets dB |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
fi
for route in 01 02 03 21 22 23; do
  args=()
  for rep in 01 02 03 04; do args+=(--data "$data/IPIN2023_T3_TrainingTrial${route}_repetition${rep}.txt"); done
  "$bin" import --overwrite "${args[@]}" --out "$out/data-$route" > /dev/null 2>&1
  runs=()
  for v in "${variants[@]}"; do
    c="$out/$v.toml"
    "$bin" replay --quiet --overwrite --config "$c" --data "$out/data-$route" --out "$out/$v-$route" \
      > /dev/null
    runs+=("$out/$v-$route")
  done
  /usr/bin/python3 - "$out/data-$route" "${runs[@]}" "$route" <<'PY'
import bisect, csv, json, math, re, sys
data = sys.argv[1]
starts = [float(x) for x in re.search(r"session_start_times_s = \[(.*)\]",
                                      open(data + "/manifest.toml").read()).group(1).split(",")]
gt = [(float(r["time_s"]), float(r["x_m"]), float(r["y_m"]))
      for r in csv.DictReader(open(data + "/ground_truth.csv"))]
times = [g[0] for g in gt]
def session(t):
    return max(k for k, s in enumerate(starts) if t >= s or k == 0)
def truth(t):
    # Linear interpolation inside one session's ground truth; none outside it.
    i = bisect.bisect_left(times, t)
    if i < len(gt) and gt[i][0] == t: return gt[i][1:]
    if i == 0 or i == len(gt): return None
    a, b = gt[i - 1], gt[i]
    if session(a[0]) != session(b[0]): return None
    f = (t - a[0]) / (b[0] - a[0])
    return (a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2]))
cells = []
for run in sys.argv[2:-1]:
    created, distances = {}, []
    for r in csv.DictReader(open(run + "/frames.csv")):
        t, tid = float(r["time_s"]), int(r["template_id"])
        if r["new_template"] == "1":
            created[tid] = t
            continue
        if r["recent"] == "1": continue
        then = created[tid]
        if (session(t) >= 2) == (session(then) >= 2): continue  # same phone
        a, b = truth(t), truth(then)
        if a is None or b is None: continue
        distances.append(math.hypot(a[0] - b[0], a[1] - b[1]))
    n = len(distances)
    rate = lambda d: f"{sum(x <= d for x in distances) / n:.2f}" if n else "-"
    summary = json.load(open(run + "/summary.json"))
    cells += [str(n), rate(5), rate(10), f"{summary['map_ate_m']:.2f}"]
offsets = json.load(open(sys.argv[-2] + "/summary.json")).get("wifi_rssi_offsets_db", [])
cells.append(" / ".join(f"{x:.1f}" for x in offsets[1:]))
print(f"| {sys.argv[-1]} | " + " | ".join(cells) + " |")
PY
done
