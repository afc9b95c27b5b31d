#!/usr/bin/env python3
"""Holds the tree to its description (CONTRIBUTING.md "Layout",
docs/architecture.md "Libraries"):

- every library rms_library(NAME ...) lives in a folder NAME/ (or
  tools/NAME/) with its public headers in include/rms/NAME/ only;
- docs/architecture.md's table names every library, and its diagram's links
  reach exactly the libraries the CMake files make each one reach (a library
  added, removed or relinked without the diagram following fails here).

Exits 1 naming each mismatch."""

import glob
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def cmake_libraries():
    """{name: (folder, set of rms libraries linked, public or private)}."""
    libs = {}
    for path in glob.glob(os.path.join(ROOT, "**", "CMakeLists.txt"), recursive=True):
        rel = os.path.relpath(path, ROOT)
        if rel.startswith(("build", "fuzz")) or "node_modules" in rel:
            continue
        text = re.sub(r"#.*", "", open(path).read())
        for m in re.finditer(r"rms_library\(\s*(\w+)(.*?)\)", text, re.S):
            links = set(re.findall(r"rms::(\w+)", m.group(2)))
            libs[m.group(1)] = (os.path.dirname(rel), links)
    return libs


def diagram_links(doc):
    """{name: set of libraries it links}, from the diagram's tree: a node
    links its parent (the node it hangs from, or the left of '──'), and
    what '(+ ...)' names; 'X = a + b (+ c, privately)' links a, b and c."""
    block = doc[doc.index("## Libraries"):]
    lines = [line for line in block.split("\n\n")[2].splitlines() if line.startswith("    ")]
    links, stack = {}, []  # stack: (column, name)

    def add(item, parent):
        m = re.match(r"\s*(\w+)\s*(?:\(\+ ([^)]*)\))?", item)
        name = m.group(1)
        extra = {w.strip() for w in (m.group(2) or "").split(",")} - {"privately"}
        links[name] = ({parent} if parent else set()) | extra
        return name

    for line in lines:
        if "=" in line:
            name, rhs = line.split("=", 1)
            m = re.match(r"([^(]*)(?:\(\+ ([^)]*)\))?", rhs.strip())
            parts = {p.strip() for p in m.group(1).split("+")}
            extra = {w.strip() for w in (m.group(2) or "").split(",")} - {"privately"}
            links[name.strip()] = (parts | extra) - {""}
            continue
        m = re.match(r"(\s*(?:[└├]─ )?)(.*)", line)
        col = len(m.group(1))
        while stack and stack[-1][0] >= col:
            stack.pop()
        parent = stack[-1][1] if stack else None
        head, _, tail = m.group(2).partition("──")
        name = add(head, parent)
        stack.append((col, name))
        for item in filter(None, (t.strip() for t in re.split(r",(?![^(]*\))", tail))):
            add(item, name)
    return links


def closure(links, name, known):
    seen, todo = set(), list(links.get(name, ()))
    while todo:
        n = todo.pop()
        if n in seen or n not in known:
            continue
        seen.add(n)
        todo += links.get(n, ())
    return seen


def main():
    libs = cmake_libraries()
    doc = open(os.path.join(ROOT, "docs", "architecture.md")).read()
    bad = []
    for name, (folder, _) in sorted(libs.items()):
        if os.path.basename(folder) != name:
            bad.append(f"rms::{name} is in {folder}/, not a folder named {name}/")
        inc = os.path.join(ROOT, folder, "include", "rms")
        others = [d for d in os.listdir(inc) if d != name] if os.path.isdir(inc) else []
        if others:
            bad.append(f"{folder}/include/rms/ holds {others}: only {name}/ belongs there")
        if f"`rms::{name}`" not in doc:
            bad.append(f"docs/architecture.md's table does not name rms::{name}")
    drawn = diagram_links(doc)
    known = set(libs)
    cmake = {n: l for n, (_, l) in libs.items()}
    for name in sorted(known | (set(drawn) & known)):
        if name not in drawn:
            bad.append(f"the diagram in docs/architecture.md does not draw {name}")
            continue
        want, got = closure(cmake, name, known), closure(drawn, name, known)
        if want != got:
            bad.append(f"the diagram has {name} reach {sorted(got)}; the CMake files: {sorted(want)}")
    for name in sorted(set(drawn) - known):
        if name not in ("CGAL",):
            bad.append(f"the diagram draws {name}, which no CMakeLists.txt makes a library")
    print(f"{len(libs)} libraries: {', '.join(sorted(libs))}")
    for b in bad:
        print("MISMATCH:", b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
