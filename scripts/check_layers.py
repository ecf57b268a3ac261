#!/usr/bin/python3
"""Layering check by the CMake graph. Fails when
  - a source file includes a header of a library that the target compiling it does not link
    (directly or through the libraries it links): a lower layer reaching up, or a dependency
    the build does not declare;
  - a header includes a header of a library that the header's own library (the one with the
    deepest folder holding it) does not link;
  - a library in a sub-folder of another library's folder links that parent (a child above its
    parent: folders should say which way the layers go);
  - a header of a folder listed in NAMESPACES_FILE opens a named namespace at its top level
    other than the folder's or one nested in it (folder = library = namespace).

Usage: check_layers.py BUILD_DIR SOURCE_DIR [KNOWN_FILE [NAMESPACES_FILE]]
BUILD_DIR/ratslam_layers.txt (written by CMakeLists.txt at configure time) gives every target's
type, folder, direct links and sources. KNOWN_FILE lists violations that are known and still to
be removed, one per line as printed; a listed one that no longer occurs is an error too, so the
list only shrinks. Prints each violation; exit 1 if any is new or a known one is gone."""
import os
import re
import sys


def main():
    build, source = sys.argv[1], os.path.realpath(sys.argv[2])
    known_file = sys.argv[3] if len(sys.argv) > 3 else None
    namespaces_file = sys.argv[4] if len(sys.argv) > 4 else None
    folder_of, links, sources, libraries = {}, {}, {}, set()
    with open(os.path.join(build, "ratslam_layers.txt")) as f:
        for line in f:
            kind, name, folder, deps, srcs = line.rstrip("\n").split("|")
            folder = os.path.relpath(os.path.realpath(folder), source)
            if folder.startswith(".."):
                continue
            folder_of[name] = folder
            if kind.endswith("LIBRARY") and name.startswith("ratslam_"):
                libraries.add(name)
            links[name] = set()
            for dep in deps.split(";"):
                dep = re.sub(r"^\$<LINK_ONLY:(.*)>$", r"\1", dep)
                if dep.startswith("ratslam::"):
                    dep = "ratslam_" + dep[len("ratslam::"):]
                links[name].add(dep)
            sources[name] = [os.path.relpath(os.path.realpath(os.path.join(folder, s)), source)
                             if not os.path.isabs(s) else os.path.relpath(s, source)
                             for s in srcs.split(";") if s]
    for name in links:
        links[name] &= libraries

    def closure(name):
        seen, todo = set(), [name]
        while todo:
            for dep in links.get(todo.pop(), ()):
                if dep not in seen:
                    seen.add(dep)
                    todo.append(dep)
        return seen

    below = {name: closure(name) | {name} for name in links}
    by_depth = sorted(((n, folder_of[n]) for n in libraries), key=lambda item: -len(item[1]))

    def library_of(path):
        for name, folder in by_depth:
            if folder == "." or path.startswith(folder + "/"):
                return name
        return None

    problems = set()
    for name in libraries:
        folder = folder_of[name]
        for other in libraries:
            parent = folder_of[other]
            if other != name and folder.startswith(parent + "/") and other in below[name]:
                problems.add(f"{folder}: {name} links {other}, the library of its parent folder "
                             f"{parent}")
    include = re.compile(r'^\s*#\s*include\s+"([^"]+)"')

    def check(path, target):
        with open(os.path.join(source, path), errors="replace") as f:
            for number, line in enumerate(f, 1):
                m = include.match(line)
                if not m or not os.path.exists(os.path.join(source, m.group(1))):
                    continue
                them = library_of(m.group(1))
                if them and them not in below[target]:
                    problems.add(f"{path}:{number}: includes {m.group(1)} of {them}, which "
                                 f"{target} does not link")

    for target, files in sources.items():
        for path in files:
            if path.endswith((".cc", ".cpp")) and os.path.exists(os.path.join(source, path)):
                check(path, target)
    for root, dirs, files in os.walk(source):
        dirs[:] = [d for d in dirs if not d.startswith((".", "build", "out"))]
        for file in files:
            if file.endswith(".h"):
                path = os.path.relpath(os.path.join(root, file), source)
                owner = library_of(path)
                if owner:
                    check(path, owner)
    if namespaces_file:
        with open(namespaces_file) as f:
            namespaced = dict(l.split() for l in f if l.strip() and not l.startswith("#"))
        opening = re.compile(r"^namespace\s+([\w:]+)\s*\{")
        for folder, namespace in namespaced.items():
            headers = sorted(h for h in os.listdir(os.path.join(source, folder)) if h.endswith(".h"))
            if not headers:
                problems.add(f"{folder}: no headers, but listed with namespace {namespace}")
            for header in headers:
                path = os.path.join(folder, header)
                with open(os.path.join(source, path), errors="replace") as f:
                    opened = [(n, m.group(1)) for n, line in enumerate(f, 1)
                              if (m := opening.match(line))]
                def own(name):  # the folder's namespace or one nested in it (a detail namespace)
                    return name == namespace or name.startswith(namespace + "::")
                if not any(own(name) for _, name in opened):
                    problems.add(f"{path}: does not open namespace {namespace}")
                for number, name in opened:
                    if not own(name):
                        problems.add(f"{path}:{number}: opens namespace {name}, not {namespace}")
    known = set()
    if known_file:
        with open(known_file) as f:
            known = {l.rstrip("\n") for l in f if l.strip() and not l.startswith("#")}
    problems = sorted(problems)
    new = [p for p in problems if p not in known]
    gone = sorted(known - set(problems))
    for p in problems:
        print(("known: " if p in known else "NEW: ") + p)
    for p in gone:
        print("fixed, remove from the known list: " + p)
    print(f"{len(problems)} layering problems, {len(new)} new, {len(gone)} fixed")
    return 1 if new or gone else 0


if __name__ == "__main__":
    sys.exit(main())
