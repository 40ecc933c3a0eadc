# SPDX-License-Identifier: MIT
"""dynaqpc-viewer: the robot's pose from telemetry frames, drawn live over the arena.

Listens on the bus (the simulator's virtual bus by default, or a USB-CAN adapter on the real
robot's bus) for the pose frame (TLM_POSE by default; GPS_POSE shows the simulator's true pose),
decodes it with the DBC and draws the robot and its trail. The pose signals are found by name
(X, Y, Heading, Fix...) and converted by their DBC unit (mm or m; deg or rad). The fix is named
from the DBC's value table; a pose without a fix (TLM_POSE FixState LOST, GPS_POSE Fix NONE) is
not drawn, and when the asked-for frame never comes the viewer says which frames did.
"""

from __future__ import annotations

import argparse
import collections
import math
import sys
import time
from dataclasses import dataclass
from typing import Optional

from .common import (ToolArgumentParser, ToolError, add_bus_arguments, bus_from_args, default_dbc_path, float_in,
                     int_in, load_dbc, run_main)

_LENGTH_SCALE = {"mm": 1e-3, "cm": 1e-2, "m": 1.0}
_ANGLE_SCALE = {"deg": math.pi / 180.0, "rad": 1.0, "mrad": 1e-3, "": math.pi / 180.0}


@dataclass
class Pose:
    t: float
    x: float        # m
    y: float        # m
    heading: float  # rad, counter-clockwise from +x
    fix: Optional[int]
    fix_name: Optional[str] = None  # from the DBC's value table, when it has one
    #: False when the fix says there is no pose (LOST, NONE): its x, y mean nothing.
    usable: bool = True

#: Fix values that mean "no pose" (TLM_POSE FixState, GPS_POSE Fix).
NO_POSE = ("LOST", "NONE")


def _find_signal(message, wanted, override):
    names = {s.name: s for s in message.signals}
    if override:
        if override not in names:
            raise ToolError(f"{message.name} has no signal {override} (has {', '.join(names)})")
        return names[override]
    for s in message.signals:
        if wanted(s.name.lower()):
            return s
    return None


class PoseDecoder:
    """Turns the pose frame into Pose; other frames give None. Ids come from the DBC only."""

    def __init__(self, db, frame: str = "TLM_POSE", x: Optional[str] = None, y: Optional[str] = None,
                 heading: Optional[str] = None, fix: Optional[str] = None):
        try:
            self.message = db.get_message_by_name(frame)
        except KeyError:
            raise ToolError(f"no frame {frame} in the DBC (frames: "
                            f"{', '.join(m.name for m in db.messages)}); pass --frame") from None
        self.db = db
        m = self.message
        self.x = _find_signal(m, lambda n: n in ("x", "x_mm", "x_m", "pos_x", "posx"), x)
        self.y = _find_signal(m, lambda n: n in ("y", "y_mm", "y_m", "pos_y", "posy"), y)
        self.heading = _find_signal(m, lambda n: "heading" in n or n in ("theta", "yaw"), heading)
        self.fix = _find_signal(m, lambda n: "fix" in n, fix)
        if self.x is None or self.y is None:
            raise ToolError(f"{m.name}: no x/y signals found (has {', '.join(s.name for s in m.signals)}); "
                            "pass --x-signal/--y-signal")
        self._xs = self._scale(self.x, _LENGTH_SCALE, "length")
        self._ys = self._scale(self.y, _LENGTH_SCALE, "length")
        self._hs = self._scale(self.heading, _ANGLE_SCALE, "angle") if self.heading else 0.0

    @staticmethod
    def _scale(sig, table, what) -> float:
        unit = (sig.unit or "").strip().lower()
        if unit not in table:
            raise ToolError(f"signal {sig.name}: unknown {what} unit {sig.unit!r}")
        return table[unit]

    def decode(self, msg) -> Optional[Pose]:
        m = self.message
        if msg.arbitration_id != m.frame_id or bool(msg.is_extended_id) != bool(m.is_extended_frame):
            return None
        if msg.is_remote_frame or msg.is_error_frame:
            return None
        try:
            v = m.decode(bytes(msg.data), decode_choices=False)
        except Exception:
            return None  # the monitor reports undecodable frames; the viewer just skips them
        heading = float(v[self.heading.name]) * self._hs if self.heading else 0.0
        fix = int(v[self.fix.name]) if self.fix else None
        name = self.fix_name(fix)
        return Pose(float(msg.timestamp), float(v[self.x.name]) * self._xs, float(v[self.y.name]) * self._ys,
                    heading, fix, name, name not in NO_POSE)

    def fix_name(self, fix: Optional[int]) -> Optional[str]:
        if fix is None or self.fix is None or not self.fix.choices:
            return None
        return str(self.fix.choices.get(fix, fix))

    def usable(self, values) -> bool:
        """Decoded values (decode_choices=False) of the pose frame carry a pose."""
        return self.fix is None or self.fix_name(int(values[self.fix.name])) not in NO_POSE


