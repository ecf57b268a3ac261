#!/usr/bin/env bash
# scripts/check_layers.py on a made-up two-library tree (a known answer: the low library's header
# includes the high one's), then on this project with its known list.
# Usage: check_layers_test.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
source_dir=$1
build_dir=$2
tree=$(mktemp -d)
trap 'rm -rf "$tree"' EXIT
mkdir -p "$tree/src/low" "$tree/src/high" "$tree/build"
printf '#include "high/b.h"\n' > "$tree/src/low/a.h"
printf '#include "low/a.h"\n' > "$tree/src/high/b.h"
printf 'STATIC_LIBRARY|ratslam_low|%s/src/low||\nSTATIC_LIBRARY|ratslam_high|%s/src/high|ratslam::low|\n' \
  "$tree" "$tree" > "$tree/build/ratslam_layers.txt"
if out=$(/usr/bin/python3 "$source_dir/scripts/check_layers.py" "$tree/build" "$tree/src"); then
  echo "check_layers.py accepted a lower layer including a higher one:"; echo "$out"; exit 1
fi
grep -qF "NEW: low/a.h:1: includes high/b.h of ratslam_high, which ratslam_low does not link" <<< "$out" || {
  echo "unexpected report:"; echo "$out"; exit 1; }
if grep -q "high/b.h:1" <<< "$out"; then echo "flagged the allowed direction: $out"; exit 1; fi
# A namespaced folder whose header opens the parent namespace instead: reported.
printf 'namespace low {\n}\n' >> "$tree/src/low/a.h"
printf 'low low\n' > "$tree/namespaces.txt"
printf '' > "$tree/known.txt"
if out=$(/usr/bin/python3 "$source_dir/scripts/check_layers.py" "$tree/build" "$tree/src" \
  "$tree/known.txt" "$tree/namespaces.txt"); then :; fi
if grep -q "low/a.h" <<< "$(grep namespace <<< "$out")"; then
  echo "flagged a header in its own namespace: $out"; exit 1; fi
# A namespace nested in the folder's is its own (a detail namespace); one that only shares the
# prefix of its name is not.
printf 'namespace low::detail {\n}\nnamespace lower {\n}\n' >> "$tree/src/low/a.h"
out=$(/usr/bin/python3 "$source_dir/scripts/check_layers.py" "$tree/build" "$tree/src" \
  "$tree/known.txt" "$tree/namespaces.txt" || true)
grep -qF "opens namespace lower, not low" <<< "$out" || {
  echo "missed a namespace that only shares the folder's prefix:"; echo "$out"; exit 1; }
if grep -q "low::detail" <<< "$out"; then echo "flagged a nested namespace: $out"; exit 1; fi
printf 'high high\n' > "$tree/namespaces.txt"
out=$(/usr/bin/python3 "$source_dir/scripts/check_layers.py" "$tree/build" "$tree/src" \
  "$tree/known.txt" "$tree/namespaces.txt" || true)
grep -qF "NEW: high/b.h: does not open namespace high" <<< "$out" || {
  echo "missed a header outside its folder's namespace:"; echo "$out"; exit 1; }
/usr/bin/python3 "$source_dir/scripts/check_layers.py" "$build_dir" "$source_dir" \
  "$source_dir/scripts/layers_known.txt" "$source_dir/scripts/layers_namespaces.txt"
