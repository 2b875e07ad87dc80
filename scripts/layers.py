#!/usr/bin/env python3
"""The layering of the crate's top-level modules, checked against scripts/layers.txt.

usage: python3 scripts/layers.py [SRC_DIR] [--layers FILE]

Reads the top-level import graph the way scripts/import-circles.py builds it (every
`crate::`/`super::`/`self::` path outside `#[cfg(test)]` code, comments and strings,
followed through re-exports) and the layers file (one layer a line, bottom first:
`name: module module …`; `allow: a -> b` lines for tolerated upward edges). Fails (exit 1)
when a module is in no layer or in two, when an import points to a higher layer and is not
allowed, and when an allowed edge no longer exists (the list may only shrink). Exit 2 on a
usage error.
"""

import importlib.util
import os
import sys


def load_circles_module():
    here = os.path.dirname(os.path.abspath(__file__))
    spec = importlib.util.spec_from_file_location(
        "import_circles", os.path.join(here, "import-circles.py")
    )
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def read_layers(path):
    rank, allowed, problems = {}, set(), []
    with open(path, encoding="utf-8") as fh:
        for n, raw in enumerate(fh, 1):
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            key, _, rest = line.partition(":")
            key = key.strip()
            if key == "allow":
                a, arrow, b = rest.strip().partition("->")
                if not arrow or not a.strip() or not b.strip():
                    problems.append(f"{path}:{n}: expected `allow: a -> b`")
                    continue
                allowed.add((a.strip(), b.strip()))
                continue
            level = len({r for r in rank.values()})
            for m in rest.split():
                if m in rank:
                    problems.append(f"{path}:{n}: module {m} is in two layers")
                rank[m] = level
    return rank, allowed, problems


def main(argv):
    args = list(argv)
    here = os.path.dirname(os.path.abspath(__file__))
    layers = os.path.join(here, "layers.txt")
    if "--layers" in args:
        i = args.index("--layers")
        if i + 1 >= len(args):
            print(__doc__, file=sys.stderr)
            return 2
        layers = args[i + 1]
        del args[i : i + 2]
    if len(args) > 1 or any(a.startswith("-") for a in args):
        print(__doc__, file=sys.stderr)
        return 2
    src = args[0] if args else "src"
    if not os.path.isdir(src) or not os.path.exists(layers):
        print(f"layers: no directory {src} or no file {layers}", file=sys.stderr)
        return 2
    rank, allowed, problems = read_layers(layers)
    edges = load_circles_module().Crate(src).graphs()[""]
    modules = {m for edge in edges for m in edge}
    modules |= {
        os.path.splitext(e)[0]
        for e in os.listdir(src)
        if e not in ("lib.rs", "main.rs") and (e.endswith(".rs") or os.path.isdir(os.path.join(src, e)))
    }
    for m in sorted(modules - set(rank)):
        problems.append(f"module {m} is in no layer of {os.path.relpath(layers)}")
    up = []
    for (a, b), causes in sorted(edges.items()):
        if a in rank and b in rank and rank[b] > rank[a]:
            if (a, b) in allowed:
                continue
            where = ", ".join(sorted({f"{r}:{l}" for r, l, _ in causes}))
            up.append(f"{a} -> {b} points up the layers   ({where})")
    for a, b in sorted(allowed - set(edges)):
        problems.append(f"allowed edge {a} -> {b} no longer exists: delete its line")
    for p in problems + up:
        print(p)
    print(f"layers: {len(rank)} modules in {len(set(rank.values()))} layers, "
          f"{len(allowed)} tolerated upward edges, {len(up) + len(problems)} problems")
    return 1 if up or problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
