# SPDX-License-Identifier: MIT
"""dynaqpc-cricket: a console for a Cricket v2 listener on a serial line.

Reads the listener's lines (115200 8N1, XON/XOFF) from a serial device or the simulator's pty,
parses them by key (``VR=2.0,ID=..,SP=..,DB=..,DR=..,TM=..,TS=..``; any field may be switched
off), prints the range to each beacon (DR, the ultrasound time of flight in us, times 343 m/s;
DB, the distance in cm, when DR is off) and, given the beacons' positions, a trilaterated x, y.
Garbage lines are reported and skipped. The stream ending (device unplugged, simulator closed)
ends the console cleanly.
"""

from __future__ import annotations

import argparse
import math
import re
import sys
import time
from dataclasses import dataclass, field
from typing import Dict, Iterable, List, Optional, Tuple

from .common import ToolError, run_main

SPEED_OF_SOUND_M_S = 343.0
#: Keys a Cricket v2 listener writes, in its fixed order.
KNOWN_KEYS = ("VR", "ID", "SP", "DB", "DR", "TM", "TS")
_KEY_RE = re.compile(r"^[A-Z][A-Z0-9]{0,7}$")
_ID_RE = re.compile(r"^[0-9A-Fa-f]{2}(?::[0-9A-Fa-f]{2})*$|^[0-9A-Fa-f]+$")
_NUM_RE = re.compile(r"^-?\d+(?:\.\d+)?$")


class CricketLineError(ValueError):
    """A line that is not a listener report."""


@dataclass
class CricketReading:
    fields: Dict[str, str]
    beacon: Optional[str]        # ID if present, else SP (the beacon's space name)
    range_m: Optional[float]     # from DR if present, else DB
    range_source: Optional[str]  # "DR" or "DB"

    @property
    def has_range(self) -> bool:
        return self.range_m is not None


def _number(key: str, value: str) -> float:
    if not _NUM_RE.match(value):
        raise CricketLineError(f"{key}={value!r} is not a number")
    v = float(value)
    if v < 0:
        raise CricketLineError(f"{key}={value} is negative")
    return v


def parse_line(line: str) -> CricketReading:
    """Parses one listener line. Raises CricketLineError saying what is wrong."""
    text = line.strip()
    if not text:
        raise CricketLineError("empty line")
    fields: Dict[str, str] = {}
    for part in text.split(","):
        if "=" not in part:
            raise CricketLineError(f"{part!r} is not KEY=VALUE")
        key, value = (s.strip() for s in part.split("=", 1))
        if not _KEY_RE.match(key):
            raise CricketLineError(f"bad key {key!r}")
        if key in fields:
            raise CricketLineError(f"key {key} twice")
        if not value or any(not (32 < ord(c) < 127) for c in value):
            raise CricketLineError(f"bad value for {key}: {value!r}")
        fields[key] = value
    if "VR" in fields:
        _number("VR", fields["VR"])
    if "ID" in fields and not _ID_RE.match(fields["ID"]):
        raise CricketLineError(f"ID={fields['ID']!r} is not hex bytes")
    range_m, source = None, None
    if "DR" in fields:
        range_m, source = _number("DR", fields["DR"]) * 1e-6 * SPEED_OF_SOUND_M_S, "DR"
    elif "DB" in fields:
        range_m, source = _number("DB", fields["DB"]) / 100.0, "DB"
    if "DB" in fields and source == "DR":
        _number("DB", fields["DB"])  # validate even when DR wins
    if not any(k in fields for k in KNOWN_KEYS):
        raise CricketLineError("no Cricket field (VR, ID, SP, DB, DR, TM, TS)")
    beacon = fields.get("ID") or fields.get("SP")
    return CricketReading(fields, beacon, range_m, source)


