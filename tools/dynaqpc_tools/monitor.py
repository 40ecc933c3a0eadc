# SPDX-License-Identifier: MIT
"""dynaqpc-monitor: CAN bus monitor and logger.

Decodes every frame with the DBC (values with a value table by name: Mode=SAFE_STOP), keeps
per-frame rates, counts gaps in the rolling counters (signals named ``Counter`` or
``*_COUNTER``), shows the last decoded values, optionally records (MCAP for Foxglove, with
decoded signals and the pose; or python-can's ASC/BLF), and prints a summary at the end, be it
reached by the source's end, --count, --duration, Ctrl-C, SIGTERM or SIGHUP (the recording is
finished in every case). A frame of the wrong length, a failed Crc or Reserved bits not 0 is
undecodable: counted, named on stderr, and --print shows no values for it.
``--speed X`` stamps a recording of a simulation run X times faster in robot time.
``--foxglove [PORT]`` serves the bus live to Foxglove over WebSocket (foxglove-sdk, loopback by
default; dynaqpc_tools/foxglove_live.py lists the topics; docs/foxglove-layout.json lays them out).
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import math
import os
import signal
import sys
import threading
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple

from .bus_decode import decode_frame, e2e_ok
from .bus_listen import frames, listener_parser
from .common import (
    ToolError,
    float_in,
    int_in,
    load_dbc,
    run_main,
)

#: Frames kept per id for the recent rate.
RATE_WINDOW = 50


def is_counter_signal(name: str) -> bool:
    n = name.lower()
    return n == "counter" or n.endswith("_counter")


@dataclass
class FrameStats:
    """What the monitor knows about one arbitration id."""

    arbitration_id: int
    is_extended_id: bool
    name: str
    count: int = 0
    first_t: float = math.nan
    last_t: float = math.nan
    recent: collections.deque = field(default_factory=lambda: collections.deque(maxlen=RATE_WINDOW))
    values: Dict[str, object] = field(default_factory=dict)
    raw: bytes = b""
    decode_errors: int = 0
    counter_signal: Optional[str] = None
    counter_modulo: int = 0
    counter_prev: Optional[int] = None
    missing: int = 0  # frames lost, from counter gaps
    gap_events: int = 0  # how many times the counter jumped
    repeats: int = 0  # counter unchanged (duplicate or stuck sender)

    def rate_hz(self) -> float:
        """Rate over the last RATE_WINDOW frames."""
        if len(self.recent) < 2 or self.recent[-1] <= self.recent[0]:
            return math.nan
        return (len(self.recent) - 1) / (self.recent[-1] - self.recent[0])

    def mean_rate_hz(self) -> float:
        if self.count < 2 or not self.last_t > self.first_t:
            return math.nan
        return (self.count - 1) / (self.last_t - self.first_t)


class StatusWatch:
    """The firmware's health from FW_STATUS: modes and error flags that are not fine, and silence
    (no FW_STATUS for more than 3 of its cycles, or none at all). Named from the DBC."""

    BAD_MODES = ("SAFE_STOP", "FAULT")

    def __init__(self, db):
        try:
            self.message = db.get_message_by_name("FW_STATUS")
        except KeyError:
            self.message = None
        cycle = getattr(self.message, "cycle_time", None) or 1000
        self.max_gap_s = 3 * cycle / 1000.0
        self.frames = 0
        self.last_t = None
        self.end_t = None
        self.problems: Dict[str, int] = {}  # what was wrong -> FW_STATUS frames that said so
        self.silences = 0

    def feed(self, message, values, t: float) -> List[str]:
        self.end_t = t if self.end_t is None else max(self.end_t, t)
        if message is not self.message:
            return []
        events = []
        self.frames += 1
        if self.last_t is not None and t - self.last_t > self.max_gap_s:
            self.silences += 1
            events.append(f"FW_STATUS: silent for {t - self.last_t:.1f} s")
        self.last_t = t
        bad = []
        mode = values.get("Mode")
        if mode is not None and str(getattr(mode, "name", mode)) in self.BAD_MODES:
            bad.append(f"Mode={getattr(mode, 'name', mode)}")
        bad += [k for k, v in values.items() if k.startswith("Err") and int(getattr(v, "value", v))]
        for b in bad:
            if b not in self.problems:
                events.append(f"FW_STATUS: {b}")
            self.problems[b] = self.problems.get(b, 0) + 1
        return events

    def verdict(self) -> List[str]:
        """What --fail-on-status fails on; empty when the firmware was heard and fine."""
        if self.message is None:
            return ["the DBC has no FW_STATUS"]
        if self.frames == 0:
            return ["no FW_STATUS heard: the firmware is silent"]
        out = [f"{k} in {n} FW_STATUS frame(s)" for k, n in self.problems.items()]
        if self.silences:
            out.append(f"FW_STATUS silent {self.silences} time(s) for more than {self.max_gap_s:g} s")
        if self.end_t is not None and self.end_t - self.last_t > self.max_gap_s:
            out.append(f"FW_STATUS silent for the last {self.end_t - self.last_t:.1f} s")
        return out


class Monitor:
    """Feeds python-can messages through the DBC; holds per-id statistics. No I/O."""

    def __init__(self, db):
        self.db = db
        self.status = StatusWatch(db)
        self.stats: Dict[Tuple[int, bool], FrameStats] = {}
        self.error_frames = 0
        self.remote_frames = 0
        self.total = 0
        self.decoded = False  # the last frame fed decoded (a DBC frame that passed its checks)
        self._messages = {}
        for m in db.messages:
            self._messages[(m.frame_id, bool(m.is_extended_frame))] = m

    def _stats_for(self, msg) -> FrameStats:
        key = (msg.arbitration_id, bool(msg.is_extended_id))
        st = self.stats.get(key)
        if st is None:
            m = self._messages.get(key)
            st = FrameStats(msg.arbitration_id, bool(msg.is_extended_id), m.name if m else "?")
            if m is not None:
                for s in m.signals:
                    if is_counter_signal(s.name):
                        st.counter_signal = s.name
                        st.counter_modulo = 1 << s.length
                        break
            self.stats[key] = st
        return st

    def feed(self, msg) -> List[str]:
        """Accounts one message; returns the events it caused (counter gaps, decode errors).
        `decoded` says afterwards whether it was a DBC frame that decoded and passed its checks."""
        events = []
        self.decoded = False
        self.total += 1
        if msg.is_error_frame:
            self.error_frames += 1
            return ["error frame"]
        st = self._stats_for(msg)
        st.count += 1
        t = float(msg.timestamp)
        if st.count == 1:
            st.first_t = t
        st.last_t = t
        st.recent.append(t)
        st.raw = bytes(msg.data)
        if msg.is_remote_frame:
            self.remote_frames += 1
            return events
        m = self._messages.get((msg.arbitration_id, bool(msg.is_extended_id)))
        if m is None:
            return events
        try:
            values = decode_frame(m, msg.data, decode_choices=True)  # value tables by name
        except Exception as e:  # a wrong length (longer or shorter than the DBC's) too
            st.decode_errors += 1
            return [f"{m.name}: cannot decode {bytes(msg.data).hex()}: {e}"]
        if not e2e_ok(m, msg.data):
            st.decode_errors += 1  # noise that decodes: its end-to-end Crc fails
            return [f"{m.name}: Crc fails on {bytes(msg.data).hex()}"]
        st.values = values
        self.decoded = True
        events += self.status.feed(m, values, t)
        if st.counter_signal is not None and st.counter_signal in values:
            c = int(values[st.counter_signal])
            if st.counter_prev is not None:
                lost = (c - st.counter_prev - 1) % st.counter_modulo
                if lost == st.counter_modulo - 1:
                    st.repeats += 1
                    events.append(f"{m.name}: counter repeated {c}")
                elif lost > 0:
                    st.missing += lost
                    st.gap_events += 1
                    events.append(f"{m.name}: counter {st.counter_prev} -> {c}: {lost} frame(s) lost")
            st.counter_prev = c
        return events

    @property
    def frames_missing(self) -> int:
        return sum(s.missing for s in self.stats.values())

    def _sorted(self) -> List[FrameStats]:
        return sorted(self.stats.values(), key=lambda s: (s.is_extended_id, s.arbitration_id))

    @staticmethod
    def _id_text(st: FrameStats) -> str:
        return f"{st.arbitration_id:08X}" if st.is_extended_id else f"{st.arbitration_id:03X}"

    def table_lines(self) -> List[str]:
        """The live view: one line per id with rate, counter state and last values."""
        lines = [f"{'id':>8} {'name':<16} {'count':>8} {'Hz':>7} {'lost':>5}  last values"]
        for st in self._sorted():
            if st.values:
                vals = " ".join(f"{k}={_fmt(v)}" for k, v in st.values.items())
            else:
                vals = st.raw.hex(" ")
            lines.append(
                f"{self._id_text(st):>8} {st.name:<16} {st.count:>8} {_fmt(st.rate_hz()):>7} "
                f"{st.missing if st.counter_signal else '-':>5}  {vals}"
            )
        return lines

    def summary_lines(self) -> List[str]:
        lines = [
            f"{self.total} frames, {len(self.stats)} ids, {self.error_frames} error frames, "
            f"{self.frames_missing} frames lost (counter gaps)"
        ]
        lines.append(
            f"{'id':>8} {'name':<16} {'frames':>8} {'mean Hz':>8} {'lost':>5} {'gaps':>5} "
            f"{'repeats':>7} {'undecodable':>11}"
        )
        for st in self._sorted():
            counter = st.counter_signal is not None
            lines.append(
                f"{self._id_text(st):>8} {st.name:<16} {st.count:>8} {_fmt(st.mean_rate_hz()):>8} "
                f"{st.missing if counter else '-':>5} {st.gap_events if counter else '-':>5} "
                f"{st.repeats if counter else '-':>7} {st.decode_errors:>11}"
            )
        return lines


def print_frame(mon: Monitor, msg, out) -> None:
    """--print's line for the frame just fed: its decoded values; for an unknown id, remote or
    error frame, its bytes; for one that did not decode or failed its checks, no line (the event
    on stderr says why), never the values of an earlier frame."""
    key = (msg.arbitration_id, bool(msg.is_extended_id))
    st = mon.stats.get(key)
    if st is None:  # an error frame
        return
    if key in mon._messages and not msg.is_remote_frame:
        if not mon.decoded:
            return
        vals = " ".join(f"{k}={_fmt(v)}" for k, v in st.values.items())
    else:
        vals = ("remote " if msg.is_remote_frame else "") + bytes(msg.data).hex(" ")
    print(f"{msg.timestamp:.6f} {mon._id_text(st)} {st.name} {vals}", file=out)


def _fmt(v) -> str:
    if hasattr(v, "name") and hasattr(v, "value"):  # cantools' NamedSignalValue: the DBC's name
        return str(v.name)
    if isinstance(v, float):
        if math.isnan(v):
            return "-"
        return f"{v:.1f}" if abs(v) >= 100 else f"{v:.3g}"
    return str(v)


@contextlib.contextmanager
def stop_on_signals():
    """Yields a list that SIGTERM and SIGHUP (`kill`, `timeout`, the terminal closed) append their
    name to, for the loop to stop at its next frame or read timeout as on Ctrl-C: the recording
    finished and the summary printed. A flag, not an exception, so that no recording is cut in
    the middle of writing a message. In the main thread only (elsewhere, a test's thread,
    signals are left as they are)."""
    stopped: List[str] = []
    if threading.current_thread() is not threading.main_thread():
        yield stopped
        return

    def handler(signum, _frame):
        stopped.append(signal.Signals(signum).name)

    previous = {sig: signal.signal(sig, handler) for sig in (signal.SIGTERM, signal.SIGHUP)}
    try:
        yield stopped
    finally:
        for sig, h in previous.items():
            signal.signal(sig, h)


def build_parser() -> argparse.ArgumentParser:
    p = listener_parser("dynaqpc-monitor", __doc__, "frames")
    p.add_argument(
        "--log", metavar="FILE", help="also record: .mcap (Foxglove: decoded signals, pose, raw frames) or .asc/.blf"
    )
    p.add_argument("--arena", metavar="JSON", help="with --log x.mcap: draw this arena (simulator JSON) in it")
    p.add_argument(
        "--speed",
        type=float_in(0, 100000, lo_open=True),
        default=1.0,
        help="the simulation runs X times faster than real time: record in robot time (default 1)",
    )
    p.add_argument("--print", dest="print_frames", action="store_true", help="print every decoded frame")
    p.add_argument(
        "--refresh",
        type=float_in(0),
        default=1.0,
        help="live table period in seconds when stdout is a terminal (0: off)",
    )
    p.add_argument("--fail-on-gap", action="store_true", help="exit 1 when a counter gap was seen")
    p.add_argument(
        "--fail-on-status",
        action="store_true",
        help="exit 1 when FW_STATUS showed SAFE_STOP, FAULT or an error flag, or went silent",
    )
    p.add_argument(
        "--foxglove",
        nargs="?",
        const=8765,
        default=None,
        type=int_in(0, 65535),
        metavar="PORT",
        help="serve the bus live to Foxglove over WebSocket (foxglove-sdk) on PORT (default 8765; "
        "0: any free port): pose, /tf, rays, bumps, arena, state, every signal for Plot",
    )
    p.add_argument(
        "--foxglove-host",
        default="127.0.0.1",
        metavar="ADDR",
        help="address to serve on (default %(default)s: this machine only)",
    )
    p.add_argument(
        "--scenario",
        metavar="FILE",
        help="with --foxglove: a scenario file: its `ray` lines give the rays' angles, its `arena` "
        "and `encode` lines place the value map's cells (/robot/values)",
    )
    return p


def run(args, out=None) -> Monitor:
    out = out or sys.stdout
    from .arena import load_arena
    from .canlog import open_log

    db = load_dbc(args.dbc)
    mon = Monitor(db)
    if args.arena and not (args.log or "").lower().endswith(".mcap") and args.foxglove is None:
        raise ToolError("--arena: only with --log FILE.mcap or --foxglove")
    if args.scenario and args.foxglove is None:
        raise ToolError("--scenario: only with --foxglove")
    arena = load_arena(args.arena) if args.arena else None
    if args.log and args.replay and os.path.abspath(args.log) == os.path.abspath(args.replay):
        raise ToolError(f"--log {args.log}: that is the file being replayed")
    ray_angles, grid = None, None
    if args.scenario:
        from .bus_decode import scenario_ray_angles
        from .foxglove_live import scenario_grid

        grid = scenario_grid(args.scenario)
        ray_angles = scenario_ray_angles(args.scenario)
    logger = open_log(args.log, db, arena, args.speed) if args.log else None
    live_fg = None
    try:
        if args.foxglove is not None:
            from .foxglove_live import LiveFoxglove

            live_fg = LiveFoxglove(db, args.foxglove, args.foxglove_host, arena, ray_angles, grid=grid)
            print(f"dynaqpc-monitor: Foxglove on ws://{args.foxglove_host}:{live_fg.port}", file=sys.stderr, flush=True)
    except ToolError:
        if logger is not None:
            logger.stop()
        raise

    def listening() -> None:
        # From here on every frame is heard: a script that sends only after this line (before it
        # had to guess how long the imports take) misses none of them.
        print(f"dynaqpc-monitor: listening on {args.interface}:{args.channel}", file=sys.stderr, flush=True)

    source = frames(args, 0.2, listening)
    with stop_on_signals() as stopped:
        _loop(args, mon, source, logger, live_fg, out, stopped)
    print("\n".join(mon.summary_lines()), file=out)
    return mon


def _loop(args, mon: Monitor, source, logger, live_fg, out, stopped: List[str]) -> None:
    """Reads until the source ends, --count or --duration, Ctrl-C, or a signal in `stopped`
    (SIGTERM, SIGHUP); then finishes the recording and closes the bus and the Foxglove server,
    whatever ended it."""
    live = args.refresh > 0 and out.isatty() and not args.print_frames
    start = time.monotonic()
    next_refresh = start + args.refresh
    try:
        for msg in source:
            if stopped:
                print(f"dynaqpc-monitor: {stopped[0]}: stopping", file=sys.stderr, flush=True)
                break
            now = time.monotonic()
            if args.duration is not None and now - start >= args.duration:
                break
            if live_fg is not None:
                live_fg(msg)
            if msg is not None:
                if logger is not None:
                    logger(msg)
                for ev in mon.feed(msg):
                    print(f"{msg.timestamp:.6f} {ev}", file=sys.stderr)
                if args.print_frames:
                    print_frame(mon, msg, out)
                if args.count is not None and mon.total >= args.count:
                    break
            if live and now >= next_refresh:
                next_refresh = now + args.refresh
                out.write("\033[H\033[J" + "\n".join(mon.table_lines()) + "\n")
                out.flush()
    except KeyboardInterrupt:
        pass
    finally:
        if logger is not None:
            logger.stop()
        if live_fg is not None:
            live_fg.stop()
        source.close()  # a bus it opened is shut down


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)

    def body():
        mon = run(args)
        rc = 1 if args.fail_on_gap and mon.frames_missing > 0 else 0
        if args.fail_on_status:
            for why in mon.status.verdict():
                print(f"status: {why}")
                rc = 1
        return rc

    return run_main(body)


if __name__ == "__main__":
    sys.exit(main())
