# SPDX-License-Identifier: MIT
"""dynaqpc-viewer: pose decoding by signal name and unit; headless PNG from a recorded log."""

import json
import math

import can
import cantools
import pytest

from dynaqpc_tools import viewer
from dynaqpc_tools.bus_decode import e2e_seal
from dynaqpc_tools.common import ToolError


def _pose_msg(db, t, x_mm, y_mm, heading_deg, counter):
    m = db.get_message_by_name("POSE_T")
    return can.Message(
        timestamp=t,
        arbitration_id=m.frame_id,
        is_extended_id=False,
        data=m.encode({"X": x_mm, "Y": y_mm, "Heading": heading_deg, "FixState": 1, "Counter": counter % 16}),
    )


def test_pose_decoder_converts_units(test_dbc):
    db = cantools.database.load_file(test_dbc)
    dec = viewer.PoseDecoder(db, "POSE_T")
    p = dec.decode(_pose_msg(db, 3.0, 1500, -250, 90.0, 1))
    assert p.x == pytest.approx(1.5) and p.y == pytest.approx(-0.25)
    assert p.heading == pytest.approx(math.pi / 2) and p.fix == 1 and p.t == 3.0
    other = can.Message(
        arbitration_id=db.get_message_by_name("STATUS_T").frame_id, is_extended_id=False, data=b"\x00\x00"
    )
    assert dec.decode(other) is None
    with pytest.raises(ToolError, match="no frame TLM_POSE"):
        viewer.PoseDecoder(db)  # the test DBC names its pose frame differently: nothing hard-coded


def test_headless_png_from_a_log(tmp_path, test_dbc):
    db = cantools.database.load_file(test_dbc)
    log = tmp_path / "run.asc"
    with can.Logger(str(log)) as w:
        for i in range(40):
            a = i / 40 * 2 * math.pi
            w(
                _pose_msg(
                    db,
                    i * 0.192,
                    round(2000 + 1000 * math.cos(a)),
                    round(1500 + 1000 * math.sin(a)),
                    (math.degrees(a) + 90) % 360,
                    i,
                )
            )
    arena = tmp_path / "arena.json"
    arena.write_text(json.dumps({"width": 4, "height": 3, "obstacles": [], "goal": {"cx": 3, "cy": 2, "r": 0.3}}))
    png = tmp_path / "pose.png"
    args = viewer.build_parser().parse_args(
        [
            "--dbc",
            test_dbc,
            "--frame",
            "POSE_T",
            "--replay",
            str(log),
            "--arena",
            str(arena),
            "--headless-png",
            str(png),
        ]
    )
    view = viewer.run(args)
    assert view.poses == 40
    assert view.last.x == pytest.approx(2.0 + math.cos(39 / 40 * 2 * math.pi), abs=1e-3)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 5000


from conftest import REPO  # noqa: E402

DBC = str(REPO / "docs" / "dynaqpc.dbc")


def _frame(db, name, t, **signals):
    m = db.get_message_by_name(name)
    values = {s.name: 0 for s in m.signals}
    values.update(signals)
    return can.Message(timestamp=t, arbitration_id=m.frame_id, is_extended_id=False, data=e2e_seal(m, m.encode(values)))


def _scan(db, t, counter, **sonars):
    """A sonar scan: SONAR_RANGES_A, _B and _C with one Counter; sonars not named read 100 cm."""
    frames = []
    for name in ("SONAR_RANGES_A", "SONAR_RANGES_B", "SONAR_RANGES_C"):
        m = db.get_message_by_name(name)
        values = {s.name: 100 for s in m.signals if s.name.startswith("Sonar")}
        values.update({k: v for k, v in sonars.items() if k in values})
        frames.append(_frame(db, name, t, Counter=counter, **values))
    return frames