def load_beacons(path: str) -> Dict[str, Tuple[float, float, float]]:
    """Beacon positions: one ``id x y z`` line each (metres); blank lines and # comments skipped."""
    beacons = {}
    try:
        with open(path, encoding="utf-8") as f:
            lines = f.readlines()
    except OSError as e:
        raise ToolError(f"cannot read beacons file {path}: {e}") from e
    for n, line in enumerate(lines, 1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        parts = line.split()
        try:
            if len(parts) != 4:
                raise ValueError
            beacons[parts[0]] = (float(parts[1]), float(parts[2]), float(parts[3]))
        except ValueError:
            raise ToolError(f"{path}:{n}: want 'id x y z', got {line!r}") from None
    if not beacons:
        raise ToolError(f"{path}: no beacons")
    return beacons


def trilaterate(ranges: Dict[str, float], beacons: Dict[str, Tuple[float, float, float]],
                listener_z: float = 0.0) -> Optional[Tuple[float, float, float]]:
    """Least-squares x, y of the listener from slant ranges to >= 3 beacons not on one line.

    Returns (x, y, rms residual in m) or None. Subtracting the first sphere's equation from the
    others leaves a linear system in x, y; then a few Gauss-Newton steps on the true ranges.
    """
    import numpy as np

    pts, dists = [], []
    for bid, r in ranges.items():
        if bid in beacons:
            bx, by, bz = beacons[bid]
            dz = bz - listener_z
            pts.append((bx, by))
            dists.append(math.sqrt(max(r * r - dz * dz, 0.0)))  # horizontal distance
    if len(pts) < 3:
        return None
    p = np.array(pts, dtype=float)
    d = np.array(dists, dtype=float)
    a = 2.0 * (p[1:] - p[0])
    b = d[0] ** 2 - d[1:] ** 2 + np.sum(p[1:] ** 2, axis=1) - np.sum(p[0] ** 2)
    if np.linalg.matrix_rank(a) < 2:
        return None  # beacons on one line: two mirror solutions
    xy = np.linalg.lstsq(a, b, rcond=None)[0]
    for _ in range(10):
        diff = xy - p
        est = np.linalg.norm(diff, axis=1)
        est[est < 1e-9] = 1e-9
        jac = diff / est[:, None]
        step = np.linalg.lstsq(jac, d - est, rcond=None)[0]
        xy = xy + step
        if np.linalg.norm(step) < 1e-9:
            break
    resid = float(np.sqrt(np.mean((np.linalg.norm(xy - p, axis=1) - d) ** 2)))
    return float(xy[0]), float(xy[1]), resid


@dataclass
class Console:
    """The console's state: latest range per beacon, counters. Feed it lines; no I/O."""

    beacons: Optional[Dict[str, Tuple[float, float, float]]] = None
    listener_z: float = 0.0
    max_age_s: float = 5.0
    ranges: Dict[str, Tuple[float, float]] = field(default_factory=dict)  # beacon -> (range, t)
    lines: int = 0
    readings: int = 0
    garbage: int = 0
    fixes: int = 0

    def feed(self, line: str, now: float) -> List[str]:
        """Returns what to print for this line (garbage goes to the second element's caller)."""
        self.lines += 1
        try:
            r = parse_line(line)
        except CricketLineError:
            self.garbage += 1
            raise
        self.readings += 1
        if not r.has_range or r.beacon is None:
            return [f"listener: {','.join(f'{k}={v}' for k, v in r.fields.items())}"]
        self.ranges[r.beacon] = (r.range_m, now)
        detail = f"DR {r.fields['DR']} us" if r.range_source == "DR" else f"DB {r.fields['DB']} cm"
        out = [f"beacon {r.beacon:<24} {r.range_m:7.3f} m  ({detail})"]
        if self.beacons:
            fresh = {b: rng for b, (rng, t) in self.ranges.items() if now - t <= self.max_age_s}
            fix = trilaterate(fresh, self.beacons, self.listener_z)
            if fix is not None:
                self.fixes += 1
                out.append(f"fix x={fix[0]:.3f} m y={fix[1]:.3f} m  (rms residual {fix[2]:.3f} m, "
                           f"{len([b for b in fresh if b in self.beacons])} beacons)")
        return out


def read_lines(port) -> Iterable[Optional[bytes]]:
    """Lines from an open pyserial port (None when its read timeout passed without a whole line)
    until the stream ends: the device or the pty's writer went away and pyserial raises."""
    import serial

    pending = b""
    while True:
        try:
            chunk = port.readline()
        except (serial.SerialException, OSError):
            if pending:
                yield pending
            return
        pending += chunk
        if pending.endswith(b"\n") or len(pending) > 4096:  # a runaway line is garbage, not a hang
            yield pending
            pending = b""
        else:
            yield None


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="dynaqpc-cricket", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("device", nargs="?", default="/dev/ttyUSB0",
                   help="serial device or the simulator's pty path (default %(default)s)")
    p.add_argument("--baud", type=int, default=115200)
    p.add_argument("--no-xonxoff", action="store_true", help="disable XON/XOFF flow control")
    p.add_argument("--beacons", metavar="FILE", help="beacon positions, 'id x y z' per line (m)")
    p.add_argument("--listener-z", type=float, default=0.0, help="listener height (m)")
    p.add_argument("--max-age", type=float, default=5.0,
                   help="ranges older than this (s) are not used for a fix")
    p.add_argument("--count", type=int, default=None, help="stop after N lines")
    p.add_argument("--duration", type=float, default=None, help="stop after S seconds")
    return p


def run(args, out=None, err=None) -> Console:
    out, err = out or sys.stdout, err or sys.stderr
    import serial

    console = Console(load_beacons(args.beacons) if args.beacons else None, args.listener_z, args.max_age)
    try:
        port = serial.Serial(args.device, args.baud, bytesize=serial.EIGHTBITS, parity=serial.PARITY_NONE,
                             stopbits=serial.STOPBITS_ONE, xonxoff=not args.no_xonxoff, timeout=0.2)
    except (serial.SerialException, OSError) as e:
        raise ToolError(f"cannot open {args.device}: {e}") from e
    print(f"listening on {args.device}", file=err, flush=True)
    start = time.monotonic()
    try:
        for raw in read_lines(port):
            now = time.monotonic()
            if args.duration is not None and now - start >= args.duration:
                break
            if raw is None:
                continue
            text = raw.decode("ascii", errors="replace")
            try:
                for line in console.feed(text, now - start):
                    print(f"{now - start:9.3f} {line}", file=out, flush=True)
            except CricketLineError as e:
                print(f"{now - start:9.3f} skipped line {text.strip()[:60]!r}: {e}", file=err, flush=True)
            if args.count is not None and console.lines >= args.count:
                break
    except KeyboardInterrupt:
        pass
    finally:
        port.close()
    print(f"{console.lines} lines, {console.readings} readings, {console.garbage} skipped, "
          f"{console.fixes} fixes", file=out)
    return console


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    return run_main(lambda: (run(args), 0)[1])


if __name__ == "__main__":
    sys.exit(main())
