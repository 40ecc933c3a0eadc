# SPDX-License-Identifier: MIT
"""Recordings: MCAP for Foxglove (decoded channels, the pose, the arena, robot time), enum names,
poses without a fix, garbage logs; and a real recording of paper-sim in a private namespace."""

import json
import os
import signal
import subprocess
import threading
import time

import can
import cantools
import pytest
from conftest import REPO, c_binary, in_netns, netns_available
from mcap.reader import make_reader

from dynaqpc_tools import monitor, viewer
from dynaqpc_tools.bus_decode import PoseDecoder, WrongLength, decode_frame, e2e_ok, e2e_seal
from dynaqpc_tools.canlog import CHUNK_BYTES, McapLog, read_log

DBC = str(REPO / "docs" / "dynaqpc.dbc")
ARENA = {
    "width": 4.3,
    "height": 3.2,
    "obstacles": [
        {"kind": "box", "cx": 2.0, "cy": 1.5, "w": 0.5, "h": 1.0, "angle_deg": 30},
        {"kind": "circle", "cx": 1.0, "cy": 2.2, "r": 0.2},
    ],
    "goal": {"cx": 3.5, "cy": 2.5, "r": 0.3, "cells": [[3.2, 2.2, 3.8, 2.8]]},
    "beacons": [{"id": "1:5e:3c:3c:a:0:0:b1", "x": 0.5, "y": 0.5, "z": 2.5}],
}


def _msg(db, name, t, **signals):
    m = db.get_message_by_name(name)
    full = {s.name: 0 for s in m.signals}
    full.update(signals)
    return can.Message(timestamp=t, arbitration_id=m.frame_id, is_extended_id=False, data=e2e_seal(m, m.encode(full)))


def a_run(db, t0=1000.0):
    """20 TLM_POSE at 0.0192 s (a 10x run of the 192 ms period), every fifth LOST at (0, 0); two
    FW_STATUS, the second SAFE_STOP; two GPS_POSE, one without a fix."""
    msgs = []
    for i in range(20):
        lost = i % 5 == 4
        msgs.append(
            _msg(
                db,
                "TLM_POSE",
                t0 + 0.0192 * i,
                X=0 if lost else 1000 + 10 * i,
                Y=0 if lost else 800,
                Heading=90.0,
                FixState=3 if lost else 0,
                Counter=i % 16,
            )
        )
    msgs.append(_msg(db, "FW_STATUS", t0 + 0.1, Mode=2, Counter=0, Uptime=5))
    msgs.append(_msg(db, "FW_STATUS", t0 + 0.2, Mode=3, Counter=1, Uptime=6, ErrPoseLost=1))
    msgs.append(_msg(db, "GPS_POSE", t0 + 0.3, X=1200, Y=800, Heading=90.0, Fix=2, Counter=0))
    msgs.append(_msg(db, "GPS_POSE", t0 + 0.35, X=0, Y=0, Heading=0.0, Fix=0, Counter=1))
    return sorted(msgs, key=lambda m: m.timestamp)


def _write_asc(path, msgs):
    with can.Logger(str(path)) as log:
        for m in msgs:
            log(m)


def _decoder(schema):
    """Decodes a message as Foxglove does: JSON, or protobuf through the schema's FileDescriptorSet."""
    if schema.encoding != "protobuf":
        return json.loads
    from google.protobuf import descriptor_pb2, descriptor_pool, json_format, message_factory

    pool = descriptor_pool.DescriptorPool()
    for f in descriptor_pb2.FileDescriptorSet.FromString(schema.data).file:
        pool.Add(f)
    cls = message_factory.GetMessageClass(pool.FindMessageTypeByName(schema.name))
    return lambda data: json_format.MessageToDict(
        cls.FromString(data), preserving_proto_field_name=True, always_print_fields_with_no_presence=True
    )