def test_a_sonar_scan_is_drawn_whole():
    """The viewer and Foxglove (both draw BusState.rays) show a scan once its three parts of one
    Counter are in, as the firmware takes it; a scan a part of which never came, or came twice
    in two different copies, is dropped and the last whole scan stays drawn, never a mix."""
    from dynaqpc_tools.bus_decode import BusState

    db = cantools.database.load_file(DBC)
    state = BusState(db)
    a, b, c = _scan(db, 1.0, 1, Sonar0=40, Sonar7=70, Sonar15=150)
    state.feed(a)
    state.feed(b)
    assert state.rays == {}  # two parts of three: nothing yet
    state.feed(c)
    assert len(state.rays) == 16 and state.sonar_scans == 1
    assert (state.rays["Sonar0"][1], state.rays["Sonar7"][1], state.rays["Sonar15"][1]) == pytest.approx(
        (0.4, 0.7, 1.5)
    )
    assert state.rays["Sonar3"][1] == 1.0
    drawn = dict(state.rays)
    # Scan 2 loses its C: scan 3's A drops it; scan 1 stays drawn until scan 3 is whole.
    a2, b2, _ = _scan(db, 1.1, 2, Sonar0=20, Sonar7=20)
    a3, b3, c3 = _scan(db, 1.2, 3, Sonar0=60, Sonar15=250)
    for f in (a2, b2, a3, b3):
        state.feed(f)
        assert state.rays == drawn
    assert state.sonar_dropped == 1
    state.feed(c3)
    assert state.sonar_scans == 2
    assert (state.rays["Sonar0"][1], state.rays["Sonar7"][1], state.rays["Sonar15"][1]) == pytest.approx(
        (0.6, 1.0, 2.5)
    )
    drawn = dict(state.rays)
    # Two different copies of scan 4's A: one is not the sensor's, the scan is dropped.
    a4, b4, c4 = _scan(db, 1.3, 4, Sonar0=30)
    (other, *_) = _scan(db, 1.3, 4, Sonar0=90)
    for f in (a4, other, b4, c4):
        state.feed(f)
    assert state.rays == drawn and state.sonar_dropped == 2 and state.sonar_scans == 2
    # The same copy of a part again is a repeat: scan 5 is whole.
    a5, b5, c5 = _scan(db, 1.4, 5, Sonar0=80)
    for f in (a5, a5, b5, c5):
        state.feed(f)
    assert state.rays["Sonar0"][1] == 0.8 and state.sonar_scans == 3 and state.sonar_dropped == 2


def _two_episodes(db):
    """Episode 1 drives east along y = 0.5 m and bumps once; the operator puts the robot down
    2 m away (x 3.0 m, y 2.5 m) for episode 2, which drives west."""
    msgs, t = [], 0.0
    msgs.append(_frame(db, "FW_STATUS", t, Mode=2))
    for episode, (x0, y0, dx) in ((1, (0.5, 0.5, 0.1)), (2, (3.0, 2.5, -0.1))):
        for step in range(10):
            t += 0.192
            x = x0 + dx * step
            msgs.append(
                _frame(
                    db, "TLM_POSE", t, X=round(x * 1000), Y=round(y0 * 1000), Heading=0 if dx > 0 else 180, FixState=0
                )
            )
            msgs.append(_frame(db, "TLM_LEARN", t, Episode=episode, Step=step + 1, Action=0))
            msgs.append(
                _frame(
                    db,
                    "IR_RANGES",
                    t,
                    RangeLeft=400,
                    RangeFront=250,
                    RangeRight=900,
                    ValidLeft=1,
                    ValidFront=1,
                    ValidRight=0,
                )
            )
            msgs.append(_frame(db, "MOTOR_STATUS", t, BumpFront=int(episode == 1 and step in (4, 5)), Enabled=1))
        msgs.append(_frame(db, "TLM_EPISODE", t, Episode=episode, Steps=10))
    msgs.append(_frame(db, "FW_STATUS", t + 0.1, Mode=1))
    return msgs


