# SPDX-License-Identifier: MIT
"""dynaqpc-monitor: decoding with the DBC, rates, counter gaps, logging and replay."""

import can
import cantools

from dynaqpc_tools import monitor


def _pose(db, t, counter, x=100):
    m = db.get_message_by_name("POSE_T")
    data = m.encode({"X": x, "Y": -50, "Heading": 90.0, "FixState": 0, "Counter": counter})
    return can.Message(timestamp=t, arbitration_id=m.frame_id, is_extended_id=False, data=data)


def _status(db, t, counter):
    m = db.get_message_by_name("STATUS_T")
    return can.Message(
        timestamp=t,
        arbitration_id=m.frame_id,
        is_extended_id=False,
        data=m.encode({"Mode": 2, "STATUS_COUNTER": counter}),
    )


def recorded_sequence(db):
    """POSE_T at 10 Hz with counters 0..5, 8 (2 lost), 9, 9 (a repeat), 10..15, 0 (wrap);
    STATUS_T wrapping 254, 255, 0, 1 without loss; an event frame without counter; an id the DBC
    does not know; a POSE_T too short to decode."""
    msgs, t = [], 0.0
    for c in [0, 1, 2, 3, 4, 5, 8, 9, 9, 10, 11, 12, 13, 14, 15, 0]:
        msgs.append(_pose(db, t, c))
        t += 0.1
    for i, c in enumerate([254, 255, 0, 1]):
        msgs.append(_status(db, 10.0 + i, c))
    ev = db.get_message_by_name("EVENT_T")
    msgs.append(
        can.Message(timestamp=12.0, arbitration_id=ev.frame_id, is_extended_id=False, data=ev.encode({"Episode": 7}))
    )
    msgs.append(can.Message(timestamp=12.5, arbitration_id=0x7AA, is_extended_id=False, data=b"\x01\x02"))
    msgs.append(
        can.Message(
            timestamp=13.0,
            arbitration_id=db.get_message_by_name("POSE_T").frame_id,
            is_extended_id=False,
            data=b"\x00\x01",
        )
    )
    return msgs


def test_monitor_counts_gaps_repeats_and_decodes(test_dbc):
    db = cantools.database.load_file(test_dbc)
    mon = monitor.Monitor(db)
    events = []
    for msg in recorded_sequence(db):
        events += mon.feed(msg)
    pose = mon.stats[(db.get_message_by_name("POSE_T").frame_id, False)]
    assert pose.name == "POSE_T"
    assert pose.count == 17
    assert pose.missing == 2 and pose.gap_events == 1
    assert pose.repeats == 1
    assert pose.decode_errors == 1
    assert pose.values["X"] == 100 and pose.values["Heading"] == 90.0
    status = mon.stats[(db.get_message_by_name("STATUS_T").frame_id, False)]
    assert status.counter_signal == "STATUS_COUNTER" and status.counter_modulo == 256
    assert status.missing == 0 and status.repeats == 0
    assert abs(status.mean_rate_hz() - 1.0) < 1e-9
    event = mon.stats[(db.get_message_by_name("EVENT_T").frame_id, False)]
    assert event.counter_signal is None and event.values == {"Episode": 7}
    assert mon.stats[(0x7AA, False)].name == "?"
    assert mon.frames_missing == 2
    assert any("5 -> 8: 2 frame(s) lost" in e for e in events)
    assert any("repeated 9" in e for e in events)
    assert abs(pose.mean_rate_hz() - 16 / 13.0) < 1e-9  # 17 frames over 0..13 s
    summary = "\n".join(mon.summary_lines())
    assert "2 frames lost" in summary


def test_monitor_replays_a_log_and_writes_one(tmp_path, test_dbc, capsys):
    db = cantools.database.load_file(test_dbc)
    src = tmp_path / "run.asc"
    with can.Logger(str(src)) as log:
        for msg in recorded_sequence(db):
            log(msg)
    out = tmp_path / "copy.blf"
    rc = monitor.main(["--dbc", test_dbc, "--replay", str(src), "--log", str(out), "--fail-on-gap"])
    text = capsys.readouterr().out
    assert rc == 1  # the gap was seen
    assert "23 frames" in text and "2 frames lost" in text
    assert len(list(can.LogReader(str(out)))) == 23
    # --count stops early; before the gap, nothing is lost.
    rc = monitor.main(["--dbc", test_dbc, "--replay", str(src), "--count", "5", "--fail-on-gap"])
    assert rc == 0
    assert "5 frames" in capsys.readouterr().out


def test_monitor_reports_a_missing_dbc(tmp_path, capsys):
    rc = monitor.main(["--dbc", str(tmp_path / "none.dbc"), "--replay", str(tmp_path / "x.asc")])
    assert rc == 2
    assert "DBC file not found" in capsys.readouterr().err


def test_monitor_says_when_it_listens_before_any_frame(capsys):
    """A live bus: one stderr line once the bus is open (scripts send after it), none on replay."""
    rc = monitor.main(["--interface", "virtual", "--channel", "monitor-listens", "--duration", "0.05"])
    assert rc == 0
    err = capsys.readouterr().err.splitlines()
    assert err == ["dynaqpc-monitor: listening on virtual:monitor-listens"]
