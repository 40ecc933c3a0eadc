# SPDX-License-Identifier: MIT
"""dynaqpc-cricket: a console for a Cricket v2 listener on a serial line.

Reads the listener's lines (115200 8N1, XON/XOFF) from a serial device or the simulator's pty,
parses them by key exactly as the firmware does (``VR=2.0,ID=1:5e:3c:3c:a:0:0:b3,SP=..,DB=..,
DR=..,TM=..,TS=..``; any field may be switched off; the format's one definition is the test
vectors in docs/cricket-lines.tsv, which this parser and the firmware's are both tested
against), prints the range to each beacon (DR, the ultrasound time of flight in us, times
343 m/s; DB, the distance in cm, when DR is off) and, given the beacons' positions, a
trilaterated x, y. Garbage lines are reported and skipped. The stream ending (device unplugged,
simulator closed) ends the console cleanly.

Beacon IDs are compared as the eight bytes they name, however a beacons file spells them
(`1:5e:3c:3c:a:0:0:b1`, `01:5E:3C:3C:0A:00:00:B1`, `01-5e-...`, `015e3c3c0a0000b1`). Hints on
stderr: when every line is skipped (not a listener, or the wrong baud rate), when none of the
beacons heard is in the beacons file, and when every fix is refused because the ranges disagree
(most often a wrong listener height: --listener-z, or a `listener_height H` line in the file;
unsaid, it is estimated from the ranges of beacons at one height).
--raw echoes every line as it arrives.

The console takes the line for itself: it refuses (one line, exit status 2) a device another
process holds — one that holds an exclusive lock on it (flock, as pyserial's ``exclusive=True``
takes; TIOCEXCL) or, on Linux, simply has it open (the firmware's host build reading its
Cricket pty, a terminal program): two readers of one tty each get some of its bytes, so the
console would read garbage and the other reader would lose lines. Once open it holds both
locks (flock and TIOCEXCL) so that a later opener is refused in turn. ``--share`` skips the
check of other openers (the locks are still taken).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from dataclasses import dataclass, field
from typing import Dict, Iterable, List, Optional, Tuple

from .common import ToolArgumentParser, ToolError, float_in, int_in, run_tool

SPEED_OF_SOUND_M_S = 343.0
#: Keys a Cricket v2 listener writes, in its fixed order (the firmware's CRICKET_FIELD_* bits).
KNOWN_KEYS = ("VR", "ID", "SP", "DB", "DR", "TM", "TS")
#: Characters kept of a space id (FW_CFG_CRICKET_SPACE_MAX).
SPACE_MAX = 16
#: Longest line the firmware keeps, in printable characters without the line end
#: (FW_CFG_CRICKET_LINE_MAX, firmware/drivers/include/drivers/drivers_config.h; cricket_feed
#: discards a longer line as overlong). tools/tests/test_cricket.py holds both to the header.
LINE_MAX = 128
#: Bytes without a line end after which read_lines gives up on the line (it is overlong).
RUNAWAY_BYTES = 4096
#: Characters of a line's text quoted in a reason; the rest is elided.
QUOTE_MAX = 40
#: Ranges beyond are refused (struct cricket_config max_range_mm default).
MAX_RANGE_M = 10.0
XON, XOFF = 0x11, 0x13
#: Skipped lines, none read, before the console hints (once) that this may not be a listener.
EARLY_HINT_LINES = 20


class CricketLineError(ValueError):
    """A line that is not a listener report."""


def _quote(text: str) -> str:
    """repr(text), elided past QUOTE_MAX characters: a reason stays one short line however long
    the garbage it quotes."""
    if len(text) <= QUOTE_MAX:
        return repr(text)
    return f"{text[:QUOTE_MAX]!r}... ({len(text)} characters)"


def parse_id(text: str) -> int:
    """A beacon ID as the listener prints it: eight hex bytes separated by ':', one or two digits
    each ("1:5e:3c:3c:a:0:0:b3"), first byte most significant (cricket_parse_id)."""
    parts = text.split(":")
    if len(parts) != 8:
        raise CricketLineError(f"ID={_quote(text)} is not eight ':'-separated hex bytes")
    value = 0
    for p in parts:
        if not 1 <= len(p) <= 2 or any(c not in "0123456789abcdefABCDEF" for c in p):
            raise CricketLineError(f"ID={_quote(text)}: byte {_quote(p)} is not one or two hex digits")
        value = (value << 8) | int(p, 16)
    return value


def id_text(value: int) -> str:
    return ":".join(f"{(value >> (8 * (7 - i))) & 0xFF:02x}" for i in range(8))


def _u32(key: str, text: str) -> int:
    if not 1 <= len(text) <= 10 or not all("0" <= c <= "9" for c in text) or int(text) > 0xFFFFFFFF:
        raise CricketLineError(f"{key}={_quote(text)} is not an unsigned 32-bit integer")
    return int(text)


def _decimal(key: str, text: str) -> float:
    """Unsigned decimal with an optional 1-6 digit fraction: "210", "210.5" (parse_decimal)."""
    whole, dot, frac = text.partition(".")
    try:
        w = _u32(key, whole)
        f = _u32(key, frac) if dot else 0
    except CricketLineError:
        raise CricketLineError(f"{key}={_quote(text)} is not an unsigned decimal") from None
    if dot and len(frac) > 6:
        raise CricketLineError(f"{key}={_quote(text)} has more than 6 decimals")
    return w + (f / 10 ** len(frac) if dot else 0.0)


@dataclass
class CricketReading:
    """One parsed line: the known fields present (cricket_line_t), and the range it gives."""

    present: Tuple[str, ...]  # known keys, in KNOWN_KEYS order
    values: Dict[str, object] = field(default_factory=dict)  # id int, sp str, db float, dr/tm/ts int
    raw: Dict[str, str] = field(default_factory=dict)  # every KEY=VALUE, as written

    @property
    def beacon_id(self) -> Optional[int]:
        return self.values.get("ID")

    @property
    def range_source(self) -> Optional[str]:
        return "DR" if "DR" in self.values else "DB" if "DB" in self.values else None

    @property
    def range_m(self) -> Optional[float]:
        if "DR" in self.values:
            return self.values["DR"] * 1e-6 * SPEED_OF_SOUND_M_S
        if "DB" in self.values:
            return self.values["DB"] / 100.0
        return None

    @property
    def has_range(self) -> bool:
        """A range the firmware would store: an ID, and DR or DB giving 0 < range <= 10 m."""
        r = self.range_m
        return self.beacon_id is not None and r is not None and 0.0 < r <= MAX_RANGE_M

    def describe(self) -> str:
        """The notation of docs/cricket-lines.tsv: "ok fields=ID,DR id=... dr=..."."""
        out = ["ok fields=" + ",".join(self.present)]
        for k in self.present:
            v = self.values[k]
            if k == "ID":
                out.append(f"id={v:016x}")
            elif k == "SP":
                out.append(f"sp={v}")
            elif k == "DB":
                out.append(f"db={v:g}")
            elif k in ("DR", "TM", "TS"):
                out.append(f"{k.lower()}={v}")
        return " ".join(out)


def parse_line(line: str) -> CricketReading:
    """Parses one line (its line end, if any, is dropped) as cricket_parse_line does: by key,
    case-sensitive, not trimmed; unknown keys ignored; a known key twice refused. Raises
    CricketLineError saying what is wrong."""
    text = line.rstrip("\r\n")
    if not text:
        raise CricketLineError("empty line")
    bad = [c for c in text if not 0x20 <= ord(c) <= 0x7E]
    if bad:
        raise CricketLineError(f"byte {ord(bad[0]):#04x} is not printable ASCII")
    present, values, raw = [], {}, {}
    for part in text.split(","):
        key, eq, value = part.partition("=")
        if not eq or not key:
            raise CricketLineError(f"{_quote(part)} is not KEY=VALUE")
        raw.setdefault(key, value)
        if key not in KNOWN_KEYS:
            continue
        if key in values:
            raise CricketLineError(f"key {key} twice")
        if key == "VR":
            if not value:
                raise CricketLineError("VR is empty")
            values[key] = value
        elif key == "ID":
            values[key] = parse_id(value)
        elif key == "SP":
            if len(value) > SPACE_MAX:
                raise CricketLineError(f"SP={_quote(value)} is longer than {SPACE_MAX}")
            values[key] = value
        elif key == "DB":
            values[key] = _decimal(key, value)
        else:
            values[key] = _u32(key, value)
        present.append(key)
    present.sort(key=KNOWN_KEYS.index)
    return CricketReading(tuple(present), values, raw)


def parse_beacon_id(text: str) -> int:
    """A beacon ID in a beacons file, however it is spelt: eight bytes of one or two hex digits
    separated by ':' or '-' (either case: `1:5e:3c:3c:a:0:0:b1`, `01-5E-3C-3C-0A-00-00-B1`), or
    sixteen hex digits (`015e3c3c0a0000b1`, optionally `0x`-prefixed). The same eight bytes are the
    same beacon. (A listener's line is read strictly, as the firmware reads it: parse_id.)"""
    t = text.strip()
    if t[:2].lower() == "0x":
        t = t[2:]
    if len(t) == 16 and all(c in "0123456789abcdefABCDEF" for c in t):
        return int(t, 16)
    return parse_id(t.replace("-", ":"))


def _beacon_key(text: str, where: str) -> int:
    try:
        return parse_beacon_id(text)
    except CricketLineError as e:
        raise ToolError(f"{where}: {e}") from None


def load_beacons(path: str) -> Tuple[Dict[int, Tuple[float, float, float]], Optional[float]]:
    """Beacon positions by ID (metres) and, when the file says, the listener's height. The file
    is a scenario (.scn: its `beacon ID X Y Z` lines and `cricket ... listener_height H`), the
    simulator's arena JSON (.json: "beacons": [{"id", "x", "y", "z"}]), or `ID X Y Z` lines.
    Blank lines and # comments are skipped."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except (OSError, UnicodeDecodeError) as e:
        raise ToolError(f"cannot read beacons file {path}: {getattr(e, 'strerror', None) or e}") from None
    beacons: Dict[int, Tuple[float, float, float]] = {}
    listener_z = None
    if path.endswith(".json"):
        try:
            items = json.loads(text).get("beacons", [])
            for i, b in enumerate(items):
                beacons[_beacon_key(str(b["id"]), f"{path}: beacons[{i}]")] = (
                    float(b["x"]),
                    float(b["y"]),
                    float(b["z"]),
                )
        except (ValueError, KeyError, TypeError, AttributeError) as e:
            raise ToolError(f"{path}: not an arena JSON with beacons ({e})") from None
    else:
        scenario = path.endswith(".scn")
        for n, line in enumerate(text.splitlines(), 1):
            words = line.split("#", 1)[0].split()
            if not words:
                continue
            if scenario:
                if words[0] == "cricket" and "listener_height" in words[:-1]:
                    listener_z = float(words[words.index("listener_height") + 1])
                if words[0] != "beacon":
                    continue
                words = words[1:]
            elif words[0] == "listener_height":
                try:
                    if len(words) != 2:
                        raise ValueError
                    listener_z = float(words[1])
                except ValueError:
                    raise ToolError(f"{path}:{n}: want 'listener_height H' (m), got {line.strip()!r}") from None
                continue
            try:
                if len(words) != 4:
                    raise ValueError
                pos = (float(words[1]), float(words[2]), float(words[3]))
            except ValueError:
                raise ToolError(f"{path}:{n}: want 'ID x y z', got {line.strip()!r}") from None
            beacons[_beacon_key(words[0], f"{path}:{n}")] = pos
    if not beacons:
        raise ToolError(f"{path}: no beacons")
    return beacons, listener_z


#: trilat_params of the firmware's Cricket driver (cricket_default_config), in metres.
MIN_SPREAD_M = 0.3
MAX_RESIDUAL_M = 0.06
GN_ITERATIONS = 8


class TrilatRefused(ValueError):
    """trilat_solve's refusals: 'invalid' (fewer than 3 ranges, a bad number, beacons too close to
    a line) or 'inconsistent' (the ranges disagree: residual above max_residual)."""

    def __init__(self, kind: str, detail: str):
        super().__init__(f"{kind}: {detail}")
        self.kind = kind


def trilat_solve(
    anchors,
    listener_z: float,
    min_spread: float = MIN_SPREAD_M,
    max_residual: float = MAX_RESIDUAL_M,
    iterations: int = GN_ITERATIONS,
):
    """The firmware's trilat_solve (firmware/drivers/src/trilat.c), step for step: the linear
    least-squares fix in centred coordinates, then Gauss-Newton on the slant ranges. `anchors` is
    a list of (x, y, z, range). Returns (x, y, rms residual); raises TrilatRefused. The shared
    vectors docs/cricket-fixes.tsv test both."""
    n = len(anchors)
    if n < 3:
        raise TrilatRefused("invalid", f"{n} ranges, a fix needs 3")
    for a in anchors:
        if not all(math.isfinite(v) for v in a) or a[3] < 0:
            raise TrilatRefused("invalid", f"bad anchor {a}")
    mx = sum(a[0] for a in anchors) / n
    my = sum(a[1] for a in anchors) / n
    sxx = sum((a[0] - mx) ** 2 for a in anchors) / n
    syy = sum((a[1] - my) ** 2 for a in anchors) / n
    sxy = sum((a[0] - mx) * (a[1] - my) for a in anchors) / n
    tr, det = sxx + syy, sxx * syy - sxy * sxy
    lambda_min = tr * 0.5 - math.sqrt(max(tr * tr * 0.25 - det, 0.0))
    if not lambda_min >= min_spread * min_spread or det <= 0:
        raise TrilatRefused("invalid", f"beacons within {math.sqrt(max(lambda_min, 0)):.3f} of a line")
    ks = []
    for x, y, z, r in anchors:
        u, v, dz = x - mx, y - my, z - listener_z
        ks.append(u * u + v * v - max(r * r - dz * dz, 0.0))
    k_mean = sum(ks) / n
    bu = sum((a[0] - mx) * (k - k_mean) for a, k in zip(anchors, ks)) / (2 * n)
    bv = sum((a[1] - my) * (k - k_mean) for a, k in zip(anchors, ks)) / (2 * n)
    x = mx + (syy * bu - sxy * bv) / det
    y = my + (sxx * bv - sxy * bu) / det
    for _ in range(iterations):
        jxx = jyy = jxy = gx = gy = 0.0
        for ax, ay, az, r in anchors:
            dx, dy, dz = x - ax, y - ay, listener_z - az
            rho = math.sqrt(dx * dx + dy * dy + dz * dz)
            if rho < 1e-9:
                continue
            jx, jy, e = dx / rho, dy / rho, rho - r
            jxx, jyy, jxy, gx, gy = jxx + jx * jx, jyy + jy * jy, jxy + jx * jy, gx + jx * e, gy + jy * e
        jdet = jxx * jyy - jxy * jxy
        if not jdet > 1e-9:
            break
        sx, sy = (jyy * gx - jxy * gy) / jdet, (jxx * gy - jxy * gx) / jdet
        x, y = x - sx, y - sy
        if abs(sx) + abs(sy) < 1e-9 * (1 + abs(x) + abs(y)):
            break
    resid = math.sqrt(sum((math.dist((x, y, listener_z), (ax, ay, az)) - r) ** 2 for ax, ay, az, r in anchors) / n)
    if resid > max_residual:
        raise TrilatRefused("inconsistent", f"rms residual {resid:.3f} above {max_residual:g}")
    return x, y, resid


def estimate_listener_z(anchors, max_tilt: float = 0.01) -> Optional[float]:
    """The listener's height from the ranges alone, when nobody said it: with beacons at one
    height zc (on a ceiling), d_i^2 - (x_i^2 + y_i^2) = -2 x x_i - 2 y y_i + K, linear in x, y and
    K = x^2 + y^2 + (z - zc)^2, so 3 or more beacons give (z - zc)^2, and the listener is below
    them. None: fewer than 3 beacons, beacons not at one height (within max_tilt), beacons on a
    line, or ranges that give no real height."""
    import numpy as np

    if len(anchors) < 3:
        return None
    zs = [a[2] for a in anchors]
    if max(zs) - min(zs) > max_tilt:
        return None
    a = np.array([[-2 * x, -2 * y, 1.0] for x, y, _, _ in anchors])
    b = np.array([r * r - x * x - y * y for x, y, _, r in anchors])
    try:
        sol, _, rank, _ = np.linalg.lstsq(a, b, rcond=None)
    except np.linalg.LinAlgError:
        return None
    if rank < 3:
        return None
    x, y, k = sol
    h2 = k - x * x - y * y
    if not h2 > 0:
        return None
    return float(sum(zs) / len(zs) - math.sqrt(h2))


def trilaterate(
    ranges: Dict[object, float], beacons: Dict[object, Tuple[float, float, float]], listener_z: float = 0.0
) -> Optional[Tuple[float, float, float]]:
    """The fix from the latest slant range to each known beacon (metres), as the firmware finds
    it; None when trilat_solve refuses."""
    anchors = [(*beacons[b], r) for b, r in ranges.items() if b in beacons]
    try:
        return trilat_solve(anchors, listener_z)
    except TrilatRefused:
        return None


@dataclass
class Console:
    """The console's state: latest range per beacon, counters. Feed it lines; no I/O."""

    beacons: Optional[Dict[int, Tuple[float, float, float]]] = None
    #: None: nobody said it; each fix estimates it from the ranges (estimate_listener_z)
    listener_z: Optional[float] = 0.0
    max_age_s: float = 3.0
    ranges: Dict[int, Tuple[float, float]] = field(default_factory=dict)  # beacon -> (range, t)
    lines: int = 0
    readings: int = 0
    garbage: int = 0  # skipped lines, the overlong ones among them
    overlong: int = 0  # lines over LINE_MAX, which the firmware discards
    fixes: int = 0
    #: beacons heard with a range, and fixes trilat_solve refused by kind (3+ known beacons fresh)
    heard: set = field(default_factory=set)
    refused: Dict[str, int] = field(default_factory=dict)
    last_residual: Optional[float] = None
    estimated_z: Optional[float] = None

    def hints(self, device: str = "the device", beacons_file: str = "the beacons file") -> List[str]:
        """What probably went wrong, when something did: every line skipped; none of the beacons
        heard in the beacons file; every fix refused for disagreeing ranges."""
        out = []
        if self.lines and not self.readings:
            out.append(
                f"every one of the {self.lines} lines was skipped: is {device} a Cricket listener, and at "
                f"its baud rate (115200 8N1; --baud)? Another process reading the same line (the firmware "
                f"on its pty) also leaves only fragments"
            )
        if self.beacons and self.heard and not self.heard & set(self.beacons):
            heard = ", ".join(id_text(b) for b in sorted(self.heard)[:5])
            known = ", ".join(id_text(b) for b in sorted(self.beacons)[:5])
            out.append(
                f"none of the {len(self.heard)} beacons heard ({heard}) is in {beacons_file} "
                f"({known}): no fix can be made"
            )
        elif self.beacons and not self.fixes and self.refused.get("inconsistent"):
            out.append(
                f"all {self.refused['inconsistent']} fixes were refused because the ranges disagree (rms "
                f"residual above {MAX_RESIDUAL_M * 100:g} cm): is the listener's height right? It is "
                + (
                    f"{self.listener_z:g} m"
                    if self.listener_z is not None
                    else f"estimated from the ranges ({self.estimated_z if self.estimated_z is not None else 0:g} m)"
                )
                + " (--listener-z, or a `listener_height H` line in the beacons file; a "
                "scenario file gives its own)"
            )
        return out

    def feed(self, line: str, now: float) -> List[str]:
        """Returns what to print for this line; a garbage line raises CricketLineError."""
        self.lines += 1
        text = line.rstrip("\r\n")
        kept = sum(1 for c in text if 0x20 <= ord(c) <= 0x7E)  # what cricket_feed would store
        if kept > LINE_MAX:
            self.garbage += 1
            self.overlong += 1
            raise CricketLineError(f"overlong: {kept} characters, the firmware discards a line over {LINE_MAX}")
        try:
            r = parse_line(line)
        except CricketLineError:
            self.garbage += 1
            raise
        self.readings += 1
        if not r.has_range:
            why = "" if r.range_m is None or r.beacon_id is None else f" (range {r.range_m:.3f} m refused)"
            return [f"listener: {','.join(f'{k}={v}' for k, v in r.raw.items())}{why}"]
        self.ranges[r.beacon_id] = (r.range_m, now)
        self.heard.add(r.beacon_id)
        detail = f"DR {r.values['DR']} us" if r.range_source == "DR" else f"DB {r.values['DB']:g} cm"
        out = [f"beacon {id_text(r.beacon_id)} {r.range_m:7.3f} m  ({detail})"]
        if self.beacons:
            if r.beacon_id not in self.beacons:
                out[0] += "  (not in the beacons file)"
            fresh = {b: rng for b, (rng, t) in self.ranges.items() if now - t <= self.max_age_s}
            anchors = [(*self.beacons[b], rng) for b, rng in fresh.items() if b in self.beacons]
            fix = None
            z = self.listener_z
            if len(anchors) >= 3 and z is None:
                self.estimated_z = estimate_listener_z(anchors)
                z = self.estimated_z if self.estimated_z is not None else 0.0
            if len(anchors) >= 3:
                try:
                    fix = trilat_solve(anchors, z)
                except TrilatRefused as e:
                    self.refused[e.kind] = self.refused.get(e.kind, 0) + 1
            if fix is not None:
                self.fixes += 1
                height = "" if self.listener_z is not None else f", listener height estimated {z:.3f} m"
                out.append(
                    f"fix x={fix[0]:.3f} m y={fix[1]:.3f} m  (rms residual {fix[2]:.3f} m, "
                    f"{len([b for b in fresh if b in self.beacons])} beacons{height})"
                )
        return out