def read_mcap(path, with_sequence=False):
    with open(path, "rb") as f:
        r = make_reader(f)
        summary = r.get_summary()
        channels = {c.topic: c for c in summary.channels.values()}
        schemas = {s.id: s for s in summary.schemas.values()}
        decoders = {sid: _decoder(s) for sid, s in schemas.items()}
        msgs = [
            (ch.topic, m.log_time, decoders[ch.schema_id](m.data)) + ((m.sequence,) if with_sequence else ())
            for _, ch, m in r.iter_messages()
        ]
    return channels, schemas, msgs


def test_mcap_has_decoded_channels_pose_arena_in_robot_time(tmp_path, capsys):
    db = cantools.database.load_file(DBC)
    src, rec, arena = tmp_path / "run.asc", tmp_path / "run.mcap", tmp_path / "arena.json"
    _write_asc(src, a_run(db))
    arena.write_text(json.dumps(ARENA))
    assert monitor.main(["--replay", str(src), "--log", str(rec), "--arena", str(arena), "--speed", "10"]) == 0
    channels, schemas, msgs = read_mcap(rec)
    for topic in (
        "/can/raw",
        "/can/TLM_POSE",
        "/can/FW_STATUS",
        "/can/GPS_POSE",
        "/robot/pose",
        "/robot/true_pose",
        "/arena",
    ):
        assert topic in channels, topic
    assert schemas[channels["/robot/pose"].schema_id].name == "foxglove.PoseInFrame"
    assert schemas[channels["/arena"].schema_id].name == "foxglove.SceneUpdate"
    assert schemas[channels["/tf"].schema_id].name == "foxglove.FrameTransforms"
    # Foxglove's published schemas, as foxglove-sdk has them, byte for byte.
    from foxglove.messages import FrameTransforms, PoseInFrame, SceneUpdate

    for topic, kind in (("/robot/pose", PoseInFrame), ("/arena", SceneUpdate), ("/tf", FrameTransforms)):
        sch = schemas[channels[topic].schema_id]
        assert (sch.encoding, bytes(sch.data)) == ("protobuf", bytes(kind.get_schema().data)), topic
        assert channels[topic].message_encoding == "protobuf"
    assert schemas[channels["/can/FW_STATUS"].schema_id].encoding == "jsonschema"
    by = {}
    for topic, t, d in msgs:
        by.setdefault(topic, []).append((t, d))
    assert len(by["/can/raw"]) == 24
    status = [d for _, d in by["/can/FW_STATUS"]]
    assert status[1]["Mode"] == 3 and status[1]["Mode_name"] == "SAFE_STOP" and status[1]["ErrPoseLost"] == 1
    # The LOST poses (x = 0) are not poses: 16 of 20; the GPS pose without a fix neither.
    poses = [d for _, d in by["/robot/pose"]]
    assert len(poses) == 16 and all(p["pose"]["position"]["x"] > 0.9 for p in poses)
    assert poses[0]["frame_id"] == "arena" and poses[0]["pose"]["orientation"]["w"] == pytest.approx(0.5**0.5)
    assert len(by["/robot/true_pose"]) == 1
    # /tf: arena -> base_link for each pose, arena -> true_base_link for the true one.
    tf = [(x["parent_frame_id"], x["child_frame_id"]) for _, d in by["/tf"] for x in d["transforms"]]
    assert tf.count(("arena", "base_link")) == 16 and tf.count(("arena", "true_base_link")) == 1
    # Sequences counted per channel from 1.
    _, _, seq = read_mcap(rec, with_sequence=True)
    per = {}
    for topic, _, _, n in seq:
        per.setdefault(topic, []).append(n)
    for topic, ns in per.items():
        assert ns == list(range(1, len(ns) + 1)), topic
    # Robot time: the 10x run's 0.0192 s between poses becomes the DBC's 192 ms.
    ts = [t for t, _ in by["/can/TLM_POSE"]]
    assert (ts[1] - ts[0]) * 1e-9 == pytest.approx(0.192, abs=1e-6)
    scene = by["/arena"][0][1]["entities"][0]
    assert len(scene["cubes"]) == 4 + 1 + 1 and len(scene["cylinders"]) == 1 and len(scene["texts"]) == 1
    # And it reads back: the monitor replays the MCAP's raw frames, FW_STATUS named.
    capsys.readouterr()
    assert monitor.main(["--replay", str(rec), "--print"]) == 0
    out = capsys.readouterr().out
    assert "24 frames" in out and "Mode=SAFE_STOP" in out and "FixState=LOST" in out


