#!/usr/bin/env python3
"""Import circles between the modules of a crate: the figure issue 32 asks for.

    python3 scripts/module-circles.py crates/hwfoc-io/src        # top-level modules (default)
    python3 scripts/module-circles.py crates/hwfoc-io/src 2 -v   # two levels deep, with edges

A module is a source file (`a/mod.rs` is `a`), merged into its ancestor at DEPTH path components
(1: `record/column.rs` counts as `record`). Module A uses module B when A's code outside
`#[cfg(test)]` modules and comments names a path `crate::…` or `super::…` that resolves to B
(the deepest file module that is a prefix of the path). A circle is a strongly connected
component of more than one module. Paths reached only through `use` of a re-export, macros or
`self::` are not followed: the figure is a lower bound.
"""

import os
import re
import sys


def modules(root):
    found = {}
    for folder, _, files in os.walk(root):
        for name in files:
            if name.endswith(".rs"):
                path = os.path.relpath(os.path.join(folder, name), root)[:-3].split(os.sep)
                if path[-1] in ("mod", "lib", "main"):
                    path = path[:-1]
                found[tuple(path)] = os.path.join(folder, name)
    return found


def without_tests(src):
    """The source without its `#[cfg(test)] mod NAME { … }` blocks and line comments."""
    kept, at = [], 0
    for m in re.finditer(r"#\[cfg\(test\)\]\s*(pub(\(\w+\))?\s+)?mod\s+\w+\s*\{", src):
        if m.start() < at:
            continue
        kept.append(src[at : m.start()])
        depth, i = 1, m.end()
        while depth and i < len(src):
            depth += {"{": 1, "}": -1}.get(src[i], 0)
            i += 1
        at = i
    kept.append(src[at:])
    return re.sub(r"//[^\n]*", "", "".join(kept))


def graph(root, depth):
    mods = modules(root)

    def resolve(path):
        path = tuple(path)
        while path and path not in mods:
            path = path[:-1]
        return path

    def node(m):
        return m[:depth] if depth else m

    edges = {node(m): set() for m in mods}
    for m, file in mods.items():
        src = without_tests(open(file, encoding="utf-8").read())
        for group in re.finditer(r"\b(crate|super(?:::super)*)::\{([^}]*)\}", src):
            for part in group.group(2).split(","):
                src += "\n" + group.group(1) + "::" + part.strip()
        for ref in re.finditer(r"\b(crate|(?:super::)+)::?([A-Za-z_][\w:]*)", src):
            head, rest = ref.group(1), [p for p in ref.group(2).split("::") if p]
            base = [] if head == "crate" else list(m)[: len(m) - head.count("super")]
            target = node(resolve(base + rest))
            if target and target != node(m):
                edges[node(m)].add(target)
    return edges


def circles(edges):
    index, low, stack, on, found = {}, {}, [], set(), []
    sys.setrecursionlimit(10000)

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in edges:
        if v not in index:
            visit(v)
    return found


def main():
    args = [a for a in sys.argv[1:] if a != "-v"]
    root, depth = args[0], int(args[1]) if len(args) > 1 else 1
    edges = graph(root, depth)
    found = circles(edges)
    name = "::".join
    print(f"{len(edges)} modules, {sum(map(len, edges.values()))} uses, {len(found)} circles")
    for component in found:
        print(f"{len(component)}: {', '.join(map(name, component))}")
        if "-v" in sys.argv:
            for a in component:
                for b in sorted(edges[a]):
                    if b in component:
                        print(f"    {name(a)} -> {name(b)}")
    sys.exit(1 if found else 0)


if __name__ == "__main__":
    main()
