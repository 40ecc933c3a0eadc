# SPDX-License-Identifier: MIT
"""dynaqpc-viewer: pose decoding by signal name and unit; headless PNG from a recorded log."""

import json
import math

import can
import cantools
import pytest

from dynaqpc_tools import viewer
from dynaqpc_tools.common import ToolError


def _pose_msg(db, t, x_mm, y_mm, heading_deg, counter):
    m = db.get_message_by_name("POSE_T")
    return can.Message(timestamp=t, arbitration_id=m.frame_id, is_extended_id=False,
                       data=m.encode({"X": x_mm, "Y": y_mm, "Heading": heading_deg, "FixState": 1,
                                      "Counter": counter % 16}))


def test_pose_decoder_converts_units(test_dbc):
    db = cantools.database.load_file(test_dbc)
    dec = viewer.PoseDecoder(db, "POSE_T")
    p = dec.decode(_pose_msg(db, 3.0, 1500, -250, 90.0, 1))
    assert p.x == pytest.approx(1.5) and p.y == pytest.approx(-0.25)
    assert p.heading == pytest.approx(math.pi / 2) and p.fix == 1 and p.t == 3.0
    other = can.Message(arbitration_id=db.get_message_by_name("STATUS_T").frame_id, is_extended_id=False,
                        data=b"\x00\x00")
    assert dec.decode(other) is None
    with pytest.raises(ToolError, match="no frame TLM_POSE"):
        viewer.PoseDecoder(db)  # the test DBC names its pose frame differently: nothing hard-coded


def test_headless_png_from_a_log(tmp_path, test_dbc):
    db = cantools.database.load_file(test_dbc)
    log = tmp_path / "run.asc"
    with can.Logger(str(log)) as w:
        for i in range(40):
            a = i / 40 * 2 * math.pi
            w(_pose_msg(db, i * 0.192, round(2000 + 1000 * math.cos(a)), round(1500 + 1000 * math.sin(a)),
                        (math.degrees(a) + 90) % 360, i))
    arena = tmp_path / "arena.json"
    arena.write_text(json.dumps({"width": 4, "height": 3, "obstacles": [], "goal": {"cx": 3, "cy": 2, "r": 0.3}}))
    png = tmp_path / "pose.png"
    args = viewer.build_parser().parse_args(["--dbc", test_dbc, "--frame", "POSE_T", "--replay", str(log),
                                             "--arena", str(arena), "--headless-png", str(png)])
    view = viewer.run(args)
    assert view.poses == 40
    assert view.last.x == pytest.approx(2.0 + math.cos(39 / 40 * 2 * math.pi), abs=1e-3)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 5000
