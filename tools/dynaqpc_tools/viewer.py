# SPDX-License-Identifier: MIT
"""dynaqpc-viewer: the robot's pose from telemetry frames, drawn live over the arena.

Listens on the bus (the simulator's virtual bus by default, or a USB-CAN adapter on the real
robot's bus) for the pose frame (TLM_POSE by default; GPS_POSE shows the simulator's true pose),
decodes it with the DBC and draws the robot and its trail. The pose signals are found by name
(X, Y, Heading, Fix...) and converted by their DBC unit (mm or m; deg or rad). The fix is named
from the DBC's value table; a pose without a fix (TLM_POSE FixState LOST, GPS_POSE Fix NONE) is
not drawn, and when the asked-for frame never comes the viewer says which frames did.

One trail per episode: a new trail starts when the firmware reports an episode's end
(TLM_EPISODE), when TLM_LEARN's episode number changes, or when the pose jumps farther than
--jump metres at once (the robot put down somewhere else), so no line is drawn across the room
from one episode to the next. The title reads episode, step (TLM_LEARN), mode (FW_STATUS) and
fix; the range sensors' latest readings are drawn as rays from the robot (IR_RANGES: left, front,
right at +45, 0, -45 degrees; SONAR_RANGES_A/B/C: sonar k at 11.25 + 22.5 k degrees, or the angles
of a scenario's `ray` lines with --scenario; a sonar scan once its three frames of one Counter are
in), and each bump (MOTOR_STATUS BumpFront/BumpRear
rising) as a red x where it happened. Frames the DBC does not define are simply not used.

Without a display (no DISPLAY or WAYLAND_DISPLAY, or a non-interactive matplotlib backend) it
says so in one line and exits 2, unless --png FILE asks for a picture instead.
"""

from __future__ import annotations

import argparse
import collections
import math
import os
import sys
import time
from typing import Optional

from .bus_decode import BusState, Pose, PoseDecoder, scenario_ray_angles
from .bus_listen import frames, listener_parser
from .common import (
    ToolError,
    float_in,
    int_in,
    load_dbc,
    run_tool,
)


