# SPDX-License-Identifier: MIT
"""dynaqpc-cricket: parsing by key, switched-off fields, garbage, trilateration, a pty to EOF."""

import io
import math
import os
import re
import threading

import pytest
from conftest import REPO, c_binary, in_netns

from dynaqpc_tools import cricket
from dynaqpc_tools.cricket import CricketLineError, parse_line

# The listener's default line (Cricket v2 manual format).
LINE = "VR=2.0,ID=01:cf:bd:43:0b:00:00:b0,SP=space1,DB=178,DR=5212,TM=10344,TS=42398\r\n"
VECTORS = REPO / "docs" / "cricket-lines.tsv"


def shared_vectors():
    out = []
    for row in VECTORS.read_text(encoding="utf-8").splitlines():
        if row and not row.startswith("#"):
            want, line = row.split("\t", 1)
            out.append((want, line))
    return out


def test_the_shared_vectors_are_read_as_the_firmware_reads_them():
    # docs/cricket-lines.tsv: the same file the firmware's unit.cricket checks cricket_parse_line with.
    vectors = shared_vectors()
    assert len(vectors) >= 40 and sum(w == "bad" for w, _ in vectors) >= 20
    for want, line in vectors:
        if want == "bad":
            with pytest.raises(CricketLineError):
                parse_line(line)
        else:
            assert parse_line(line).describe() == want, line


def test_parses_the_default_line_by_key():
    r = parse_line(LINE)
    assert r.values["VR"] == "2.0" and r.values["TS"] == 42398
    assert r.beacon_id == 0x01CFBD430B0000B0 and cricket.id_text(r.beacon_id) == "01:cf:bd:43:0b:00:00:b0"
    assert r.range_source == "DR" and r.has_range
    assert r.range_m == pytest.approx(5212e-6 * 343.0)  # 1.7877 m


def test_the_simulators_one_digit_ids():
    r = parse_line("VR=2.0,ID=1:5e:3c:3c:a:0:0:b3,SP=LAB,DB=210,DR=6174,TM=7012,TS=32457")
    assert r.beacon_id == cricket.parse_id("01:5e:3c:3c:0a:00:00:b3") and r.has_range


def test_fields_switched_off():
    r = parse_line("VR=2.0,SP=space1,DB=178")  # no ID: a distance, but no beacon to give it to
    assert r.range_source == "DB" and r.range_m == pytest.approx(1.78) and not r.has_range
    r = parse_line("VR=2.0,ID=01:02:03:04:05:06:07:08,TS=5")
    assert not r.has_range
    r = parse_line("ID=1:2:3:4:5:6:7:8,DR=2000,XX=7")  # an unknown key is kept, not fatal
    assert r.raw["XX"] == "7" and r.range_m == pytest.approx(0.686) and r.has_range
    assert not parse_line("ID=1:2:3:4:5:6:7:8,DR=0").has_range  # 0 m: refused
    assert not parse_line("ID=1:2:3:4:5:6:7:8,DR=30000").has_range  # 10.3 m: refused


@pytest.mark.parametrize(
    "line",
    [
        "",
        "\r\n",
        "hello world",
        "VR=2.0,,DB=1",
        "VR=2.0,DB=abc",
        "DB=1,DB=2",
        "VR=2.0,DR=-5",
        "ID=zz:01,DR=5",
        "\x00\xff\x13",
        "VR=2.0,DB=",
        "VR=2.0,DB=1 2",
        "ID=0102030405060708,DR=5",
    ],
)
def test_garbage_is_rejected_with_a_reason(line):
    with pytest.raises(CricketLineError) as e:
        parse_line(line)
    assert str(e.value)


def test_line_max_is_the_firmwares():
    header = REPO / "firmware" / "drivers" / "include" / "drivers" / "drivers_config.h"
    m = re.search(r"#define FW_CFG_CRICKET_LINE_MAX (\d+)", header.read_text(encoding="utf-8"))
    assert m and int(m.group(1)) == cricket.LINE_MAX


def _padded(n: int) -> str:
    """The default line with an unknown key padding it to n characters (line end not counted)."""
    base = LINE.rstrip("\r\n") + ",XX="
    return base + "A" * (n - len(base)) + "\r\n"


