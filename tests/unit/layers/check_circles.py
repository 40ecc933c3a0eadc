#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""No two files use each other, directly or around a circle (docs/design.md, "Modules").

C: reads the static libraries given with `nm -A -g`: a file (an archive member) uses another when
it needs a symbol the other defines. Python (--python DIR): a module uses another when it imports
it, at the top or inside a function. Prints each circle of files and exits 1 if there is one;
prints "no circles among N files" otherwise.

    check_circles.py --nm NM LIB.a...
    check_circles.py --python tools/dynaqpc_tools
"""

import argparse
import ast
import collections
import pathlib
import subprocess
import sys


def c_graph(nm, libs):
    """Archive member -> the members defining a symbol it needs."""
    defines = collections.defaultdict(set)
    needs = collections.defaultdict(set)
    for lib in libs:
        out = subprocess.run([nm, "-A", "-g", lib], capture_output=True, text=True, check=True).stdout
        for line in out.splitlines():
            where, _, rest = line.rpartition(":")
            member = where.split(":", 1)[-1] if ":" in where else where
            fields = rest.split()
            if len(fields) < 2:
                continue
            kind, symbol = fields[-2], fields[-1]
            if kind == "U":
                needs[member].add(symbol)
            elif kind in "TDBRCVW":
                defines[symbol].add(member)
    edges = {m: set() for m in set(needs) | {m for ms in defines.values() for m in ms}}
    for member, symbols in needs.items():
        for s in symbols:
            edges[member].update(d for d in defines.get(s, ()) if d != member)
    return edges


def python_graph(package_dir):
    """Module -> the package's modules it imports (dotted names, relative imports resolved)."""
    root = pathlib.Path(package_dir).resolve()
    mods = {}
    for path in root.rglob("*.py"):
        parts = path.relative_to(root.parent).with_suffix("").parts
        mods[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    edges = {}
    for name, path in mods.items():
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        used = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                base = package.split(".")
                if node.level > 1:
                    base = base[: -(node.level - 1)]
                target = ".".join(base) if node.level else ""
                if node.module:
                    target = f"{target}.{node.module}" if target else node.module
                subs = [f"{target}.{a.name}" for a in node.names if f"{target}.{a.name}" in mods]
                used.update(subs if len(subs) == len(node.names) else [target, *subs])
            elif isinstance(node, ast.Import):
                used.update(a.name for a in node.names)
        edges[name] = {m for m in used if m in mods and m != name}
    return edges


def circles(edges):
    """The strongly connected components of more than one file (Tarjan), each sorted."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(edges[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(edges):
        if v not in index:
            visit(v)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nm", default="nm")
    ap.add_argument("--python", metavar="DIR", help="a Python package's folder instead of C libraries")
    ap.add_argument("libs", nargs="*")
    args = ap.parse_args()
    edges = python_graph(args.python) if args.python else c_graph(args.nm, args.libs)
    found = circles(edges)
    for c in found:
        print("circle: " + " <-> ".join(c))
    if found:
        return 1
    print(f"no circles among {len(edges)} files")
    return 0


if __name__ == "__main__":
    sys.exit(main())
