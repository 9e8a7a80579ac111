#!/usr/bin/env python3
"""Circles of includes among the project's files: files (a .cc with its .h as one) that
include each other in a loop, within the folders given (default: every source folder).

    /usr/bin/python3 scripts/include_circles.py [FOLDER ...]

Prints each circle and exits 1 if there is one, 0 otherwise. The include arrows are the
`#include "FOLDER/..."` lines of the sources; the circles are the strongly connected
components of more than one file (Tarjan)."""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FOLDERS = ["core", "dem", "fem", "coupling", "sph", "mlp", "app"]


def arrows(folders):
    """{unit: {unit it includes}} over the .cc and .h files under @p folders."""
    graph = {}
    for folder in folders:
        for base, _, names in os.walk(os.path.join(ROOT, folder)):
            for name in names:
                if not name.endswith((".cc", ".h")):
                    continue
                path = os.path.join(base, name)
                unit = os.path.splitext(os.path.relpath(path, ROOT))[0]
                graph.setdefault(unit, set())
                with open(path, encoding="utf-8") as f:
                    for include in re.findall(r'#include "([^"]+)"', f.read()):
                        target = os.path.splitext(include)[0]
                        if target != unit and target.split("/")[0] in folders:
                            graph[unit].add(target)
    return graph


def circles(graph):
    """The strongly connected components of more than one unit."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def main():
    folders = sys.argv[1:] or FOLDERS
    graph = arrows(folders)
    found = circles(graph)
    for circle in found:
        print("circle: " + " <-> ".join(circle))
    print(f"{len(graph)} files, {sum(len(t) for t in graph.values())} include arrows, {len(found)} circles "
          f"({', '.join(folders)})")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