class PoseView:
    """The figure: arena, trail, robot arrow."""

    def __init__(self, arena=None, trail: int = 5000, jump: float = 1.0):
        import matplotlib.pyplot as plt

        from .arena import draw_arena

        self.fig, self.ax = plt.subplots(figsize=(10, 6.5), layout="constrained")
        self.arena = arena
        if arena is not None:
            draw_arena(self.ax, arena)
        else:
            self.ax.set_aspect("equal")
            self.ax.set_xlabel("x (m)")
            self.ax.set_ylabel("y (m)")
        self.has_arena = arena is not None
        self.max_points = trail
        self.jump = jump
        #: One list of (x, y) per episode: a trail never joins two episodes.
        self.segments = collections.deque()
        self.points = 0
        self.lines = []
        self.arrow = None
        self.title = self.ax.set_title("waiting for pose frames", fontsize=9)
        self.poses = 0
        self.skipped = 0
        self.state: Optional[BusState] = None
        self.bumps = []  # where each bump happened
        self._break = True  # the next pose starts a trail
        self.ray_lines = []
        (self.bump_marks,) = self.ax.plot([], [], "x", color="tab:red", markersize=8, mew=2, linestyle="none")
        self._key()
        #: With keep_history (a replay), what the view showed after each pose, for show_upto():
        #: (pose, a trail starts here, bumps so far, episode, step, mode, rays)
        self.keep_history = False
        self.history = []
        self.bumps_all = None  # a replay's every bump, kept once show_upto() first scrubs back

    def _key(self) -> None:
        """A legend of every mark, beside the room; the suptitle says what is drawn."""
        from matplotlib.lines import Line2D

        from .arena import arena_key

        handles = [
            Line2D([], [], color="tab:blue", label="trail, this episode"),
            Line2D([], [], color="tab:cyan", alpha=0.7, label="trails, earlier episodes"),
            Line2D([], [], color="tab:red", marker=">", markersize=7, linewidth=2, label="the robot and its heading"),
            Line2D([], [], color="tab:orange", label="range ray: the reading\n(stops at the wall it meets)"),
            Line2D([], [], color="tab:orange", linestyle=":", label="range ray: no echo"),
            Line2D([], [], color="tab:red", marker="x", linestyle="", mew=2, label="a bump"),
        ]
        if self.arena is not None:
            handles += arena_key(self.arena)
        self.ax.legend(handles=handles, fontsize=7.5, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0)

    def set_source(self, text: str) -> None:
        """What the picture shows, above the readout: the frame, the room, a recording."""
        self.fig.suptitle(text, fontsize=10)

    def new_episode(self, late: bool = False) -> None:
        """The next pose starts a trail. `late`: known only from TLM_LEARN's episode number, which
        may come a pose after the episode's first: a trail just begun (by a jump) is kept."""
        if late and self.segments and len(self.segments[-1]) <= 1:
            return
        self._break = True

    def bump(self) -> None:
        if self.poses:
            self.bumps.append((self.last.x, self.last.y))

    def add(self, pose: Pose) -> None:
        if not pose.usable:
            self.skipped += 1  # no fix: its x, y (often 0, 0) are not where the robot is
            return
        if self.poses and math.hypot(pose.x - self.last.x, pose.y - self.last.y) > self.jump:
            self._break = True  # put down somewhere else
        if self._break or not self.segments:
            self.segments.append([])
            self._break = False
        if self.keep_history:
            st = self.state
            self.history.append(
                (
                    pose,
                    not self.segments[-1],
                    len(self.bumps),
                    st.episode if st else None,
                    st.step if st else None,
                    st.mode if st else None,
                    dict(st.rays) if st else {},
                )
            )
        self.segments[-1].append((pose.x, pose.y))
        self.points += 1
        while self.points > self.max_points and len(self.segments) > 1:
            self.points -= len(self.segments.popleft())
        self.poses += 1
        self.last = pose

    def show_upto(self, k: int) -> None:
        """A replay scrubbed back: the view as it was after pose k (0-based; clamped), trails,
        bumps, rays and readout included. Needs keep_history; redraws."""
        if not self.history:
            return
        k = max(0, min(k, len(self.history) - 1))
        self.segments = collections.deque()
        if self.bumps_all is None:
            self.bumps_all = list(self.bumps)
        for pose, starts, _, _, _, _, _ in self.history[: k + 1]:
            if starts or not self.segments:
                self.segments.append([])
            self.segments[-1].append((pose.x, pose.y))
        pose, _, bumps, episode, step, mode, rays = self.history[k]
        self.last = pose
        self.poses = k + 1
        self.bumps = self.bumps_all[:bumps]
        if self.state is not None:
            self.state.episode, self.state.step, self.state.mode, self.state.rays = episode, step, mode, rays
        if not self.bumps:
            self.bump_marks.set_data([], [])
        self.redraw()

    def readout(self) -> str:
        p = self.last
        parts = []
        st = self.state
        if st is not None and st.episode is not None:
            parts.append(f"episode {st.episode}")
        if st is not None and st.step is not None:
            parts.append(f"step {st.step}")
        if st is not None and st.mode is not None:
            parts.append(f"mode {st.mode}")
        if st is not None and st.trust is not None:
            parts.append(f"pose {st.trust}")
        if p.fix is not None:
            parts.append(f"fix {p.fix_name or p.fix}")
        pose = f"x {p.x:.3f} m  y {p.y:.3f} m  heading {math.degrees(p.heading):.1f} deg  ({self.poses} poses)"
        return ("  ".join(parts) + "\n" if parts else "") + pose

    def redraw(self) -> None:
        if not self.segments:
            return
        colors = ["tab:blue", "tab:cyan"]
        while len(self.lines) < len(self.segments):
            (ln,) = self.ax.plot([], [], "-", linewidth=1, alpha=0.7)
            self.lines.append(ln)
        for i, ln in enumerate(self.lines):
            if i < len(self.segments):
                xs, ys = zip(*self.segments[i])
                ln.set_data(xs, ys)
                # the episode in progress darker, earlier ones alternating light
                ln.set_color(
                    "tab:blue" if i == len(self.segments) - 1 else colors[1 - (len(self.segments) - 1 - i) % 2]
                )
            else:
                ln.set_data([], [])
        p = self.last
        if self.arrow is not None:
            self.arrow.remove()
        self.arrow = self.ax.arrow(
            p.x,
            p.y,
            0.25 * math.cos(p.heading),
            0.25 * math.sin(p.heading),
            width=0.04,
            color="tab:red",
            length_includes_head=True,
        )
        for ln in self.ray_lines:
            ln.remove()
        self.ray_lines = []
        if self.state is not None:
            for ang, r in self.state.rays.values():
                a = p.heading + ang
                length = r if r is not None else 0.15
                if self.arena is not None:  # a ray ends at what it meets, even if the reading says more
                    from .arena import ray_hit

                    length = ray_hit(self.arena, p.x, p.y, a, length)
                (ln,) = self.ax.plot(
                    [p.x, p.x + length * math.cos(a)],
                    [p.y, p.y + length * math.sin(a)],
                    "-" if r is not None else ":",
                    color="tab:orange",
                    linewidth=1,
                )
                self.ray_lines.append(ln)
        if self.bumps:
            bx, by = zip(*self.bumps)
            self.bump_marks.set_data(bx, by)
        self.title.set_text(self.readout())
        if not self.has_arena:
            self.ax.relim()
            self.ax.autoscale_view()