def read_lines(port) -> Iterable[Optional[bytes]]:
    """Lines from an open pyserial port (None when its read timeout passed without a whole line)
    until the stream ends: the device or the pty's writer went away and pyserial raises."""
    import serial

    pending = b""
    runaway = False  # the rest of a line already given as overlong: dropped up to its end
    while True:
        try:
            chunk = port.readline()
        except (serial.SerialException, OSError):
            if pending:
                yield pending
            return
        if runaway:
            ends = [i for i in (chunk.find(b"\r"), chunk.find(b"\n")) if i >= 0]
            if not ends:
                yield None
                continue
            runaway, chunk = False, chunk[min(ends) :]
        pending += chunk
        if pending.endswith(b"\n"):
            yield pending
            pending = b""
        elif len(pending) > RUNAWAY_BYTES:  # no line end for long: not a hang
            cut = max(pending.rfind(b"\r"), pending.rfind(b"\n"))
            if len(pending) - cut - 1 > LINE_MAX:
                # The unfinished line is already overlong: given once, its rest dropped up to
                # its end rather than reported again piece by piece.
                yield pending
                runaway, pending = True, b""
            else:  # lines ended by CR alone: those are given, the unfinished one kept
                yield pending[: cut + 1]
                pending = pending[cut + 1 :]
        else:
            yield None