def test_a_line_over_the_firmwares_limit_is_skipped_as_overlong():
    c = cricket.Console()
    assert c.feed(_padded(cricket.LINE_MAX), 0.0)  # the longest line the firmware keeps
    assert c.readings == 1
    with pytest.raises(CricketLineError, match=f"overlong: {cricket.LINE_MAX + 1} characters"):
        c.feed(_padded(cricket.LINE_MAX + 1), 0.0)
    with pytest.raises(CricketLineError, match="overlong: 165 characters"):  # the audit's 167-byte line
        c.feed(_padded(165), 0.0)
    assert (c.lines, c.readings, c.garbage, c.overlong) == (3, 1, 2, 2)


def test_a_reason_quotes_only_the_start_of_a_long_value():
    with pytest.raises(CricketLineError) as e:
        parse_line("VR=2.0," + "B" * 5000)
    assert len(str(e.value)) < 100 and "(5000 characters)" in str(e.value)


class _Port:
    """pyserial's readline over a byte string: up to a LF, at most `size` bytes at a time."""

    def __init__(self, data: bytes, size: int = 1000):
        self.data, self.size = data, size

    def readline(self):
        if not self.data:
            raise OSError("end of stream")
        n = self.data.find(b"\n")
        n = self.size if n < 0 else min(n + 1, self.size)
        chunk, self.data = self.data[:n], self.data[n:]
        return chunk


def test_a_runaway_line_is_given_once_and_its_rest_dropped():
    good = LINE.encode()
    data = good + b"VR=2.0," + b"A" * 100_000 + b"\r\n" + good + b"ID=1:2:3:4:5:6:7:8\r" * 300 + good
    got = [x for x in cricket.read_lines(_Port(data)) if x is not None]
    lines = [p for x in got for p in x.replace(b"\r", b"\n").split(b"\n") if p]
    assert lines[0] + b"\r\n" == good and lines[-1] + b"\r\n" == good
    assert len(lines[1]) > cricket.LINE_MAX and lines[1].startswith(b"VR=2.0,AAA")
    assert lines[2:-1] == [good.rstrip()] + [b"ID=1:2:3:4:5:6:7:8"] * 300  # CR-ended lines kept whole
    assert sum(len(x) for x in got) < len(data) - 90_000  # not the 100 KB


def test_the_shared_fix_vectors_are_solved_as_the_firmware_solves_them():
    # docs/cricket-fixes.tsv: the same file the firmware's unit.trilateration checks trilat_solve with.
    n = refused = 0
    for row in (REPO / "docs" / "cricket-fixes.tsv").read_text(encoding="utf-8").splitlines():
        if not row or row.startswith("#"):
            continue
        verdict, params, anchors = row.split("\t")
        z, spread, resid = (float(v) for v in params.split())
        an = [tuple(float(v) for v in a.split(",")) for a in anchors.split(";")]
        if verdict.startswith("ok "):
            x, y = (float(v) for v in verdict.split()[1:])
            fx, fy, _ = cricket.trilat_solve(an, z, spread, resid)
            assert fx == pytest.approx(x, abs=1.0) and fy == pytest.approx(y, abs=1.0), row
        else:
            with pytest.raises(cricket.TrilatRefused) as e:
                cricket.trilat_solve(an, z, spread, resid)
            assert e.value.kind == verdict, row
            refused += 1
        n += 1
    assert n >= 10 and refused >= 4


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
    p.write_text("# id x y z\n1:2:3:4:5:6:7:8 0 0 2.5\n\n01:02:03:04:05:06:07:09 4 0 2.5  # east\n")
    assert cricket.load_beacons(str(p)) == (
        {0x0102030405060708: (0.0, 0.0, 2.5), 0x0102030405060709: (4.0, 0.0, 2.5)},
        None,
    )
    p.write_text("1:2:3:4:5:6:7:8 0 0\n")
    with pytest.raises(cricket.ToolError, match=":1:"):
        cricket.load_beacons(str(p))
    p.write_text("space1 0 0 1\n")
    with pytest.raises(cricket.ToolError, match="not eight"):
        cricket.load_beacons(str(p))
    # A scenario: its beacon lines and the listener's height; an arena JSON.
    beacons, z = cricket.load_beacons(str(REPO / "host_sim" / "scenarios" / "paper-lab.scn"))
    assert len(beacons) == 5 and z == pytest.approx(0.15)
    assert beacons[cricket.parse_id("1:5e:3c:3c:a:0:0:b5")] == (2.15, 1.6, 2.5)
    j = tmp_path / "arena.json"
    j.write_text('{"width": 4, "height": 3, "beacons": [{"id": "1:5e:3c:3c:a:0:0:b1", "x": 0.5, "y": 0.5, "z": 2.5}]}')
    assert cricket.load_beacons(str(j))[0] == {cricket.parse_id("1:5e:3c:3c:a:0:0:b1"): (0.5, 0.5, 2.5)}


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
    pos = {
        "1:0:0:0:0:0:0:a1": (0.0, 0.0, 2.0),
        "1:0:0:0:0:0:0:a2": (3.0, 0.0, 2.0),
        "1:0:0:0:0:0:0:a3": (0.0, 3.0, 2.0),
    }
    beacons.write_text("".join(f"{k} {x} {y} {z}\n" for k, (x, y, z) in pos.items()))
    lines = []
    for k, p in pos.items():  # listener at (1, 1, 0)
        dr_us = round(math.dist((1.0, 1.0, 0.0), p) / 343.0 * 1e6)
        lines.append(f"VR=2.0,ID={k},SP=lab,DB={round(dr_us * 343e-4)},DR={dr_us},TM=1,TS=2\r\n")
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
    assert "beacon 01:00:00:00:00:00:00:a1" in text and "3 readings, 1 skipped, 1 fixes" in text
    fix = [ln for ln in text.splitlines() if "fix x=" in ln][0]
    fx = float(fix.split("x=")[1].split()[0])
    fy = float(fix.split("y=")[1].split()[0])
    assert fx == pytest.approx(1.0, abs=0.01) and fy == pytest.approx(1.0, abs=0.01)
    assert "skipped line '#### garbage ####'" in err.getvalue()


