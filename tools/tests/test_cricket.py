# SPDX-License-Identifier: MIT
"""dynaqpc-cricket: parsing by key, switched-off fields, garbage, trilateration, a pty to EOF."""

import io
import math
import os
import threading

import pytest

from dynaqpc_tools import cricket
from dynaqpc_tools.cricket import CricketLineError, parse_line

# The listener's default line (Cricket v2 manual format).
LINE = "VR=2.0,ID=01:cf:bd:43:0b:00:00:b0,SP=space1,DB=178,DR=5212,TM=10344,TS=42398\r\n"


def test_parses_the_default_line_by_key():
    r = parse_line(LINE)
    assert r.fields["VR"] == "2.0" and r.fields["TS"] == "42398"
    assert r.beacon == "01:cf:bd:43:0b:00:00:b0"
    assert r.range_source == "DR"
    assert r.range_m == pytest.approx(5212e-6 * 343.0)  # 1.7877 m


def test_fields_switched_off():
    r = parse_line("VR=2.0,SP=space1,DB=178")  # no ID, no DR: the space name and the cm distance
    assert r.beacon == "space1" and r.range_source == "DB" and r.range_m == pytest.approx(1.78)
    r = parse_line("DR=1000")
    assert r.beacon is None and r.range_m == pytest.approx(0.343)
    r = parse_line("VR=2.0,ID=01:02:03:04:05:06:07:08,TS=5")
    assert not r.has_range
    r = parse_line("ID=0102030405060708,DR=2000,XX=7")  # an unknown key is kept, not fatal
    assert r.fields["XX"] == "7" and r.range_m == pytest.approx(0.686)


@pytest.mark.parametrize("line", [
    "", "\r\n", "hello world", "VR=2.0,,DB=1", "VR=2.0,DB=abc", "DB=1,DB=2", "VR=2.0,DR=-5",
    "ID=zz:01,DR=5", "\x00\xff\x13", "VR=2.0,DB=", "vr=2.0", "AB=1,CD=2", "VR=2.0,DB=1 2",
])
def test_garbage_is_rejected_with_a_reason(line):
    with pytest.raises(CricketLineError) as e:
        parse_line(line)
    assert str(e.value)


def test_trilateration_recovers_the_position():
    beacons = {"a": (0.0, 0.0, 2.5), "b": (4.0, 0.0, 2.5), "c": (0.0, 4.0, 2.5), "d": (4.0, 4.0, 2.4)}
    x, y, z = 1.2, 2.5, 0.1
    ranges = {k: math.dist((x, y, z), p) for k, p in beacons.items()}
    fx, fy, resid = cricket.trilaterate(ranges, beacons, listener_z=z)
    assert fx == pytest.approx(x, abs=1e-6) and fy == pytest.approx(y, abs=1e-6) and resid < 1e-6
    assert cricket.trilaterate({"a": 1.0, "b": 2.0}, beacons) is None  # two beacons: ambiguous
    line = {"a": (0, 0, 2), "b": (1, 0, 2), "c": (2, 0, 2)}
    assert cricket.trilaterate({"a": 2.0, "b": 2.0, "c": 2.5}, line) is None  # collinear


def test_beacons_file(tmp_path):
    p = tmp_path / "beacons.txt"
    p.write_text("# id x y z\nspace1 0 0 2.5\n\nspace2 4 0 2.5  # east\n")
    assert cricket.load_beacons(str(p)) == {"space1": (0.0, 0.0, 2.5), "space2": (4.0, 0.0, 2.5)}
    p.write_text("space1 0 0\n")
    with pytest.raises(cricket.ToolError, match=":1:"):
        cricket.load_beacons(str(p))


class _Signal(io.StringIO):
    """A stream that tells when the console has opened the port."""

    def __init__(self):
        super().__init__()
        self.opened = threading.Event()

    def write(self, s):
        if "listening on" in s:
            self.opened.set()
        return super().write(s)


def test_console_reads_a_pty_to_end_of_stream(tmp_path):
    master, slave = os.openpty()
    path = os.ttyname(slave)
    os.close(slave)
    beacons = tmp_path / "beacons.txt"
    pos = {"space1": (0.0, 0.0, 2.0), "space2": (3.0, 0.0, 2.0), "space3": (0.0, 3.0, 2.0)}
    beacons.write_text("".join(f"{k} {x} {y} {z}\n" for k, (x, y, z) in pos.items()))
    lines = []
    for k, p in pos.items():  # listener at (1, 1, 0)
        dr_us = round(math.dist((1.0, 1.0, 0.0), p) / 343.0 * 1e6)
        lines.append(f"VR=2.0,SP={k},DB={round(dr_us * 343e-4)},DR={dr_us},TM=1,TS=2\r\n")
    lines.insert(1, "#### garbage ####\r\n")
    out, err = io.StringIO(), _Signal()
    args = cricket.build_parser().parse_args([path, "--beacons", str(beacons)])
    result = {}
    t = threading.Thread(target=lambda: result.setdefault("c", cricket.run(args, out, err)))
    t.start()
    assert err.opened.wait(10), "console did not open the pty"
    os.write(master, "".join(lines).encode())
    # Let the reader take the bytes before hanging up (closing drops unread pty input).
    deadline = 200
    while deadline and "fix" not in out.getvalue():
        threading.Event().wait(0.05)
        deadline -= 1
    os.close(master)  # end of stream
    t.join(10)
    assert not t.is_alive(), "console did not end at end of stream"
    c = result["c"]
    assert c.readings == 3 and c.garbage == 1 and c.fixes == 1
    text = out.getvalue()
    assert "beacon space1" in text and "3 readings, 1 skipped, 1 fixes" in text
    fix = [ln for ln in text.splitlines() if "fix x=" in ln][0]
    fx = float(fix.split("x=")[1].split()[0])
    fy = float(fix.split("y=")[1].split()[0])
    assert fx == pytest.approx(1.0, abs=0.01) and fy == pytest.approx(1.0, abs=0.01)
    assert "skipped line '#### garbage ####'" in err.getvalue()


def test_console_reports_a_missing_device(capsys):
    assert cricket.main(["/dev/does-not-exist"]) == 2
    assert "cannot open /dev/does-not-exist" in capsys.readouterr().err
