# SPDX-License-Identifier: MIT
"""No two modules of dynaqpc_tools import each other, directly or around a circle (docs/design.md,
"Modules"): imports inside functions count too, since they are uses all the same. The check is
tests/unit/layers/check_circles.py's, which also checks the C files (unit.no_circles)."""

import importlib.util
import pathlib

REPO = pathlib.Path(__file__).resolve().parents[2]
PACKAGE = REPO / "tools" / "dynaqpc_tools"


def _check():
    spec = importlib.util.spec_from_file_location("check_circles", REPO / "tests/unit/layers/check_circles.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_no_module_circles():
    check = _check()
    edges = check.python_graph(PACKAGE)
    assert "dynaqpc_tools.bus_decode" in edges
    assert check.circles(edges) == []


def test_bus_decoding_is_below_every_view():
    edges = _check().python_graph(PACKAGE)
    assert edges["dynaqpc_tools.bus_decode"] <= {"dynaqpc_tools.common"}
