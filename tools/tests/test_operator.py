# SPDX-License-Identifier: MIT
"""dynaqpc-operator: its frames (two TOOL_CMDs, CRC, counters) and, against the firmware's host
build and the simulated devices in a private network namespace, every command."""

import os
import subprocess
import sys
import zlib

import cantools
import pytest
from conftest import REPO, TOOLS, c_binary, netns_available

from dynaqpc_tools import operator

DBC = str(REPO / "docs" / "dynaqpc.dbc")


def test_every_command_is_a_nop_then_the_command_with_the_next_counter():
    db = cantools.database.load_file(DBC)
    m = db.get_message_by_name("TOOL_CMD")
    for k in range(16):
        (id0, nop), (id1, cmd) = operator.tool_cmd_frames(db, "SAFE_STOP", 0, counter=k)
        assert id0 == id1 == 0x040
        a, b = m.decode(nop, decode_choices=False), m.decode(cmd, decode_choices=False)
        assert (a["Command"], b["Command"]) == (0, 3)
        assert (a["Counter"], b["Counter"]) == (k, (k + 1) % 16)
        for data in (nop, cmd):
            assert len(data) == 8 and data[4:] == zlib.crc32(bytes([0x40, 0x00]) + data[:4]).to_bytes(4, "little")
    # The firmware's rule (telemetry.c tlm_rx_tool_cmd): refuse a counter equal to the last one.
    # Whatever the last counter was, the command is accepted exactly once.
    for last in range(16):
        for k in range(16):
            accepted, prev = [], last
            for c, what in ((k, "NOP"), ((k + 1) % 16, "CMD")):
                if c != prev:
                    accepted.append(what)
                    prev = c
            assert accepted.count("CMD") == 1


def test_status_is_decoded_by_name():
    db = cantools.database.load_file(DBC)
    m = db.get_message_by_name("FW_STATUS")
    sigs = {s.name: 0 for s in m.signals}
    sigs.update(Mode=3, Uptime=42, ErrFlash=1, ErrPoseLost=1, TrustReason=2, BootCount=7)
    st = operator.decode_status(db, m.encode(sigs))
    assert st["mode"] == "SAFE_STOP" and st["uptime_s"] == 42
    assert len(st["errors"]) == 8 and st["errors"]["Flash"] == 1
    text = operator.status_text(st)
    assert "mode SAFE_STOP" in text and "errors: PoseLost, Flash" in text and "DeadlineMiss=0" in text
    assert st["pose_trusted"] == 0 and "pose NOT trusted (FIX_JUMP)" in text and "boot 7, reset cause POWER_ON" in text


def test_answers_are_one_line_by_name():
    db = cantools.database.load_file(DBC)
    m = db.get_message_by_name("TOOL_ACK")
    data = m.encode(
        {"Command": "SAVE_LEARNED", "Counter": 5, "Result": "DONE", "Reason": "NONE", "Sequence": 7, "Episodes": 157}
    )
    ack = operator.decode_ack(db, data)
    assert ack == {
        "command": "SAVE_LEARNED",
        "counter": 5,
        "result": "DONE",
        "reason": "NONE",
        "sequence": 7,
        "episodes": 157,
    }
    assert operator.ack_text(ack) == "SAVE_LEARNED: done, record 7 written (157 episodes)"
    # Every reason the DBC names has words for the operator.
    for value, name in m.get_signal_by_name("Reason").choices.items():
        assert str(name) in operator.REASONS, name
        text = operator.ack_text(dict(ack, result="REFUSED", reason=str(name), command="RESET_LEARNING"))
        assert "\n" not in text and text.startswith(f"RESET_LEARNING: refused, {name}")
    confirm = operator.ack_text(dict(ack, command="RESET_LEARNING", result="REFUSED", reason="CONFIRM"))
    assert "--yes" in confirm and "restore-previous" in confirm


@pytest.mark.parametrize(
    "argv",
    [
        ["start", "--heading", "360"],
        ["start", "--heading", "-1"],
        ["status", "--timeout", "0"],
        ["jump"],
        ["watch", "--duration", "0"],
        ["save", "--yes"],
        ["status", "--no-wait"],
        ["restore-previous", "x"],
    ],
)
def test_bad_arguments_are_one_line_and_status_2(argv, capsys):
    with pytest.raises(SystemExit) as e:
        rc = operator.main(argv)
        raise SystemExit(rc)
    assert e.value.code == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


@pytest.mark.parametrize("value", ["360", "nan", "-0.5"])
def test_heading_range_reads_half_open(value, capsys):
    # 360 is a full turn (0), so the range is [0, 360), and every refusal says so.
    with pytest.raises(SystemExit):
        operator.main(["start", "--heading", value])
    assert "[0, 360)" in capsys.readouterr().err


@pytest.mark.skipif(
    not c_binary("dynaqpc-fw").exists() or not c_binary("dynaqpc-sim").exists(),
    reason="build dynaqpc-fw and dynaqpc-sim first or set DYNAQPC_BUILD_DIR",
)
@pytest.mark.skipif(not netns_available(), reason="needs a private network namespace (unshare -n)")
def test_operator_commands_the_firmware_in_a_private_namespace(tmp_path):
    scenario = os.path.join(os.path.dirname(__file__), "operator_scenario.py")
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
        timeout=240,
        env=env,
        cwd=str(REPO),
    )
    print(proc.stdout, proc.stderr)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-2000:]
    assert "PASS" in proc.stdout