def test_console_reports_a_missing_device(capsys):
    assert cricket.main(["/dev/does-not-exist"]) == 2
    assert "cannot open /dev/does-not-exist" in capsys.readouterr().err


@pytest.mark.parametrize("argv", [["--count", "-5"], ["--max-age", "0"], ["--baud", "x"], ["--duration", "-1"]])
def test_numeric_arguments_are_range_checked(argv, capsys):
    with pytest.raises(SystemExit) as e:
        cricket.main(["/dev/null", *argv])
    assert e.value.code == 2 and len(capsys.readouterr().err.strip().splitlines()) == 1


@pytest.mark.skipif(not c_binary("dynaqpc-sim").exists(), reason="build dynaqpc-sim first or set DYNAQPC_BUILD_DIR")
def test_fixes_from_the_simulators_pty():
    """dynaqpc-sim devices on paper-lab (its bus in a private namespace) writes the Cricket
    listener's lines to a pty; the console, given the scenario's five beacons, prints fixes where
    the robot stands."""
    import subprocess

    scn = REPO / "host_sim" / "scenarios" / "paper-lab.scn"
    dev = subprocess.Popen(
        in_netns([str(c_binary("dynaqpc-sim")), "devices", "--scenario", str(scn), "--speed", "5", "--duration", "30"]),
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        tty = None
        for line in dev.stdout:
            if line.startswith("cricket_tty="):
                tty = line.strip().split("=", 1)[1]
                break
        assert tty, "dynaqpc-sim devices printed no cricket_tty"
        out, err = io.StringIO(), io.StringIO()
        args = cricket.build_parser().parse_args([tty, "--beacons", str(scn), "--duration", "6"])
        c = cricket.run(args, out, err)
    finally:
        dev.terminate()
        dev.wait(10)
    text = out.getvalue()
    assert c.readings >= 15 and c.garbage == 0, err.getvalue()[-2000:]
    fixes = [ln for ln in text.splitlines() if " fix x=" in ln]
    assert len(fixes) >= 5 and c.fixes == len(fixes)
    # The robot stands still: every fix lands on the same spot, inside the 4.3 m x 3.2 m room.
    xs = [float(ln.split("x=")[1].split()[0]) for ln in fixes]
    ys = [float(ln.split("y=")[1].split()[0]) for ln in fixes]
    assert all(0 < x < 4.3 for x in xs) and all(0 < y < 3.2 for y in ys)
    assert max(xs) - min(xs) < 0.1 and max(ys) - min(ys) < 0.1


def _run_on_pty(lines, argv, until=None):
    """The console on a pty fed `lines`; returns (console, out, err) once the stream ended."""
    master, slave = os.openpty()
    path = os.ttyname(slave)
    os.close(slave)
    out, err = io.StringIO(), _Signal()
    args = cricket.build_parser().parse_args([path, *argv])
    result = {}
    t = threading.Thread(target=lambda: result.setdefault("c", cricket.run(args, out, err)))
    t.start()
    assert err.opened.wait(10), "console did not open the pty"
    os.write(master, "".join(lines).encode("latin-1"))
    for _ in range(200):  # until the reader took them (closing drops unread pty input)
        text = out.getvalue() + err.getvalue()
        if until is not None and until(text):
            break
        threading.Event().wait(0.05)
    os.close(master)
    t.join(10)
    assert not t.is_alive()
    return result["c"], out.getvalue(), err.getvalue()


LAB = {
    "1:5e:3c:3c:a:0:0:b1": (0.5, 0.5, 2.5),
    "1:5e:3c:3c:a:0:0:b2": (3.8, 0.5, 2.5),
    "1:5e:3c:3c:a:0:0:b3": (0.5, 2.7, 2.5),
    "1:5e:3c:3c:a:0:0:b4": (3.8, 2.7, 2.5),
}


def _listener_lines(beacons, at=(1.2, 1.0, 0.15), repeat=2):
    out = []
    for _ in range(repeat):
        for k, p in beacons.items():
            dr = round(math.dist(at, p) / 343.0 * 1e6)
            out.append(f"VR=2.0,ID={k},SP=LAB,DB={round(dr * 343e-4)},DR={dr},TM=0,TS=0\r\n")
    return out


def test_beacon_ids_are_compared_as_bytes_however_spelt(tmp_path):
    same = [
        "1:5e:3c:3c:a:0:0:b1",
        "01:5E:3C:3C:0A:00:00:B1",
        "01-5e-3c-3c-0a-00-00-b1",
        "015e3c3c0a0000b1",
        "0x015E3C3C0A0000B1",
    ]
    assert {cricket.parse_beacon_id(t) for t in same} == {0x015E3C3C0A0000B1}
    # A beacons file in upper case, zero-padded, with the listener's height; the listener prints
    # one-digit lower-case bytes: the console fixes where the listener is.
    f = tmp_path / "beacons.txt"
    f.write_text(
        "listener_height 0.15\n"
        + "".join(
            f"{':'.join(f'{int(b, 16):02X}' for b in k.split(':'))} {x} {y} {z}\n" for k, (x, y, z) in LAB.items()
        )
    )
    beacons, z = cricket.load_beacons(str(f))
    assert z == 0.15 and set(beacons) == {cricket.parse_id(k) for k in LAB}
    c, out, err = _run_on_pty(_listener_lines(LAB), ["--beacons", str(f)], until=lambda t: t.count("fix x=") >= 5)
    assert c.fixes >= 5 and "hint" not in err
    fix = [ln for ln in out.splitlines() if "fix x=" in ln][-1]
    assert float(fix.split("x=")[1].split()[0]) == pytest.approx(1.2, abs=0.01)


def test_a_file_without_the_listeners_height_still_fixes(tmp_path):
    # The 0 fixes: a file of `ID x y z` lines spelt as the listener prints them, no height.
    # With the beacons at one height the ranges give the listener's height too: it fixes.
    f = tmp_path / "beacons.txt"
    f.write_text("".join(f"{k} {x} {y} {z}\n" for k, (x, y, z) in LAB.items()))
    c, out, err = _run_on_pty(_listener_lines(LAB), ["--beacons", str(f)], until=lambda t: t.count("fix x=") >= 5)
    assert c.fixes >= 5 and "hint" not in err
    fix = [ln for ln in out.splitlines() if "fix x=" in ln][-1]
    assert float(fix.split("x=")[1].split()[0]) == pytest.approx(1.2, abs=0.02)
    assert "listener height estimated" in fix and c.estimated_z == pytest.approx(0.15, abs=0.05)


def test_a_wrong_listener_height_is_hinted(tmp_path):
    # A height given, and wrong (0 m, 15 cm below the listener): every fix is refused as
    # inconsistent, and the console says why.
    f = tmp_path / "beacons.txt"
    f.write_text("".join(f"{k} {x} {y} {z}\n" for k, (x, y, z) in LAB.items()))
    c, out, err = _run_on_pty(
        _listener_lines(LAB), ["--beacons", str(f), "--listener-z", "0"], until=lambda t: t.count("beacon 01:") >= 8
    )
    assert c.readings == 8 and c.fixes == 0
    hints = [ln for ln in err.splitlines() if ln.startswith("hint:")]
    assert len(hints) == 1 and "listener's height" in hints[0] and "0 m" in hints[0]
    c, out, err = _run_on_pty(
        _listener_lines(LAB), ["--beacons", str(f), "--listener-z", "0.15"], until=lambda t: t.count("fix x=") >= 5
    )
    assert c.fixes >= 5 and "hint" not in err


def test_the_height_estimate(tmp_path):
    at = (1.2, 1.0, 0.15)
    anchors = [(x, y, z, math.dist(at, (x, y, z))) for x, y, z in LAB.values()]
    assert cricket.estimate_listener_z(anchors) == pytest.approx(0.15, abs=1e-6)
    assert cricket.estimate_listener_z(anchors[:3]) == pytest.approx(0.15, abs=1e-6)
    assert cricket.estimate_listener_z(anchors[:2]) is None  # too few
    tilted = [(x, y, z + 0.1 * i, r) for i, (x, y, z, r) in enumerate(anchors)]
    assert cricket.estimate_listener_z(tilted) is None  # not at one height
    line = [(float(i), 0.0, 2.5, 3.0) for i in range(4)]
    assert cricket.estimate_listener_z(line) is None  # on a line


def test_hints_when_every_line_is_skipped_and_when_no_beacon_matches(tmp_path):
    # The wrong baud rate: bytes, no lines a listener writes.
    noise = ["\x8a\xf3Z\x11\x9c=,\x02\r\n"] * 25
    c, out, err = _run_on_pty(noise, [], until=lambda t: "25 skipped" in t or t.count("skipped line") >= 25)
    assert c.readings == 0 and c.garbage == 25
    hints = [ln for ln in err.splitlines() if ln.startswith("hint:")]
    # once after 20 skipped lines, once at the end
    assert len(hints) == 2 and all("every one of the" in h and "baud" in h for h in hints)
    # A beacons file of other beacons.
    f = tmp_path / "other.txt"
    f.write_text("1:0:0:0:0:0:0:1 0 0 2\n1:0:0:0:0:0:0:2 3 0 2\n1:0:0:0:0:0:0:3 0 3 2\n")
    c, out, err = _run_on_pty(
        _listener_lines(LAB, repeat=1), ["--beacons", str(f)], until=lambda t: t.count("beacon 01:") >= 4
    )
    hints = [ln for ln in err.splitlines() if ln.startswith("hint:")]
    assert len(hints) == 1 and "none of the 4 beacons heard" in hints[0] and "01:5e:3c:3c:0a:00:00:b1" in hints[0]


def test_raw_echoes_every_line(tmp_path):
    lines = _listener_lines(dict(list(LAB.items())[:1]), repeat=1) + ["junk\x07line\r\n"]
    c, out, err = _run_on_pty(lines, ["--raw"], until=lambda t: "skipped line" in t)
    raw = [ln.split(" < ", 1)[1] for ln in out.splitlines() if " < " in ln]
    assert raw == [lines[0].strip(), "junk\\x07line"]


def _holder(path, how):
    """A child process holding the pty's slave `path`: plainly open, or flock'ed as pyserial's
    exclusive=True does. Returns the process once it holds it."""
    import subprocess
    import sys

    code = (
        "import fcntl, os, sys, time\n"
        "fd = os.open(sys.argv[1], os.O_RDWR | os.O_NOCTTY)\n"
        "if sys.argv[2] == 'flock': fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)\n"
        "print('held', flush=True)\n"
        "time.sleep(60)\n"
    )
    p = subprocess.Popen([sys.executable, "-c", code, path, how], stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "held"
    return p


@pytest.mark.parametrize("how", ["open", "flock"])
def test_refuses_a_line_another_process_holds(how, capsys):
    master, slave = os.openpty()
    path = os.ttyname(slave)
    os.close(slave)
    holder = _holder(path, how)
    try:
        argv = [path, "--duration", "1"] + (["--share"] if how == "flock" else [])
        assert cricket.main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and f"{path} is held by another process" in err[0], err
        if how == "open":
            assert f"pid {holder.pid}" in err[0]
    finally:
        holder.kill()
        holder.wait()
        os.close(master)


def test_holds_the_line_against_a_second_console(capsys):
    master, slave = os.openpty()
    path = os.ttyname(slave)
    os.close(slave)
    out, err = io.StringIO(), _Signal()
    args = cricket.build_parser().parse_args([path])
    t = threading.Thread(target=lambda: cricket.run(args, out, err))
    t.start()
    try:
        assert err.opened.wait(10), "console did not open the pty"
        # A second console in this process (so /proc shows no other holder): the lock refuses it.
        assert cricket.main([path, "--share", "--duration", "1"]) == 2
        line = capsys.readouterr().err.strip().splitlines()
        assert len(line) == 1 and "held by another process" in line[0], line
    finally:
        os.close(master)
        t.join(10)
    assert not t.is_alive()
