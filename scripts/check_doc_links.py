#!/usr/bin/python3
"""Every relative link of the project's markdown (README.md, CHANGELOG.md, configs/README.md,
docs/**/*.md, or the files given) names a file that exists, and a `#anchor` names a heading of
the target (GitHub's rule: lower case, punctuation dropped, spaces to hyphens). Prints each
broken link with its file and line; exit status 1 if there is one.
Usage: check_doc_links.py SOURCE_DIR [FILE.md ...]"""
import glob
import os
import re
import sys


def anchors(path):
    found = set()
    with open(path, encoding="utf-8") as f:
        for line in f:
            m = re.match(r"#+ (.*)", line)
            if m:
                title = re.sub(r"[^\w\- ]", "", m.group(1).strip().lower())
                found.add(title.replace(" ", "-"))
    return found


def broken_links(root, files):
    problems = []
    for f in files:
        with open(f, encoding="utf-8") as text:
            lines = text.read().split("\n")
        fence = False
        for number, line in enumerate(lines, 1):
            if line.startswith("```"):
                fence = not fence
            if fence:
                continue
            for m in re.finditer(r"\]\(([^)\s]+)\)", line):
                link = m.group(1)
                if re.match(r"[a-z]+:", link):
                    continue  # http:, https:, mailto:
                path, _, anchor = link.partition("#")
                target = os.path.normpath(os.path.join(os.path.dirname(f), path)) if path else f
                where = f"{os.path.relpath(f, root)}:{number}: {link}"
                if not os.path.exists(target):
                    problems.append(f"{where}: no such file")
                elif anchor and target.endswith(".md") and anchor not in anchors(target):
                    problems.append(f"{where}: no heading #{anchor} in {os.path.relpath(target, root)}")
    return problems


def main():
    root = sys.argv[1]
    files = sys.argv[2:] or (
        [os.path.join(root, p) for p in ("README.md", "CHANGELOG.md", "configs/README.md")]
        + sorted(glob.glob(os.path.join(root, "docs", "**", "*.md"), recursive=True)))
    problems = broken_links(root, [f for f in files if os.path.exists(f)])
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
