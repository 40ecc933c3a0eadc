# SPDX-License-Identifier: MIT
"""dynaqpc-monitor --foxglove: the bus live in Foxglove over the sdk's WebSocket server. Against
the firmware's host build and the simulated robot in a private network namespace, a WebSocket
client receives the pose, /tf, the rays and the plot channels within 5 s of the firmware
starting (foxglove_scenario.py); bad input is one line and exit 2."""

import json
import os
import re
import socket
import subprocess
import sys

import pytest
from conftest import REPO, TOOLS, c_binary, netns_available

from dynaqpc_tools import monitor

foxglove = pytest.importorskip("foxglove", reason="foxglove-sdk is not installed (tools/requirements.txt)")


def test_the_layout_is_generated_and_names_what_is_served(tmp_path):
    subprocess.run(
        [sys.executable, str(REPO / "tools" / "gen_foxglove_layout.py"), "-o", str(tmp_path / "l.json")],
        check=True,
        stdout=subprocess.DEVNULL,
    )
    committed = (REPO / "docs" / "foxglove-layout.json").read_text()
    assert (tmp_path / "l.json").read_text() == committed, (
        "docs/foxglove-layout.json is stale: run `.venv/bin/python tools/gen_foxglove_layout.py`"
    )
    import cantools

    from dynaqpc_tools.foxglove_live import TOPICS

    db = cantools.database.load_file(str(REPO / "docs" / "dynaqpc.dbc"))
    text = json.dumps(json.loads(committed))
    for topic, field in re.findall(r'"(/[a-z_/A-Z]+)(?:\.([A-Za-z_]+))?"', text):
        if topic.startswith("/can/"):
            sigs = {s.name for s in db.get_message_by_name(topic[5:]).signals}
            assert not field or field.replace("_name", "") in sigs, f"{topic}.{field}"
        else:
            assert topic in TOPICS, topic


@pytest.mark.parametrize(
    "argv",
    [
        ["--foxglove", "70000"],
        ["--foxglove", "x"],
        ["--scenario", "paper-sim.scn"],
        ["--foxglove", "0", "--scenario", "/nonexistent.scn"],
        ["--foxglove", "0", "--arena", "/nonexistent.json"],
    ],
)
def test_bad_foxglove_arguments_are_one_line_and_status_2(argv, capsys):
    with pytest.raises(SystemExit) as e:
        raise SystemExit(monitor.main(argv + ["--duration", "0.1"]))
    assert e.value.code == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_a_port_in_use_is_one_line_and_status_2(capsys):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen(1)
        port = s.getsockname()[1]
        rc = monitor.main(["--foxglove", str(port), "--duration", "0.1", "--bus-kwarg", "port=59999"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and f"127.0.0.1:{port}" in err[0], err


@pytest.mark.skipif(
    not c_binary("dynaqpc-fw").exists() or not c_binary("dynaqpc-sim").exists(),
    reason="build dynaqpc-fw and dynaqpc-sim first or set DYNAQPC_BUILD_DIR",
)
@pytest.mark.skipif(not netns_available(), reason="needs a private network namespace (unshare -n)")
def test_a_websocket_client_sees_the_robot_within_5_s(tmp_path):
    scenario = os.path.join(os.path.dirname(__file__), "foxglove_scenario.py")
    env = dict(os.environ, PYTHONPATH=str(TOOLS) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    setup = 'ip link set lo up && ip route add 224.0.0.0/4 dev lo && exec "$@"'
    proc = subprocess.run(
        [
            "unshare",
            "-n",
            "sh",
            "-c",
            setup,
            "netns",
            sys.executable,
            scenario,
            str(c_binary("dynaqpc-fw").parent),
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
        timeout=180,
        env=env,
        cwd=str(REPO),
    )
    print(proc.stdout, proc.stderr)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-2000:]
    assert "PASS" in proc.stdout