def test_a_10x_asc_recording_is_in_robot_time_too(tmp_path):
    db = cantools.database.load_file(DBC)
    src, rec = tmp_path / "run.asc", tmp_path / "robot.asc"
    _write_asc(src, a_run(db))
    assert monitor.main(["--replay", str(src), "--log", str(rec), "--speed", "10"]) == 0
    ts = [m.timestamp for m in can.LogReader(str(rec)) if m.arbitration_id == 0x180]
    assert ts[1] - ts[0] == pytest.approx(0.192, abs=1e-3)


def test_viewer_skips_lost_poses_and_names_the_fix(tmp_path, capsys):
    db = cantools.database.load_file(DBC)
    src = tmp_path / "run.asc"
    _write_asc(src, a_run(db))
    png = tmp_path / "p.png"
    view = viewer.run(viewer.build_parser().parse_args(["--replay", str(src), "--headless-png", str(png)]))
    assert view.poses == 16 and view.skipped == 4 and view.last.fix_name == "FRESH"
    assert "4 without a fix not drawn" in capsys.readouterr().out
    # Asked for a frame that is not there: it says so, and what was.
    only_tlm = tmp_path / "tlm.asc"
    _write_asc(only_tlm, [m for m in a_run(db) if m.arbitration_id != 0x0C0])
    view = viewer.run(
        viewer.build_parser().parse_args(["--replay", str(only_tlm), "--frame", "GPS_POSE", "--headless-png", str(png)])
    )
    err = capsys.readouterr().err
    assert view.poses == 0 and "no GPS_POSE frame in the recording" in err and "TLM_POSE" in err


