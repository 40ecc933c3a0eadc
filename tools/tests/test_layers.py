# SPDX-License-Identifier: MIT
"""No two modules of dynaqpc_tools import each other, directly or around a circle (docs/design.md,
"Modules"): imports inside functions count too, since they are uses all the same."""

import ast
import pathlib

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / "dynaqpc_tools"


def _modules():
    mods = {}
    for path in PACKAGE.rglob("*.py"):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        mods[name] = path
    return mods


def _imports(name, path, mods):
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
    return {m for m in used if m in mods and m != name}


def _circles(edges):
    """Strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []

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
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in edges:
        if v not in index:
            visit(v)
    return out


def test_no_module_circles():
    mods = _modules()
    edges = {name: _imports(name, path, mods) for name, path in mods.items()}
    assert "dynaqpc_tools.bus_decode" in edges
    assert _circles(edges) == []


def test_bus_decoding_is_below_every_view():
    mods = _modules()
    used = _imports("dynaqpc_tools.bus_decode", mods["dynaqpc_tools.bus_decode"], mods)
    assert used <= {"dynaqpc_tools.common"}
