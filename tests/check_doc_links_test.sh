#!/usr/bin/env bash
# scripts/check_doc_links.py on a made-up page first (a known answer: one good link, a missing
# file and a missing heading must be the two reported), then on the project's own pages.
# Usage: check_doc_links_test.sh SOURCE_DIR
set -euo pipefail
source_dir=$1
tree=$(mktemp -d)
trap 'rm -rf "$tree"' EXIT
mkdir -p "$tree/docs"
printf '# Top\n\n## A section, with punctuation!\n' > "$tree/docs/other.md"
printf '[ok](docs/other.md#a-section-with-punctuation) [gone](docs/none.md) [bad](docs/other.md#nowhere)\n```\n[in a fence](docs/ignored.md)\n```\n' \
  > "$tree/README.md"
if out=$(/usr/bin/python3 "$source_dir/scripts/check_doc_links.py" "$tree"); then
  echo "check_doc_links.py accepted broken links"; exit 1
fi
[ "$(printf '%s\n' "$out" | wc -l)" = 2 ] || { echo "expected two problems, got:"; echo "$out"; exit 1; }
grep -q "README.md:1: docs/none.md: no such file" <<< "$out" || { echo "$out"; exit 1; }
grep -q "no heading #nowhere" <<< "$out" || { echo "$out"; exit 1; }
/usr/bin/python3 "$source_dir/scripts/check_doc_links.py" "$source_dir"