@pytest.mark.parametrize(
    "tool, argv",
    [
        (monitor, ["--replay", "garbage.asc"]),
        (monitor, ["--replay", "garbage.blf"]),
        (monitor, ["--replay", "garbage.mcap"]),
        (monitor, ["--replay", "missing.asc"]),
        (monitor, ["--replay", "good.asc", "--log", "no/such/dir/x.mcap"]),
        (viewer, ["--replay", "garbage.mcap", "--headless-png", "x.png"]),
        (viewer, ["--replay", "good.asc", "--headless-png", "no/such/dir/x.png"]),
    ],
)
def test_bad_logs_and_outputs_are_one_line_and_status_2(tmp_path, capsys, monkeypatch, tool, argv):
    db = cantools.database.load_file(DBC)
    junk = bytes(range(256)) * 8
    (tmp_path / "garbage.asc").write_bytes(junk)
    (tmp_path / "garbage.blf").write_bytes(junk)
    (tmp_path / "garbage.mcap").write_bytes(b"\x89MCAP0\r\n" + junk)
    _write_asc(tmp_path / "good.asc", a_run(db))
    monkeypatch.chdir(tmp_path)
    capsys.readouterr()
    assert tool.main(["--dbc", DBC, *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: "), err


@pytest.mark.parametrize(
    "tool, argv",
    [
        (monitor, ["--count", "-5"]),
        (monitor, ["--speed", "0"]),
        (viewer, ["--duration", "0"]),
        (viewer, ["--count", "0"]),
    ],
)
def test_numeric_arguments_are_range_checked(capsys, tool, argv):
    with pytest.raises(SystemExit) as e:
        tool.main(argv)
    assert e.value.code == 2 and len(capsys.readouterr().err.strip().splitlines()) == 1


@pytest.mark.skipif(
    not c_binary("dynaqpc-fw").exists() or not c_binary("dynaqpc-sim").exists(),
    reason="build dynaqpc-fw and dynaqpc-sim first or set DYNAQPC_BUILD_DIR",
)
@pytest.mark.skipif(not netns_available(), reason="needs a private network namespace (unshare -n)")
def test_recording_paper_sim_reads_back_with_the_mcap_library(tmp_path):
    """The firmware and the simulated robot on paper-sim at 10x, supervised, recorded 4 s."""
    import sys

    b = c_binary("dynaqpc-fw").parent
    rec = tmp_path / "run.mcap"
    script = (
        f"{b}/dynaqpc-fw --scenario paper-sim --speed 10 --duration 8 >{tmp_path}/fw.out 2>&1 & "
        f"sleep 0.5; {b}/dynaqpc-sim devices --scenario paper-sim --speed 10 --supervise --duration 7 "
        f">{tmp_path}/dev.out 2>&1 & "
        f"{sys.executable} -m dynaqpc_tools.monitor --dbc {DBC} --log {rec} --speed 10 --duration 4; "
        "wait"
    )
    proc = subprocess.run(
        in_netns(["sh", "-c", script]), capture_output=True, text=True, timeout=120, cwd=str(REPO / "tools")
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    channels, _, msgs = read_mcap(rec)
    topics = {t for t, _, _ in msgs}
    assert len(channels) >= 5 and len(msgs) >= 500, (len(channels), len(msgs))
    assert {"/can/raw", "/can/MOTOR_CMD", "/can/GPS_POSE", "/can/FW_STATUS", "/robot/true_pose", "/tf"} <= topics
    # Robot time: 4 s of wall time at 10x span about 40 s.
    times = [t for _, t, _ in msgs]
    assert 25 < (max(times) - min(times)) * 1e-9 < 45


def test_fail_on_status_notices_safe_stop_errors_and_silence(tmp_path, capsys):
    db = cantools.database.load_file(DBC)

    def run(msgs):
        src = tmp_path / "s.asc"
        _write_asc(src, msgs)
        capsys.readouterr()
        rc = monitor.main(["--dbc", DBC, "--replay", str(src), "--fail-on-status"])
        return rc, [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("status: ")]

    poses = [m for m in a_run(db) if m.arbitration_id == 0x180]
    fine = [_msg(db, "FW_STATUS", 1000.0 + i, Mode=2, Counter=i % 16, Uptime=i) for i in range(5)]
    assert run(sorted(fine + poses, key=lambda m: m.timestamp)) == (0, [])
    rc, why = run(a_run(db))  # SAFE_STOP with ErrPoseLost
    assert rc == 1 and any("Mode=SAFE_STOP" in w for w in why) and any("ErrPoseLost" in w for w in why)
    rc, why = run(poses)  # no FW_STATUS at all
    assert rc == 1 and why == ["status: no FW_STATUS heard: the firmware is silent"]
    gap = fine[:2] + [_msg(db, "FW_STATUS", 1010.0, Mode=2, Counter=2, Uptime=10)]
    rc, why = run(gap)  # 9 s without FW_STATUS (3 cycles: 3 s)
    assert rc == 1 and any("silent 1 time(s)" in w for w in why)


def _gyro(db, i, t0=1000.0):
    return _msg(db, "GYRO_RATE", t0 + 0.01 * i, YawRate=(i % 100) * 0.5, Counter=i % 16)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_and_sighup_finish_the_recording(tmp_path, capsys, monkeypatch, sig):
    """`kill` or `timeout` (SIGTERM), or the terminal closing (SIGHUP), end the monitor as Ctrl-C
    does: the MCAP is finished (it has its summary) and the summary is printed."""
    db = cantools.database.load_file(DBC)
    rec, channel = tmp_path / "run.mcap", f"monitor-{sig.name}"
    opened, original = threading.Event(), monitor.frames

    def frames(args, timeout, on_open=None):
        return original(args, timeout, lambda: (on_open and on_open(), opened.set()))

    monkeypatch.setattr(monitor, "frames", frames)

    def bus_then_signal():
        assert opened.wait(20)
        with can.Bus(interface="virtual", channel=channel) as bus:
            for i in range(10):
                bus.send(_gyro(db, i))
        time.sleep(0.5)
        os.kill(os.getpid(), sig)

    t = threading.Thread(target=bus_then_signal)
    t.start()
    rc = monitor.main(["--dbc", DBC, "--interface", "virtual", "--channel", channel, "--log", str(rec)])
    t.join()
    out, err = capsys.readouterr()
    assert rc == 0 and f"{sig.name}: stopping" in err and "10 frames" in out
    with open(rec, "rb") as f:
        assert make_reader(f).get_summary().statistics.message_count > 10  # finished: it has a summary
    assert monitor.main(["--dbc", DBC, "--replay", str(rec), "--print"]) == 0
    out, err = capsys.readouterr()
    assert "10 frames" in out and "warning" not in err


def test_a_cut_recording_is_replayed_up_to_the_cut(tmp_path, capsys):
    """A recorder killed with SIGKILL or a power cut leaves an MCAP without its end: the monitor
    and the viewer read its frames up to the cut and warn that it was cut."""
    db = cantools.database.load_file(DBC)
    rec, cut = tmp_path / "run.mcap", tmp_path / "cut.mcap"
    log = McapLog(str(rec), db)
    n = 12000
    for i in range(n):
        log(_gyro(db, i))
        if i == n // 2:
            log._file.flush()
            killed = rec.read_bytes()  # what the disk holds when the recorder dies here
    log.stop()
    whole = rec.read_bytes()
    cut.write_bytes(killed)
    assert monitor.main(["--dbc", DBC, "--replay", str(cut), "--print"]) == 0
    out, err = capsys.readouterr()
    got = int(out.splitlines()[-3].split()[0])  # "N frames, 1 ids, ..."
    assert 0 < got <= n // 2 and f"{got} frames read up to the cut" in err and "was cut short" in err
    lines = [ln for ln in out.splitlines() if "GYRO_RATE" in ln and "YawRate" in ln]
    assert len(lines) == got  # in order, from the first
    assert lines[0].startswith("1000.000000 ") and "Counter=0" in lines[0]
    # Cut anywhere, even inside the first chunk or its end: read up to there, never an error.
    for size in (len(whole) // 3, 2 * len(whole) // 3, len(whole) - 1, 200):
        cut.write_bytes(whole[:size])
        assert monitor.main(["--dbc", DBC, "--replay", str(cut)]) == 0
        assert "was cut short" in capsys.readouterr().err
    cut.write_bytes(whole[:-1])
    assert viewer.main(["--dbc", DBC, "--replay", str(cut), "--headless-png", str(tmp_path / "v.png")]) == 0
    assert "was cut short" in capsys.readouterr().err
    cut.write_bytes(b"\x89MCAP0\r\n" + bytes(range(256)))  # not a recording, however cut: an error
    assert monitor.main(["--dbc", DBC, "--replay", str(cut)]) == 2
    assert "not a dynaqpc MCAP recording" in capsys.readouterr().err


def test_frames_longer_than_the_dbc_are_undecodable(tmp_path, capsys):
    """The firmware refuses a frame of the wrong length, longer or shorter: so do the tools (a
    longer one used to decode from its first bytes and pass its Crc check)."""
    db = cantools.database.load_file(DBC)
    gyro = db.get_message_by_name("GYRO_RATE")
    good = e2e_seal(gyro, gyro.encode({"YawRate": 1.5, "Temperature": 20, "Status": 0, "Counter": 3, "Crc": 0}))
    assert e2e_ok(gyro, good)
    assert not e2e_ok(gyro, good + b"\x00\x00\x00") and not e2e_ok(gyro, good[:4])
    with pytest.raises(WrongLength):
        decode_frame(gyro, good + b"\x00")
    log = tmp_path / "x.log"
    log.write_text(
        f"(1.0) can0 0A0#0102030405060708\n(2.0) can0 0A0#0102030405\n(3.0) can0 0A0#{good.hex()}\n"
        f"(4.0) can0 0A0#{good.hex()}00\n(5.0) can0 7AA#0102\n"
    )
    assert monitor.main(["--dbc", DBC, "--replay", str(log), "--print"]) == 0
    out, err = capsys.readouterr()
    assert "1.000000 GYRO_RATE: cannot decode 0102030405060708: wrong length: 8 bytes, GYRO_RATE has 5" in err
    assert "4.000000 GYRO_RATE: cannot decode" in err and "wrong length: 6 bytes" in err
    assert "2.000000 GYRO_RATE: Crc fails" in err
    # --print: a line for the good frame and the unknown id (raw), none for the three bad ones,
    # never one repeating the last good frame's values.
    printed = [ln for ln in out.splitlines() if ln[:1].isdigit() and "." in ln.split()[0]]
    assert printed == [
        "3.000000 0A0 GYRO_RATE YawRate=1.5 Temperature=20 Status=OK Counter=3 Crc=" + str(good[-1]),
        "5.000000 7AA ? 01 02",
    ]
    gyro_row = [ln for ln in out.splitlines() if " GYRO_RATE " in ln and "frames" not in ln][-1]
    assert gyro_row.split()[-1] == "3"  # undecodable: 2 wrong lengths, 1 Crc
    # The views skip it too: a BusState or a pose decoder never takes a longer frame.
    pose = db.get_message_by_name("TLM_POSE")
    data = pose.encode({s.name: 0 for s in pose.signals} | {"X": 1000, "Y": 800})
    dec = PoseDecoder(db, "TLM_POSE")
    assert dec.decode(can.Message(arbitration_id=pose.frame_id, is_extended_id=False, data=data)) is not None
    assert dec.decode(can.Message(arbitration_id=pose.frame_id, is_extended_id=False, data=data + b"\x00")) is None


def test_mcap_keeps_no_values_of_a_frame_whose_crc_fails(tmp_path):
    """Noise that decodes but fails its Crc: the raw channel keeps its bytes, the decoded channel
    and the pose get nothing from it (the monitor counts it undecodable)."""
    db = cantools.database.load_file(DBC)
    good, bad = _gyro(db, 1), _gyro(db, 2)
    bad.data = bytearray(bad.data)
    bad.data[-1] ^= 0x5A  # the Crc byte
    assert not e2e_ok(db.get_message_by_name("GYRO_RATE"), bad.data)
    rec = tmp_path / "run.mcap"
    log = McapLog(str(rec), db)
    for m in (good, bad):
        log(m)
    log.stop()
    _, _, msgs = read_mcap(rec)
    assert [t for t, _, _ in msgs] == ["/can/raw", "/can/GYRO_RATE", "/can/raw"]
    assert msgs[2][2]["data_hex"] == bytes(bad.data).hex()


def test_a_sigkill_loses_at_most_one_small_chunk(tmp_path):
    """What the disk holds while the recorder runs trails it by at most one chunk of records."""
    db = cantools.database.load_file(DBC)
    rec = tmp_path / "run.mcap"
    log = McapLog(str(rec), db)
    for i in range(3000):
        log(_gyro(db, i))
    log._file.flush()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(rec.read_bytes())
    log.stop()
    frames = list(read_log(str(cut)))
    per_frame = CHUNK_BYTES / 60  # a GYRO_RATE's two records take well over 60 bytes
    assert 3000 - per_frame <= len(frames) < 3000