class PoseView:
    """The figure: arena, trail, robot arrow."""

    def __init__(self, arena=None, trail: int = 5000):
        import matplotlib.pyplot as plt

        from .arena import draw_arena

        self.fig, self.ax = plt.subplots(figsize=(7, 7))
        if arena is not None:
            draw_arena(self.ax, arena)
        else:
            self.ax.set_aspect("equal")
            self.ax.set_xlabel("x (m)")
            self.ax.set_ylabel("y (m)")
        self.has_arena = arena is not None
        self.trail = collections.deque(maxlen=trail)
        (self.trail_line,) = self.ax.plot([], [], "-", color="tab:blue", linewidth=1, alpha=0.7)
        self.arrow = None
        self.title = self.ax.set_title("waiting for pose frames")
        self.poses = 0
        self.skipped = 0

    def add(self, pose: Pose) -> None:
        if not pose.usable:
            self.skipped += 1  # no fix: its x, y (often 0, 0) are not where the robot is
            return
        self.poses += 1
        self.trail.append((pose.x, pose.y))
        self.last = pose

    def redraw(self) -> None:
        if not self.trail:
            return
        xs, ys = zip(*self.trail)
        self.trail_line.set_data(xs, ys)
        p = self.last
        if self.arrow is not None:
            self.arrow.remove()
        self.arrow = self.ax.arrow(p.x, p.y, 0.25 * math.cos(p.heading), 0.25 * math.sin(p.heading),
                                   width=0.04, color="tab:red", length_includes_head=True)
        fix = "" if p.fix is None else f"  fix {p.fix_name or p.fix}"
        self.title.set_text(f"x {p.x:.3f} m  y {p.y:.3f} m  heading {math.degrees(p.heading):.1f} deg"
                            f"{fix}  ({self.poses} poses)")
        if not self.has_arena:
            self.ax.relim()
            self.ax.autoscale_view()


def build_parser() -> argparse.ArgumentParser:
    p = ToolArgumentParser(prog="dynaqpc-viewer", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    add_bus_arguments(p)
    p.add_argument("--dbc", default=default_dbc_path(), help="CAN database (default %(default)s)")
    p.add_argument("--frame", default="TLM_POSE", help="pose frame name in the DBC (default %(default)s)")
    p.add_argument("--x-signal"), p.add_argument("--y-signal")
    p.add_argument("--heading-signal"), p.add_argument("--fix-signal")
    p.add_argument("--arena", metavar="JSON", help="arena file written by the simulator")
    p.add_argument("--replay", metavar="FILE", help="read a recording (.mcap, .asc, .blf) instead of a bus")
    p.add_argument("--headless-png", metavar="FILE", help="no window: render to FILE at the end")
    p.add_argument("--duration", type=float_in(0, lo_open=True), default=None, help="stop after S seconds")
    p.add_argument("--count", type=int_in(1), default=None, help="stop after N pose frames")
    return p


def run(args) -> PoseView:
    import matplotlib

    if args.headless_png:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .arena import load_arena

    decoder = PoseDecoder(load_dbc(args.dbc), args.frame, args.x_signal, args.y_signal,
                          args.heading_signal, args.fix_signal)
    view = PoseView(load_arena(args.arena) if args.arena else None)
    if not args.headless_png:
        plt.ion()
        plt.show(block=False)
    start = time.monotonic()
    last_draw = 0.0

    def done() -> bool:
        return ((args.count is not None and view.poses >= args.count) or
                (args.duration is not None and time.monotonic() - start >= args.duration))

    bus = None
    seen = set()
    try:
        if args.replay:
            from .canlog import read_log

            for msg in read_log(args.replay):
                seen.add(msg.arbitration_id)
                pose = decoder.decode(msg)
                if pose is not None:
                    view.add(pose)
                if done():
                    break
        else:
            bus = bus_from_args(args)
            while not done():
                msg = bus.recv(timeout=0.05)
                if msg is not None:
                    seen.add(msg.arbitration_id)
                pose = decoder.decode(msg) if msg is not None else None
                if pose is not None:
                    view.add(pose)
                now = time.monotonic()
                if not args.headless_png and now - last_draw > 0.1:
                    last_draw = now
                    view.redraw()
                    plt.pause(0.001)
                    if not plt.fignum_exists(view.fig.number):
                        break  # window closed
    except KeyboardInterrupt:
        pass
    finally:
        if bus is not None:
            bus.shutdown()
    view.redraw()
    skipped = f", {view.skipped} without a fix not drawn" if view.skipped else ""
    if view.poses == 0 and view.skipped == 0:
        m = decoder.message
        others = sorted({(msg.name if msg else f"0x{i:03X}") for i in seen if i != m.frame_id
                         for msg in [_by_id(decoder.db, i)]})
        hint = (f"frames seen: {', '.join(others)}" if others else "no frames at all")
        print(f"warning: no {m.name} frame {'in the recording' if args.replay else 'on the bus'} ({hint}); "
              f"the scenario may not send {m.name} (GPS_POSE: only a robot with a GPS), or pass --frame",
              file=sys.stderr)
    if args.headless_png:
        try:
            view.fig.savefig(args.headless_png, dpi=100)
        except OSError as e:
            raise ToolError(f"cannot write {args.headless_png}: {e.strerror or e}") from None
        print(f"{view.poses} poses{skipped}; wrote {args.headless_png}")
    else:
        print(f"{view.poses} poses{skipped}")
    return view


def _by_id(db, frame_id: int):
    try:
        return db.get_message_by_frame_id(frame_id)
    except KeyError:
        return None


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    return run_main(lambda: (run(args), 0)[1])


if __name__ == "__main__":
    sys.exit(main())