def holders(device: str) -> List[Tuple[int, str]]:
    """Other processes that have `device` open, as (pid, command name): Linux's /proc, best effort
    (processes whose fds cannot be read are not seen; elsewhere the list is empty)."""
    try:
        rdev = os.stat(device).st_rdev
    except OSError:
        return []
    if not rdev or not os.path.isdir("/proc/self/fd"):
        return []
    me = os.getpid()
    found = []
    for pid in os.listdir("/proc"):
        if not pid.isdigit() or int(pid) == me:
            continue
        fd_dir = f"/proc/{pid}/fd"
        try:
            fds = os.listdir(fd_dir)
        except OSError:
            continue
        for fd in fds:
            try:
                st = os.stat(f"{fd_dir}/{fd}")
            except OSError:
                continue
            if st.st_rdev == rdev and (st.st_mode & 0o170000) == 0o020000:  # the same char device
                try:
                    with open(f"/proc/{pid}/comm", encoding="utf-8", errors="replace") as f:
                        comm = f.read().strip()
                except OSError:
                    comm = "?"
                found.append((int(pid), comm))
                break
    return found


def open_exclusive(device: str, **kwargs):
    """The device opened through pyserial for this console alone (see the module's doc): a
    ToolError of one line when it cannot be opened or another process holds it."""
    import errno

    import serial

    if not kwargs.pop("share", False):
        held = holders(device)
        if held:
            who = ", ".join(f"pid {pid} ({comm})" for pid, comm in held)
            raise ToolError(
                f"{device} is held by another process ({who}): not reading it, "
                f"both readers would lose bytes (stop it, or pass --share)"
            )
    try:
        port = serial.Serial(device, exclusive=True, **kwargs)
    except (serial.SerialException, OSError) as e:
        text = str(e)
        if "exclusively lock" in text or getattr(e, "errno", None) == errno.EBUSY or "Device or resource busy" in text:
            raise ToolError(
                f"{device} is held by another process (it holds a lock on the line): "
                f"not reading it, both readers would lose bytes"
            ) from None
        raise ToolError(f"cannot open {device}: {e}") from None
    try:
        import fcntl
        import termios

        fcntl.ioctl(port.fileno(), termios.TIOCEXCL)
    except (ImportError, AttributeError, OSError):
        pass  # not a tty that knows TIOCEXCL: the flock still stands
    return port


