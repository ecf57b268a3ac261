#!/usr/bin/env bash
# The FABMAP front end's new-place rule on the IPIN 2023 routes: how the map depends on the
# threshold, in single walks and in multi-session runs. configs/ipin2023-fabmap-wifi.toml (log
# odds, earlier sessions apart, their threshold calibrated in a first pass; match_log_odds 0) and
# three variants of it: earlier sessions' threshold set by hand (a grid of
# earlier_session_log_odds), the posterior rule (a grid of match_probability) and one log-odds
# threshold for every place (a grid of match_log_odds), run as sweeps (`ratslam sweep`) over every single walk
# and over each of the six training routes' four repetitions as one multi-session run; the b_out
# front end (configs/ipin2023-wifi-compass.toml) and dead reckoning (odometry_ate_m) in the same
# run as baselines.
# Prints a markdown table of mean map ATE and templates per rule and threshold, then the
# multi-session map ATE per route.
# Usage: scripts/ipin_fabmap_threshold_table.sh [data dir] [out dir] [ratslam binary]
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
data=$(realpath "${1:-../shared/data/ipin2023-t3}")
out=${2:-out/ipin-fabmap-threshold}
ratslam=$(realpath "${3:-build/apps/ratslam}")
mkdir -p "$out"
out=$(realpath "$out")

# The shipped config decides by log odds with earlier sessions apart and calibrates their
# threshold; the other rules are its variants (a line that is not there stops the script).
config=configs/ipin2023-fabmap-wifi.toml
variant() {  # out name, sed expression that must change a line
  sed "$2" "$config" > "$out/$1.toml"
  cmp -s "$config" "$out/$1.toml" && { echo "$1: $2 changed nothing" >&2; exit 1; }
  return 0
}
by_hand='s/^calibrate_earlier_session_log_odds = true$/calibrate_earlier_session_log_odds = false/'
cp "$config" "$out/calibrated.toml"
variant apart "$by_hand"
variant log-odds "$by_hand;"'s/^earlier_sessions_apart = true$/earlier_sessions_apart = false/'
variant posterior "$by_hand;"'s/^decide_by_log_odds = true$/decide_by_log_odds = false/;
  s/^earlier_sessions_apart = true$/earlier_sessions_apart = false/'

multi=""
for route in 01 02 03 21 22 23; do
  walks=""
  for rep in 01 02 03 04; do
    walks+="${walks:+, }\"$data/IPIN2023_T3_TrainingTrial${route}_repetition${rep}.txt\""
  done
  multi+=$'[[datasets]]\n'"data = [$walks]"$'\n'
done
single=$'[[datasets]]\n'"glob = \"$data/IPIN2023_T3_TrainingTrial*_repetition0*.txt\""$'\n'

run_sweep() {  # name, base config, datasets, parameters
  rm -rf "${out:?}/$1"
  {
    printf '[sweep]\nbase_config = "%s"\nobjective = "map_ate_m"\n' "$2"
    printf 'metrics = ["templates", "odometry_ate_m"]\n%s%s' "$3" "$4"
  } > "$out/$1.toml"
  "$ratslam" sweep plan "$out/$1.toml" --out "$out/$1" > /dev/null
  "$ratslam" sweep run "$out/$1" --jobs "$(nproc)" --quiet
  "$ratslam" sweep collect "$out/$1" > /dev/null
}
log_odds=$'[parameters]\n"fabmap_front_end.match_log_odds" = [-40.0, -20.0, -10.0, -5.0, -2.0, 0.0, 2.0, 5.0]\n'
posterior=$'[parameters]\n"fabmap_front_end.match_probability" = [0.1, 0.5, 0.9]\n'
apart=$'[parameters]\n"fabmap_front_end.earlier_session_log_odds" = [-40.0, -30.0, -20.0, -10.0, -5.0]\n'
for kind in multi single; do
  sets=$multi
  [[ $kind == single ]] && sets=$single
  run_sweep "$kind-log-odds" "$out/log-odds.toml" "$sets" "$log_odds"
  run_sweep "$kind-posterior" "$out/posterior.toml" "$sets" "$posterior"
  run_sweep "$kind-b-out" "$root/configs/ipin2023-wifi-compass.toml" "$sets" ""
  run_sweep "$kind-apart" "$out/apart.toml" "$sets" "$apart"
  run_sweep "$kind-calibrated" "$out/calibrated.toml" "$sets" ""
done

/usr/bin/python3 - "$out" <<'EOF'
import json, sys
out = sys.argv[1]

def points(name):
    """{threshold or None: (mean map ATE, mean templates, mean odometry ATE, runs)}"""
    runs = json.load(open(f"{out}/{name}/results.json"))["runs"]
    by = {}
    for r in runs:
        if r["status"] != "ok":
            sys.exit(f"{name}: run {r['index']} {r['status']}")
        key = next(iter(r["parameters"].values()), None)
        by.setdefault(key, []).append(r["metrics"])
    mean = lambda ms, k: sum(m[k] for m in ms) / len(ms)
    return {k: (mean(ms, "map_ate_m"), mean(ms, "templates"), mean(ms, "odometry_ate_m"), len(ms))
            for k, ms in by.items()}

rows = [("log odds (decide_by_log_odds)", "log-odds"), ("posterior (match_probability)", "posterior"),
        ("log odds 0, earlier sessions apart (earlier_session_log_odds)", "apart"),
        ("log odds 0, earlier sessions apart, calibrated (shipped)", "calibrated"),
        ("b_out (ipin2023-wifi-compass)", "b-out")]
multi = {name: points(f"multi-{name}") for _, name in rows}
single = {name: points(f"single-{name}") for _, name in rows}
n_multi = next(iter(multi["b-out"].values()))[3]
n_single = next(iter(single["b-out"].values()))[3]
print(f"| rule | threshold | multi-session ({n_multi} runs): mean map ATE m | templates "
      f"| single walks ({n_single}): mean map ATE m | templates |")
print("|---|---|---|---|---|---|")
for label, name in rows:
    for key in multi[name]:
        m, s = multi[name][key], single[name][key]
        shown = "-" if key is None else key
        print(f"| {label} | {shown} | {m[0]:.2f} | {m[1]:.0f} | {s[0]:.2f} | {s[1]:.0f} |")
m = next(iter(multi["b-out"].values()))
s = next(iter(single["b-out"].values()))
print(f"| dead reckoning (PDR, compass) | - | {m[2]:.2f} | - | {s[2]:.2f} | - |")

# Multi-session map ATE per route (the run's first data set names the route).
def per_route(name):
    runs = json.load(open(f"{out}/multi-{name}/results.json"))["runs"]
    by = {}
    for r in runs:
        key = next(iter(r["parameters"].values()), None)
        route = r["data"][0].split("TrainingTrial")[1][:2]
        by.setdefault(key, {})[route] = r["metrics"]["map_ate_m"]
    return by
print()
routes = sorted(per_route("b-out")[None])
print("| rule | threshold | " + " | ".join(f"route {r}" for r in routes) + " |")
print("|---|---|" + "---|" * len(routes))
for label, name in rows:
    for key, ate in per_route(name).items():
        shown = "-" if key is None else key
        print(f"| {label} | {shown} | " + " | ".join(f"{ate[r]:.2f}" for r in routes) + " |")
EOF