def test_one_trail_per_episode_with_readout_rays_and_bumps(tmp_path):
    db = cantools.database.load_file(DBC)
    log = tmp_path / "run.asc"
    with can.Logger(str(log)) as w:
        for m in _two_episodes(db):
            w(m)
    png = tmp_path / "v.png"
    # --jump 5: only the episode frames may split the trail here
    view = viewer.run(viewer.build_parser().parse_args(["--replay", str(log), "--png", str(png), "--jump", "5"]))
    assert view.poses == 20
    assert [len(s) for s in view.segments] == [10, 10]
    for seg in view.segments:  # no line across the room
        assert all(math.hypot(b[0] - a[0], b[1] - a[1]) < 0.2 for a, b in zip(seg, seg[1:]))
    text = view.title.get_text()
    assert "episode 2" in text and "mode IDLE" in text and "fix FRESH" in text
    assert view.bumps == [(pytest.approx(0.9), pytest.approx(0.5))]  # one bump: the rising edge
    rays = view.state.rays
    assert rays["RangeFront"] == (0.0, pytest.approx(0.25)) and rays["RangeRight"][1] is None
    assert len(view.ray_lines) == 3
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # TLM_EPISODE lost: TLM_LEARN's new episode number splits the trail as well, one pose late here
    # (this log sends the pose before TLM_LEARN); the jump splits it where the robot was put down.
    end = db.get_message_by_name("TLM_EPISODE").frame_id
    with can.Logger(str(log)) as w:
        for m in _two_episodes(db):
            if m.arbitration_id != end:
                w(m)
    view = viewer.run(viewer.build_parser().parse_args(["--replay", str(log), "--png", str(png), "--jump", "5"]))
    assert [len(s) for s in view.segments] == [11, 9]
    view = viewer.run(viewer.build_parser().parse_args(["--replay", str(log), "--png", str(png)]))
    assert [len(s) for s in view.segments] == [10, 10]


def test_a_replay_scrubs_back(tmp_path):
    # --at K (and the window's slider, which calls the same show_upto): the run as it was at pose
    # K: the first episode's trail only, no bump yet, its readout.
    db = cantools.database.load_file(DBC)
    log = tmp_path / "run.asc"
    with can.Logger(str(log)) as w:
        for m in _two_episodes(db):
            w(m)
    png = tmp_path / "v.png"
    args = ["--replay", str(log), "--png", str(png), "--jump", "5"]
    view = viewer.run(viewer.build_parser().parse_args(args + ["--at", "5"]))
    assert [len(s) for s in view.segments] == [5] and view.poses == 5
    assert "episode 1" in view.title.get_text() and view.bumps == []
    view.show_upto(19)  # and forward again: as the whole run
    assert [len(s) for s in view.segments] == [10, 10] and "episode 2" in view.title.get_text()
    assert len(view.bumps) == 1
    view.show_upto(12)
    assert [len(s) for s in view.segments] == [10, 3]
    assert viewer.main(["--png", str(png), "--at", "3", "--interface", "virtual"]) == 2


def test_a_jump_starts_a_new_trail_without_episode_frames(tmp_path, test_dbc):
    db = cantools.database.load_file(test_dbc)
    log = tmp_path / "run.asc"
    with can.Logger(str(log)) as w:
        for i in range(20):
            x = 500 + 50 * (i % 10) + (2500 if i >= 10 else 0)
            w(_pose_msg(db, i * 0.192, x, 1000, 0.0, i))
    view = viewer.run(
        viewer.build_parser().parse_args(
            ["--dbc", test_dbc, "--frame", "POSE_T", "--replay", str(log), "--png", str(tmp_path / "v.png")]
        )
    )
    assert [len(s) for s in view.segments] == [10, 10]


def test_without_a_display_it_says_so_and_exits_2(tmp_path, test_dbc, monkeypatch, capsys):
    log = tmp_path / "run.asc"
    db = cantools.database.load_file(test_dbc)
    with can.Logger(str(log)) as w:
        w(_pose_msg(db, 0.0, 1000, 1000, 0.0, 0))
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert viewer.main(["--dbc", test_dbc, "--frame", "POSE_T", "--replay", str(log)]) == 2
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and "no display" in err[0] and "--png" in err[0], err
    assert "poses" not in captured.out  # it did not pretend to show anything


