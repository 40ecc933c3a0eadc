# SPDX-License-Identifier: MIT
"""Shared by the tool tests: import path, test data, private network namespaces."""

import os
import random
import subprocess
import sys
from pathlib import Path

import pytest

TOOLS = Path(__file__).resolve().parents[1]
REPO = TOOLS.parent
DATA = Path(__file__).resolve().parent / "data"
if str(TOOLS) not in sys.path:  # runnable without `pip install -e tools`
    sys.path.insert(0, str(TOOLS))

NETNS_SETUP = 'ip link set lo up && ip route add 224.0.0.0/4 dev lo && exec "$@"'


def netns_available() -> bool:
    try:
        return subprocess.run(["unshare", "-n", "true"], capture_output=True).returncode == 0
    except OSError:
        return False


def in_netns(argv):
    """argv run inside a private network namespace (multicast over lo) when one can be made;
    else on the host's network, where TTL 0 still keeps frames on this machine."""
    if netns_available():
        return ["unshare", "-n", "sh", "-c", NETNS_SETUP, "netns", *argv]
    return list(argv)


def c_binary(name: str) -> Path:
    build = Path(os.environ.get("DYNAQPC_BUILD_DIR", REPO / "build" / "host"))
    return build / "bin" / name


@pytest.fixture
def test_dbc() -> str:
    return str(DATA / "test.dbc")


@pytest.fixture
def bus_port() -> int:
    return random.randint(50000, 59999)  # a bus of its own: never another run's frames
