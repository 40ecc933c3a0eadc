# SPDX-License-Identifier: MIT
"""The C virtual CAN bus and python-can's udp_multicast interface understand each other.

Needs the C tools (cmake --build --preset host --target vcan-send vcan-dump). Runs inside a
private network namespace when one can be made (root), else on the host's network with TTL 0.
"""

import os
import subprocess
import sys

import pytest
from conftest import DATA, TOOLS, c_binary, in_netns


@pytest.mark.skipif(
    not c_binary("vcan-send").exists() or not c_binary("vcan-dump").exists(),
    reason="build vcan-send and vcan-dump first (cmake --build --preset host "
    "--target vcan-send vcan-dump) or set DYNAQPC_BUILD_DIR",
)
def test_c_and_python_can_interoperate(bus_port):
    scenario = os.path.join(os.path.dirname(__file__), "vcan_interop_scenario.py")
    env = dict(os.environ, PYTHONPATH=str(TOOLS) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    proc = subprocess.run(
        in_netns([sys.executable, scenario, str(c_binary("vcan-send").parent), str(bus_port), str(DATA / "test.dbc")]),
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
    )
    print(proc.stdout, proc.stderr)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "C -> python-can: 30 frames identical" in proc.stdout
    assert "python-can -> C: 10 frames identical" in proc.stdout
    assert "2 lost" in proc.stdout