def no_display_reason() -> Optional[str]:
    """Why no window can be shown here, or None."""
    import matplotlib

    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        return "no display (DISPLAY and WAYLAND_DISPLAY are not set)"
    backend = matplotlib.get_backend().lower()
    if backend in ("agg", "pdf", "ps", "svg", "pgf", "cairo", "template") or backend.startswith(
        "module://matplotlib_inline"
    ):
        return f"no display (matplotlib backend {backend} draws no window)"
    return None


def build_parser() -> argparse.ArgumentParser:
    p = listener_parser("dynaqpc-viewer", __doc__, "pose frames")
    p.add_argument("--frame", default="TLM_POSE", help="pose frame name in the DBC (default %(default)s)")
    p.add_argument("--x-signal"), p.add_argument("--y-signal")
    p.add_argument("--heading-signal"), p.add_argument("--fix-signal")
    p.add_argument("--arena", metavar="JSON", help="arena file written by the simulator")
    p.add_argument(
        "--png",
        "--headless-png",
        dest="headless_png",
        metavar="FILE",
        help="no window: render to FILE at the end (what to do without a display)",
    )
    p.add_argument(
        "--scenario",
        metavar="FILE",
        help="a scenario file whose `ray` lines give the rays' angles "
        "(default: IR left/front/right at 45/0/-45 deg, sonar k at 11.25 + 22.5 k deg)",
    )
    p.add_argument(
        "--jump",
        type=float_in(0, lo_open=True),
        default=1.0,
        metavar="M",
        help="a pose this far (m) from the last starts a new trail (default %(default)s)",
    )
    p.add_argument(
        "--at",
        type=int_in(1),
        default=None,
        metavar="K",
        help="with --replay: show the run as it was at its K-th pose (a window scrubs with its slider)",
    )
    return p


