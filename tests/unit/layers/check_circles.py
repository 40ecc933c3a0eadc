#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""No two C files use each other, directly or around a circle (docs/design.md, "Modules").

Reads the static libraries given with `nm -A -g`: a file (an archive member) uses another when it
needs a symbol the other defines. Prints each circle of files and exits 1 if there is one; prints
"no circles among N files" otherwise.

    check_circles.py --nm NM LIB.a...
"""

import argparse
import collections
import subprocess
import sys


def _graph(nm, libs):
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


def _circles(edges):
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
    ap.add_argument("libs", nargs="+")
    args = ap.parse_args()
    edges = _graph(args.nm, args.libs)
    circles = _circles(edges)
    for c in circles:
        print("circle: " + " <-> ".join(c))
    if circles:
        return 1
    print(f"no circles among {len(edges)} files")
    return 0


if __name__ == "__main__":
    sys.exit(main())
