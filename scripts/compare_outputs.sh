#!/usr/bin/env bash
# Runs the shipped configs with two `ratslam` binaries and reports every output file that differs
# (summary/evaluation JSON compared without wall times and the provenance `run` object). For refactors that must keep outputs
# bit-identical:
#   git worktree add /tmp/old HEAD~1 && BUILD_DIR=/tmp/old-build BUILD_TARGET=ratslam \
#     bash /tmp/old/scripts/build.sh && bash scripts/compare_outputs.sh /tmp/old-build/apps/ratslam build/apps/ratslam
# Extra JSON keys to ignore (e.g. a new summary key) can be listed in IGNORE_KEYS.
set -uo pipefail
cd "$(dirname "$0")/.."
root=$PWD
old=$(realpath "$1")
new=$(realpath "$2")
work=${3:-$(mktemp -d)}
data=$root/../shared/data
ignore="wall_seconds calibration_wall_seconds frames_per_second query_time_ms wall_time_s run ${IGNORE_KEYS:-}"

run_all() {  # binary, folder
  local b=$1 o=$2 c=$root/configs r=$data/ipin2023-t3/IPIN2023_T3_TrainingTrial01
  mkdir -p "$o" && cd "$o" || return
  "$b" demo --out demo --quiet >/dev/null 2>&1; echo "demo $?"
  "$b" synthesize --out syn >/dev/null 2>&1
  "$b" replay --config "$c/synthetic.toml" --data syn --out synthetic --quiet >/dev/null 2>&1
  echo "synthetic $?"
  if [[ -f ${r}_repetition01.txt ]]; then
    "$b" replay --config "$c/ipin2023-wifi-compass.toml" --data "${r}_repetition01.txt" \
      --data "${r}_repetition02.txt" --out ipin-wc --quiet >/dev/null 2>&1; echo "ipin-wc $?"
    "$b" replay --config "$c/ipin2023-fabmap-wifi.toml" --data "${r}_repetition01.txt" \
      --data "${r}_repetition02.txt" --out ipin-fabmap --quiet >/dev/null 2>&1
    echo "ipin-fabmap $?"
  fi
  "$b" simulate --world apartment --out apt --quiet >/dev/null 2>&1
  "$b" replay --config "$c/sim-fused.toml" --data apt --out sim-fused --quiet >/dev/null 2>&1
  echo "sim-fused $?"
  if [[ -d $data/msft-ilc20-site1 ]]; then
    "$b" evaluate --config "$c/msft-ilc20-wifi.toml" --map "$data/msft-ilc20-site1" \
      --query "$data/msft-ilc20-site1" --out msft --quiet >/dev/null 2>&1; echo "msft $?"
  fi
  cd "$root" || return
}

echo "old: $old"; run_all "$old" "$work/old"
echo "new: $new"; run_all "$new" "$work/new"
differ=0
while IFS= read -r f; do
  a=$work/old/$f b=$work/new/$f
  if [[ ! -f $b ]]; then echo "MISSING $f"; differ=1; continue; fi
  case $f in
    */.ratslam.lock) ;;  # names the writing process and binary
    *.json)
      strip="import json,sys; s=json.load(open(sys.argv[1])); [s.pop(k,None) for k in sys.argv[2].split()]; print(json.dumps(s,sort_keys=True))"
      cmp -s <(/usr/bin/python3 -c "$strip" "$a" "$ignore") <(/usr/bin/python3 -c "$strip" "$b" "$ignore") ||
        { echo "DIFF $f"; differ=1; } ;;
    *) cmp -s "$a" "$b" || { echo "DIFF $f"; differ=1; } ;;
  esac
done < <(cd "$work/old" && find . -type f | sort)
((differ)) && echo "outputs differ (runs in $work)" || echo "all outputs identical (runs in $work)"
exit $differ