def build_parser() -> argparse.ArgumentParser:
    p = ToolArgumentParser(
        prog="dynaqpc-cricket", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument(
        "device",
        nargs="?",
        default="/dev/ttyUSB0",
        help="serial device or the simulator's pty path (default %(default)s)",
    )
    p.add_argument("--baud", type=int_in(50, 4000000), default=115200)
    p.add_argument("--no-xonxoff", action="store_true", help="disable XON/XOFF flow control")
    p.add_argument(
        "--beacons", metavar="FILE", help="beacon positions: a scenario (.scn), an arena JSON, or 'ID x y z' lines (m)"
    )
    p.add_argument(
        "--listener-z",
        type=float_in(-100, 100),
        default=None,
        help="listener height (m; default: the scenario's or the file's, else estimated from the "
        "ranges of beacons at one height)",
    )
    p.add_argument(
        "--max-age",
        type=float_in(0, 3600, lo_open=True),
        default=3.0,
        help="ranges older than this (s) are not used for a fix (default 3, the firmware's)",
    )
    p.add_argument(
        "--raw", action="store_true", help="echo every line as it arrives ('<' and the line, unprintable bytes escaped)"
    )
    p.add_argument(
        "--share",
        action="store_true",
        help="read the device even if another process has it open (not if it holds a lock)",
    )
    p.add_argument("--count", type=int_in(1), default=None, help="stop after N lines")
    p.add_argument("--duration", type=float_in(0, lo_open=True), default=None, help="stop after S seconds")
    return p


def run(args, out=None, err=None) -> Console:
    out, err = out or sys.stdout, err or sys.stderr
    import serial

    beacons, z = load_beacons(args.beacons) if args.beacons else (None, None)
    # Unsaid (neither --listener-z nor the file): estimated from the ranges at each fix.
    listener_z = args.listener_z if args.listener_z is not None else z
    console = Console(beacons, listener_z, args.max_age)
    port = open_exclusive(
        args.device,
        baudrate=args.baud,
        bytesize=serial.EIGHTBITS,
        parity=serial.PARITY_NONE,
        stopbits=serial.STOPBITS_ONE,
        xonxoff=not args.no_xonxoff,
        timeout=0.2,
        share=args.share,
    )
    print(f"listening on {args.device}", file=err, flush=True)
    start = time.monotonic()
    try:
        for raw in read_lines(port):
            now = time.monotonic()
            if args.duration is not None and now - start >= args.duration:
                break
            if raw is None:
                continue
            # XON/XOFF are flow control, not data; CR, LF or CR LF end a line; empty lines are
            # skipped; any other byte outside printable ASCII makes its line garbage (cricket_feed).
            raw = raw.replace(bytes([XON]), b"").replace(bytes([XOFF]), b"")
            for piece in raw.replace(b"\r", b"\n").split(b"\n"):
                if not piece:
                    continue
                text = piece.decode("latin-1")
                if args.raw:
                    shown = "".join(c if 0x20 <= ord(c) <= 0x7E else f"\\x{ord(c):02x}" for c in text)
                    print(f"{now - start:9.3f} < {shown}", file=out, flush=True)
                try:
                    for line in console.feed(text, now - start):
                        print(f"{now - start:9.3f} {line}", file=out, flush=True)
                except CricketLineError as e:
                    print(f"{now - start:9.3f} skipped line {text.strip()[:60]!r}: {e}", file=err, flush=True)
                    if console.garbage == EARLY_HINT_LINES and not console.readings:
                        for h in console.hints(args.device):
                            print(f"hint: {h}", file=err, flush=True)
                if args.count is not None and console.lines >= args.count:
                    break
            if args.count is not None and console.lines >= args.count:
                break
    except KeyboardInterrupt:
        pass
    finally:
        port.close()
    print(
        f"{console.lines} lines, {console.readings} readings, {console.garbage} skipped, {console.fixes} fixes",
        file=out,
    )
    for h in console.hints(args.device, args.beacons or "the beacons file"):
        print(f"hint: {h}", file=err, flush=True)
    return console


def main(argv=None) -> int:
    return run_tool(build_parser, run, argv)


if __name__ == "__main__":
    sys.exit(main())