def test_rays_stop_at_what_they_hit_and_the_picture_has_a_key(tmp_path):
    """A reading longer than the room (a far echo, or the firmware's pose a little off) is drawn
    only up to the wall or obstacle the ray meets; the legend names every mark and the room's."""
    db = cantools.database.load_file(DBC)
    log = tmp_path / "run.asc"
    with can.Logger(str(log)) as w:
        w(_frame(db, "TLM_POSE", 0.1, X=3800, Y=500, Heading=0, FixState=0))  # 0.2 m from the east wall
        w(
            _frame(
                db,
                "IR_RANGES",
                0.1,
                RangeLeft=900,
                RangeFront=900,
                RangeRight=100,
                ValidLeft=1,
                ValidFront=1,
                ValidRight=1,
            )
        )
        w(_frame(db, "TLM_POSE", 0.3, X=3800, Y=500, Heading=0, FixState=0))
    arena = tmp_path / "arena.json"
    arena.write_text(
        json.dumps(
            {
                "name": "box-room",
                "width": 4.0,
                "height": 3.0,
                "obstacles": [{"kind": "circle", "cx": 3.8, "cy": 1.0, "r": 0.2}],
                "goal": {"cx": 1.0, "cy": 1.0, "r": 0.3},
                "beacons": [],
            }
        )
    )
    png = tmp_path / "v.png"
    view = viewer.run(
        viewer.build_parser().parse_args(["--replay", str(log), "--arena", str(arena), "--png", str(png)])
    )
    lengths = {}
    for ln in view.ray_lines:
        (x0, x1), (y0, y1) = ln.get_xdata(), ln.get_ydata()
        lengths[round(math.degrees(math.atan2(y1 - y0, x1 - x0)))] = math.hypot(x1 - x0, y1 - y0)
    assert lengths[0] == pytest.approx(0.2, abs=1e-3)  # front: the wall, not 0.9 m
    assert lengths[45] == pytest.approx(0.2 * math.sqrt(2), abs=1e-3)  # left: the wall at 45 degrees
    assert lengths[-45] == pytest.approx(0.1, abs=1e-3)  # right: its own reading, nothing nearer
    labels = [t.get_text() for t in view.ax.get_legend().get_texts()]
    assert any("range ray" in s for s in labels) and any("bump" in s for s in labels)
    assert any("obstacle" in s for s in labels) and "goal" in labels
    assert "TLM_POSE" in view.fig._suptitle.get_text() and "box-room" in view.fig._suptitle.get_text()


def test_frames_whose_crc_fails_are_not_drawn():
    """The end-to-end Crc (docs/can-protocol.md): a bump or a pose in noise is not shown."""
    from dynaqpc_tools.bus_decode import BusState, PoseDecoder, e2e_ok

    db = cantools.database.load_file(DBC)
    bump = _frame(db, "MOTOR_STATUS", 1.0, BumpFront=1, Enabled=1)
    assert e2e_ok(db.get_message_by_name("MOTOR_STATUS"), bump.data)
    noise = can.Message(timestamp=1.0, arbitration_id=bump.arbitration_id, is_extended_id=False, data=bytes(bump.data))
    noise.data[-1] ^= 0x01
    state = BusState(db)
    assert state.feed(noise) == "" and not state.bumping
    assert state.feed(bump) == "bump"
    gps = _frame(db, "GPS_POSE", 2.0, X=1000, Y=500, Heading=90.0, Fix=2)
    dec = PoseDecoder(db, "GPS_POSE")
    assert dec.decode(gps) is not None
    gps.data[0] ^= 0x80
    assert dec.decode(gps) is None
    # A scan is three frames, each with its CRC-8: a part that fails it leaves the scan unfinished
    # (nothing drawn) until the part comes whole.
    for name, sig in (("SONAR_RANGES_A", "Sonar0"), ("SONAR_RANGES_B", "Sonar7"), ("SONAR_RANGES_C", "Sonar15")):
        scan = _scan(db, 3.0, 5, **{sig: 50})
        sonar = next(f for f in scan if f.arbitration_id == db.get_message_by_name(name).frame_id)
        assert e2e_ok(db.get_message_by_name(name), sonar.data)
        state = BusState(db)
        sonar.data[0] ^= 0x01
        assert not e2e_ok(db.get_message_by_name(name), sonar.data)
        for f in scan:
            state.feed(f)
        assert state.rays == {} and state.sonar_scans == 0
        sonar.data[0] ^= 0x01
        state.feed(sonar)
        assert state.rays[sig][1] == 0.5 and state.sonar_scans == 1  # 50 cm, as sent
    for f in _scan(db, 3.1, 6, Sonar0=200, Sonar1=254):  # 254 cm: raw 127, no echo
        state.feed(f)
    assert state.rays["Sonar0"][1] == 2.0 and state.rays["Sonar1"][1] is None
    # Its unused bits (Reserved) are sent as 0: a frame with one set is noise, whatever its Crc.
    m = db.get_message_by_name("SONAR_RANGES_C")
    assert not e2e_ok(m, e2e_seal(m, m.encode({s.name: 0 for s in m.signals} | {"Reserved": 1})))
