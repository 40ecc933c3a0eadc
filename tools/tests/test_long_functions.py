# SPDX-License-Identifier: MIT
"""tools/long_functions.py: the brace scanner finds C and C++ functions and their lengths."""

import importlib.util

from conftest import TOOLS

spec = importlib.util.spec_from_file_location("long_functions", TOOLS / "long_functions.py")
lf = importlib.util.module_from_spec(spec)
spec.loader.exec_module(lf)

SOURCE = """\
// a { comment } with braces
#define M(x) { x }
static int f(int a)
{
    const char *s = "}{";
    if (a) {
        return '}';
    }
    return 0;
}
namespace ns {
struct S {
    int g() const { return [] { return 1; }(); }
};
S::S(int v) : v_{v}, w_(v)
{
}
}  // namespace ns
int table[] = {1, 2};
"""


def test_c_functions_and_lines(tmp_path):
    p = tmp_path / "x.cpp"
    p.write_text(SOURCE)
    assert list(lf.c_functions(p)) == [("f", 3, 10), ("g", 13, 13), ("S::S", 15, 17)]


def test_production_filter():
    assert lf.is_production("firmware/agent/src/cmac.c")
    assert not lf.is_production("tools/tests/test_emu.py")
    assert not lf.is_production("firmware/drivers/src/generated/dynaqpc_can.c")
    assert not lf.is_production("host_sim/src/foo_test.cpp")