def run(args) -> PoseView:
    import matplotlib

    if args.headless_png:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .arena import load_arena

    if not args.headless_png:
        why = no_display_reason()
        if why is not None:
            raise ToolError(f"{why}: cannot show the viewer; write a picture with --png FILE")
    db = load_dbc(args.dbc)
    decoder = PoseDecoder(db, args.frame, args.x_signal, args.y_signal, args.heading_signal, args.fix_signal)
    angles = None
    if args.scenario:
        angles = scenario_ray_angles(args.scenario)
    if args.at is not None and not args.replay:
        raise ToolError("--at: only with --replay (a live bus has no past to scrub)")
    view = PoseView(load_arena(args.arena) if args.arena else None, jump=args.jump)
    view.state = BusState(db, angles)
    room = ""
    if view.arena is not None:
        room = f" over {view.arena.get('name') or os.path.basename(args.arena)}"
    source = f"recording {os.path.basename(args.replay)}" if args.replay else "the bus"
    est = {"TLM_POSE": "the firmware's estimate", "GPS_POSE": "the simulator's true pose"}.get(args.frame, "")
    view.set_source(
        f"dynaqpc-viewer: the robot's pose from {args.frame}{' (' + est + ')' if est else ''}{room}, {source}"
    )
    view.keep_history = bool(args.replay)

    def feed(msg) -> None:
        seen.add(msg.arbitration_id)
        event = view.state.feed(msg)
        if event == "new episode":
            view.new_episode()
        elif event == "episode number changed":
            view.new_episode(late=True)
        elif event == "bump":
            view.bump()
        pose = decoder.decode(msg)
        if pose is not None:
            view.add(pose)

    if not args.headless_png and not args.replay:
        plt.ion()
        plt.show(block=False)
    start = time.monotonic()
    last_draw = 0.0

    def done() -> bool:
        return (args.count is not None and view.poses >= args.count) or (
            args.duration is not None and time.monotonic() - start >= args.duration
        )

    seen = set()
    source = frames(args, 0.05)
    try:
        for msg in source:
            if msg is not None:
                feed(msg)
            if done():
                break
            now = time.monotonic()
            if not args.headless_png and not args.replay and now - last_draw > 0.1:
                last_draw = now
                view.redraw()
                plt.pause(0.001)
                if not plt.fignum_exists(view.fig.number):
                    break  # window closed
    except KeyboardInterrupt:
        pass
    finally:
        source.close()  # a bus it opened is shut down
    view.redraw()
    if args.at is not None:
        view.show_upto(args.at - 1)
    skipped = f", {view.skipped} without a fix not drawn" if view.skipped else ""
    if len(view.segments) > 1:
        skipped += f", {len(view.segments)} trails (one per episode)"
    if view.bumps:
        skipped += f", {len(view.bumps)} bumps"
    if view.poses == 0 and view.skipped == 0:
        m = decoder.message
        others = sorted(
            {(msg.name if msg else f"0x{i:03X}") for i in seen if i != m.frame_id for msg in [_by_id(decoder.db, i)]}
        )
        hint = f"frames seen: {', '.join(others)}" if others else "no frames at all"
        print(
            f"warning: no {m.name} frame {'in the recording' if args.replay else 'on the bus'} ({hint}); "
            f"the scenario may not send {m.name} (GPS_POSE: only a robot with a GPS), or pass --frame",
            file=sys.stderr,
        )
    if args.headless_png:
        try:
            view.fig.savefig(args.headless_png, dpi=100)
        except OSError as e:
            raise ToolError(f"cannot write {args.headless_png}: {e.strerror or e}") from None
        print(f"{view.poses} poses{skipped}; wrote {args.headless_png}")
    else:
        print(f"{view.poses} poses{skipped}")
        if args.replay and view.history:
            _replay_window(view, plt, args.at)
    return view


def _replay_window(view: PoseView, plt, at: Optional[int]) -> None:
    """A replay stays open with a slider under the arena: dragging it shows the run as it was at
    that pose (trails, bumps, rays, readout); closing the window ends the viewer."""
    from matplotlib.widgets import Slider

    view.fig.subplots_adjust(bottom=0.14)
    axis = view.fig.add_axes([0.15, 0.03, 0.7, 0.03])
    n = len(view.history)
    slider = Slider(axis, "pose", 1, n, valinit=at if at is not None else n, valstep=1)
    slider.on_changed(lambda v: (view.show_upto(int(v) - 1), view.fig.canvas.draw_idle()))
    view.slider = slider  # kept alive with the figure
    plt.show(block=True)


def _by_id(db, frame_id: int):
    try:
        return db.get_message_by_frame_id(frame_id)
    except KeyError:
        return None


def main(argv=None) -> int:
    return run_tool(build_parser, run, argv)


if __name__ == "__main__":
    sys.exit(main())
