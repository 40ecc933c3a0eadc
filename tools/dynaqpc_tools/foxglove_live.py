# SPDX-License-Identifier: MIT
"""The bus live in Foxglove: `dynaqpc-monitor --foxglove [PORT]`.

Every frame the monitor hears is turned into Foxglove's own message types (foxglove-sdk,
protobuf, the schemas Foxglove publishes) and served by the sdk's WebSocket server, on
127.0.0.1 unless --foxglove-host says otherwise. Open Foxglove → *Open connection* →
*Foxglove WebSocket* → ws://127.0.0.1:8765, and import the layout docs/foxglove-layout.json.

  /tf                    foxglove.FrameTransforms: arena → base_link (TLM_POSE, the firmware's
                         estimate), arena → true_base_link (GPS_POSE, the simulator's true pose)
  /robot/pose            foxglove.PoseInFrame, TLM_POSE in frame arena (FixState LOST left out)
  /robot/true_pose       foxglove.PoseInFrame, GPS_POSE (Fix NONE left out)
  /robot/rays            foxglove.SceneUpdate in frame base_link: one line per range sensor to
                         its reading (IR_RANGES, SONAR_RANGES_A/B/C: a whole scan, its three
                         frames of one Counter; no echo: a short grey stub),
                         the robot's body, and a label with episode, step and mode
  /robot/bumps           foxglove.SceneUpdate in frame arena: a red mark where each bump was
                         (MOTOR_STATUS BumpFront/BumpRear rising); cleared at each episode's end
  /robot/trail           foxglove.SceneUpdate in frame arena: the episode's path so far
  /arena                 foxglove.SceneUpdate: walls, obstacles, goal cells and beacons, from
                         --arena FILE.json (the simulator's `run --arena`), every 2 s
  /robot/values          foxglove.SceneUpdate in frame arena: the value map as it changes (TLM_VALUE:
                         V of the state each real step updated), one flat tile per cell coloured
                         from blue (lowest V seen) to red (highest), the cell's largest V over
                         headings and range codes; needs --scenario FILE (its arena and encode
                         lines place a state's cell)
  /robot/state           JSON: episode, step, mode, fix, episodes ended (Plot, State Transitions)
  /can/<MESSAGE>         JSON: every DBC message's signals decoded, numbers (Plot panel:
                         /can/TLM_SCHED.QueueLength), a value table's name as <signal>_name
"""

from __future__ import annotations

import json
import math
import subprocess
import time
from typing import Dict, Optional

from .agents import default_sim
from .bus_decode import NO_POSE, BusState, PoseDecoder, decode_frame
from .common import ToolError

#: The fixed topics (besides /can/<MESSAGE>, one per DBC message).
TOPICS = (
    "/tf",
    "/robot/pose",
    "/robot/true_pose",
    "/robot/rays",
    "/robot/bumps",
    "/robot/trail",
    "/arena",
    "/robot/state",
    "/robot/values",
)
FRAME = "arena"
BASE = "base_link"
TRUE_BASE = "true_base_link"
ARENA_PERIOD_S = 2.0
TRAIL_POINTS = 2000
#: Robot body radius (m) drawn in base_link; paper-sim's robot is 0.15 m.
BODY_R = 0.15
#: A reading with no echo is drawn this long (m), grey.
NO_ECHO_M = 0.1


def _import_sdk():
    try:
        import foxglove  # noqa: F401
    except ImportError as e:  # pragma: no cover - the venv has it
        raise ToolError(
            "Foxglove's message types (--foxglove, --log x.mcap) need foxglove-sdk: "
            f"pip install -r tools/requirements.txt ({e})"
        ) from None
    import foxglove
    from foxglove import channels as fc
    from foxglove import messages as fm

    return foxglove, fc, fm


def scenario_grid(path: str, sim: Optional[str] = None) -> dict:
    """The state grid of a scenario file: arena size (m), the `encode` line's bits (x, y, heading,
    sensor; the firmware packs them in that order from bit 0, space_pack) and every cell's edges
    along x and y (`x_edges`, `y_edges`). An equal grid's edges follow from the bits; a grid fitted
    to the room (`encode auto`) is asked of `dynaqpc-sim learned --grid`, which fits it by the
    firmware's own rule (`sim`: that binary; default: this checkout's build)."""
    grid = {"width": None, "height": None, "x": 5, "y": 5, "heading": 4, "sensor": None}
    code_bits, fitted = 0, False
    try:
        with open(path, encoding="utf-8") as f:
            for line in f:
                w = line.split("#", 1)[0].split()
                if not w:
                    continue
                if w[0] == "arena" and len(w) >= 3:
                    grid["width"], grid["height"] = float(w[1]), float(w[2])
                elif w[0] == "encode":
                    fitted = len(w) > 1 and w[1] == "auto"
                    rest = w[2:] if fitted else w[1:]
                    for k, v in zip(rest[0::2], rest[1::2]):
                        if k != "cell":
                            grid[k] = int(v)
                elif w[0] == "code_bit":
                    code_bits += 1
    except (OSError, ValueError) as e:
        raise ToolError(f"--scenario: cannot read {path}: {e}") from None
    if grid["width"] is None:
        raise ToolError(f"--scenario: {path} has no `arena W H` line")
    if grid["sensor"] is None:
        grid["sensor"] = code_bits
    if fitted:
        return _fitted_grid(path, sim)
    for axis, side in (("x", "width"), ("y", "height")):
        n = 1 << grid[axis]
        grid[axis + "_edges"] = [grid[side] * k / n for k in range(n + 1)]
    return grid


def _fitted_grid(path: str, sim: Optional[str]) -> dict:
    sim = sim or default_sim()
    if sim is None:
        raise ToolError(
            f"--scenario: {path} says `encode auto`: its cells are fitted by dynaqpc-sim, "
            "and none is built (cmake --preset host-release && cmake --build --preset host-release)"
        )
    try:
        out = subprocess.run([sim, "learned", "--scenario", path, "--grid"], capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.SubprocessError) as e:
        raise ToolError(f"--scenario: {sim} learned --grid: {e}") from None
    if out.returncode != 0:
        raise ToolError(f"--scenario: {path}: {out.stderr.strip() or 'dynaqpc-sim learned --grid failed'}")
    try:
        d = json.loads(out.stdout)
        g = d["grid"]
        return {
            "width": float(d["arena"][0]),
            "height": float(d["arena"][1]),
            **{k: int(v) for k, v in d["bits"].items()},
            "x_edges": [float(v) for v in g["x_edges"]],
            "y_edges": [float(v) for v in g["y_edges"]],
        }
    except (ValueError, KeyError, TypeError, IndexError) as e:
        raise ToolError(f"--scenario: {sim} learned --grid printed no grid ({e})") from None


def state_cell(grid: dict, state: int):
    """(x cell, y cell, heading sector, range code) of an encoded state."""
    out = []
    for k in ("x", "y", "heading", "sensor"):
        bits = grid[k]
        out.append(state & ((1 << bits) - 1))
        state >>= bits
    return tuple(out)


def _signal_schema(message) -> dict:
    props = {}
    for s in message.signals:
        props[s.name] = {"type": "number"}
        if s.choices:
            props[s.name + "_name"] = {"type": "string"}
    return {"type": "object", "title": f"dynaqpc.{message.name}", "properties": props}


class Build:
    """Foxglove's message types (foxglove-sdk, protobuf) for what the bus says: poses, transforms,
    the arena. Shared by the live server and the MCAP recording (canlog.McapLog)."""

    def __init__(self):
        self.fg, self.fc, self.m = _import_sdk()
        self.arena = None

    def pose_in_frame(self, x: float, y: float, heading: float, t: float):
        return self.m.PoseInFrame(timestamp=self._ts(t), frame_id=FRAME, pose=self._pose(x, y, 0.0, heading))

    def transforms(self, child: str, x: float, y: float, heading: float, t: float):
        m = self.m
        return m.FrameTransforms(
            transforms=[
                m.FrameTransform(
                    timestamp=self._ts(t),
                    parent_frame_id=FRAME,
                    child_frame_id=child,
                    translation=m.Vector3(x=x, y=y, z=0.0),
                    rotation=self._quat(heading),
                )
            ]
        )

    # ---- helpers ---------------------------------------------------------------------------------

    def _ts(self, t: float):
        return self.m.Timestamp.from_epoch_secs(t)

    def _scene(self, t: float, frame_id: str, ident: str, **parts):
        """A scene update of one entity `ident` at time t in frame_id, of `parts` (SceneEntity's
        cubes=, lines=, texts=... and frame_locked=)."""
        m = self.m
        return m.SceneUpdate(entities=[m.SceneEntity(timestamp=self._ts(t), frame_id=frame_id, id=ident, **parts)])

    def _quat(self, yaw: float):
        return self.m.Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))

    def _pose(self, x, y, z=0.0, yaw=0.0):
        return self.m.Pose(position=self.m.Vector3(x=x, y=y, z=z), orientation=self._quat(yaw))

    def _color(self, r, g, b, a=1.0):
        return self.m.Color(r=r, g=g, b=b, a=a)

    def _label(self, x, y, z, text: str, color, font_size: float = 12.0):
        """Text that faces the viewer at one size on screen, however far the camera is."""
        return self.m.TextPrimitive(
            pose=self._pose(x, y, z),
            billboard=True,
            font_size=font_size,
            scale_invariant=True,
            color=color,
            text=text,
        )

    # ---- what is published -----------------------------------------------------------------------

    def arena_scene(self, t: float, arena: Optional[dict] = None):
        m, a = self.m, arena if arena is not None else self.arena
        w, h = a["width"], a["height"]
        wall, height = 0.02, 0.3
        dark, grey = self._color(0.2, 0.2, 0.2), self._color(0.5, 0.5, 0.5)
        green, purple = self._color(0.1, 0.7, 0.2, 0.4), self._color(0.5, 0.2, 0.7)
        cube = lambda x, y, z, sx, sy, sz, c, yaw=0.0: m.CubePrimitive(  # noqa: E731
            pose=self._pose(x, y, z, yaw), size=m.Vector3(x=sx, y=sy, z=sz), color=c
        )
        cyl = lambda x, y, z, d, sz, c: m.CylinderPrimitive(  # noqa: E731
            pose=self._pose(x, y, z), size=m.Vector3(x=d, y=d, z=sz), bottom_scale=1.0, top_scale=1.0, color=c
        )
        cubes = [
            cube(w / 2, 0, height / 2, w, wall, height, dark),
            cube(w / 2, h, height / 2, w, wall, height, dark),
            cube(0, h / 2, height / 2, wall, h, height, dark),
            cube(w, h / 2, height / 2, wall, h, height, dark),
        ]
        cylinders, spheres, texts = [], [], []
        for ob in a.get("obstacles", []):
            if ob["kind"] == "box":
                cubes.append(
                    cube(
                        ob["cx"],
                        ob["cy"],
                        height / 2,
                        ob["w"],
                        ob["h"],
                        height,
                        grey,
                        math.radians(ob.get("angle_deg", 0.0)),
                    )
                )
            else:
                cylinders.append(cyl(ob["cx"], ob["cy"], height / 2, 2 * ob["r"], height, grey))
        goal = a.get("goal")
        if goal and goal.get("cells"):
            for x0, y0, x1, y1 in goal["cells"]:
                cubes.append(cube((x0 + x1) / 2, (y0 + y1) / 2, 0.005, x1 - x0, y1 - y0, 0.01, green))
        elif goal:
            cylinders.append(cyl(goal["cx"], goal["cy"], 0.005, 2 * goal["r"], 0.01, green))
        for b in a.get("beacons", []):
            spheres.append(
                m.SpherePrimitive(
                    pose=self._pose(b["x"], b["y"], b["z"]), size=m.Vector3(x=0.08, y=0.08, z=0.08), color=purple
                )
            )
            texts.append(self._label(b["x"], b["y"], b["z"] + 0.1, str(b.get("id", "")), purple))
        return self._scene(t, FRAME, "arena", cubes=cubes, cylinders=cylinders, spheres=spheres, texts=texts)


class LiveFoxglove(Build):
    """Feeds python-can messages into Foxglove channels on a WebSocket server."""

    def __init__(
        self,
        db,
        port: int = 8765,
        host: str = "127.0.0.1",
        arena: Optional[dict] = None,
        ray_angles=None,
        name: str = "dynaqpc",
        grid: Optional[dict] = None,
    ):
        Build.__init__(self)
        fc = self.fc
        self.db = db
        self.arena = arena
        try:
            self.server = self.fg.start_server(name=name, host=host, port=port)
        except Exception as e:
            raise ToolError(f"--foxglove: cannot serve on {host}:{port}: {e}") from None
        self.port = self.server.port
        self.host = host
        self.tf = fc.FrameTransformsChannel("/tf")
        self.pose = fc.PoseInFrameChannel("/robot/pose")
        self.true_pose = fc.PoseInFrameChannel("/robot/true_pose")
        self.rays = fc.SceneUpdateChannel("/robot/rays")
        self.bumps_ch = fc.SceneUpdateChannel("/robot/bumps")
        self.trail_ch = fc.SceneUpdateChannel("/robot/trail")
        self.arena_ch = fc.SceneUpdateChannel("/arena")
        self.values_ch = fc.SceneUpdateChannel("/robot/values")
        self.grid = grid
        self.values: Dict[tuple, Dict[tuple, float]] = {}  # (x, y) cell -> (heading, code) -> V
        try:
            self.value_msg = db.get_message_by_name("TLM_VALUE")
        except KeyError:
            self.value_msg = None
        self.state_ch = self.fg.Channel(
            "/robot/state",
            schema={
                "type": "object",
                "title": "dynaqpc.RobotState",
                "properties": {k: {"type": "number"} for k in ("episode", "step", "episodes_ended", "bumps")}
                | {k: {"type": "string"} for k in ("mode", "fix")},
            },
        )
        # Every DBC message's channel from the start: a client sees (and Plot offers) them all at once.
        self.signal_ch: Dict[int, object] = {}
        self.by_id = {}
        for msg in db.messages:
            self.by_id[(msg.frame_id, bool(msg.is_extended_frame))] = msg
            self.signal_ch[(msg.frame_id, bool(msg.is_extended_frame))] = self.fg.Channel(
                f"/can/{msg.name}", schema=_signal_schema(msg)
            )
        self.pose_dec = PoseDecoder(db, "TLM_POSE")
        try:
            self.gps_dec = PoseDecoder(db, "GPS_POSE")
        except ToolError:
            self.gps_dec = None
        self.bus = BusState(db, ray_angles)
        self.last_pose = None
        self.bump_points = []
        self.trail = []
        self.next_arena = 0.0
        self.counts: Dict[str, int] = {}
        self.tick()  # the arena at once

    def _log(self, ch, topic: str, msg) -> None:
        ch.log(msg)
        self.counts[topic] = self.counts.get(topic, 0) + 1

    def label(self) -> str:
        b = self.bus
        parts = [
            f"episode {b.episode}" if b.episode is not None else "episode ?",
            f"step {b.step}" if b.step is not None else "step -",
            b.mode or "?",
        ]
        if self.last_pose is not None and self.last_pose.fix_name:
            parts.append(f"fix {self.last_pose.fix_name}")
        return " | ".join(parts)

    def rays_scene(self, t: float):
        m = self.m
        lines = []
        for ang, r in self.bus.rays.values():
            length = r if r is not None else NO_ECHO_M
            color = self._color(1.0, 0.55, 0.0, 0.9) if r is not None else self._color(0.6, 0.6, 0.6, 0.6)
            lines.append(
                m.LinePrimitive(
                    type=m.LinePrimitiveLineType.LineList,
                    thickness=0.01,
                    color=color,
                    points=[
                        m.Point3(x=0.0, y=0.0, z=0.05),
                        m.Point3(x=length * math.cos(ang), y=length * math.sin(ang), z=0.05),
                    ],
                )
            )
        body = m.CylinderPrimitive(
            pose=self._pose(0, 0, 0.05),
            size=m.Vector3(x=2 * BODY_R, y=2 * BODY_R, z=0.1),
            bottom_scale=1.0,
            top_scale=1.0,
            color=self._color(0.1, 0.4, 0.9, 0.8),
        )
        arrow = m.ArrowPrimitive(
            pose=self._pose(0, 0, 0.11),
            shaft_length=BODY_R,
            shaft_diameter=0.03,
            head_length=0.08,
            head_diameter=0.08,
            color=self._color(1, 1, 1),
        )
        text = self._label(0, 0, 0.4, self.label(), self._color(0, 0, 0), font_size=14.0)
        return self._scene(
            t, BASE, "robot", frame_locked=True, lines=lines, cylinders=[body], arrows=[arrow], texts=[text]
        )

    def _points_scene(self, t: float, ident: str, pts, line: bool):
        m = self.m
        if line:
            prim = m.LinePrimitive(
                type=m.LinePrimitiveLineType.LineStrip,
                thickness=0.02,
                color=self._color(0.1, 0.4, 0.9, 0.7),
                points=[m.Point3(x=x, y=y, z=0.02) for x, y in pts],
            )
            return self._scene(t, FRAME, ident, lines=[prim] if pts else [])
        spheres = [
            m.SpherePrimitive(
                pose=self._pose(x, y, 0.1),
                size=m.Vector3(x=0.12, y=0.12, z=0.12),
                color=self._color(0.9, 0.1, 0.1, 0.9),
            )
            for x, y in pts
        ]
        return self._scene(t, FRAME, ident, spheres=spheres)

    def values_scene(self, t: float):
        m, g = self.m, self.grid
        xe, ye = g["x_edges"], g["y_edges"]
        best = {cell: max(vs.values()) for cell, vs in self.values.items()}
        lo, hi = min(best.values()), max(best.values())
        span = hi - lo if hi > lo else 1.0
        cubes, texts = [], []
        for (x, y), v in sorted(best.items()):
            f = (v - lo) / span
            cubes.append(
                m.CubePrimitive(
                    pose=self._pose((xe[x] + xe[x + 1]) / 2, (ye[y] + ye[y + 1]) / 2, 0.002),
                    size=m.Vector3(x=(xe[x + 1] - xe[x]) * 0.95, y=(ye[y + 1] - ye[y]) * 0.95, z=0.004),
                    color=self._color(f, 0.2, 1.0 - f, 0.55),
                )
            )
        texts.append(
            self._label(0.0, -0.3, 0.0, f"V {lo:.1f} (blue) .. {hi:.1f} (red), {len(best)} cells", self._color(0, 0, 0))
        )
        return self._scene(t, FRAME, "values", cubes=cubes, texts=texts)

    def _value(self, msg, t: float) -> None:
        vm = self.value_msg
        if vm is None or self.grid is None or msg.arbitration_id != vm.frame_id or msg.is_extended_id:
            return
        try:
            v = decode_frame(vm, msg.data)
        except Exception:
            return
        x, y, h, code = state_cell(self.grid, int(v["State"]))
        if x + 1 >= len(self.grid["x_edges"]) or y + 1 >= len(self.grid["y_edges"]):
            return
        self.values.setdefault((x, y), {})[(h, code)] = float(v["Value"])
        self._log(self.values_ch, "/robot/values", self.values_scene(t))

    def state(self) -> dict:
        b = self.bus
        return {
            "episode": b.episode if b.episode is not None else -1,
            "step": b.step if b.step is not None else -1,
            "mode": b.mode or "",
            "fix": (self.last_pose.fix_name or "") if self.last_pose else "",
            "episodes_ended": b.episodes_ended,
            "bumps": len(self.bump_points),
        }

    def _signals(self, msg, t: float) -> None:
        dm = self.by_id.get((msg.arbitration_id, bool(msg.is_extended_id)))
        if dm is None:
            return
        try:
            v = decode_frame(dm, msg.data)
        except Exception:
            return
        out = {}
        for s in dm.signals:
            if s.name not in v:
                continue
            out[s.name] = float(v[s.name])
            if s.choices:
                raw = int(v[s.name])
                out[s.name + "_name"] = str(s.choices.get(raw, raw))
        self._log(self.signal_ch[(dm.frame_id, bool(dm.is_extended_frame))], f"/can/{dm.name}", out)

    def tick(self, now: Optional[float] = None) -> None:
        """The periodic part: the arena every ARENA_PERIOD_S (a Foxglove client joining late sees
        it within that time)."""
        now = time.time() if now is None else now
        if self.arena is not None and now >= self.next_arena:
            self.next_arena = now + ARENA_PERIOD_S
            self._log(self.arena_ch, "/arena", self.arena_scene(now))

    def __call__(self, msg) -> None:
        if msg is None or msg.is_error_frame or getattr(msg, "is_remote_frame", False):
            self.tick()
            return
        t = time.time()
        self._signals(msg, t)
        self._value(msg, t)
        event = self.bus.feed(msg)
        pose = self.pose_dec.decode(msg)
        if pose is not None:
            self.last_pose = pose
            if pose.usable:
                self._log(self.pose, "/robot/pose", self.pose_in_frame(pose.x, pose.y, pose.heading, t))
                self._log(self.tf, "/tf", self.transforms(BASE, pose.x, pose.y, pose.heading, t))
                self.trail.append((pose.x, pose.y))
                del self.trail[:-TRAIL_POINTS]
                self._log(self.trail_ch, "/robot/trail", self._points_scene(t, "trail", self.trail, True))
            # Rays and the label follow the pose frame (192 ms): the bus budget's own pace.
            self._log(self.rays, "/robot/rays", self.rays_scene(t))
            self._log(self.state_ch, "/robot/state", self.state())
        gps = self.gps_dec.decode(msg) if self.gps_dec is not None else None
        if gps is not None and gps.fix_name not in NO_POSE:
            self._log(self.true_pose, "/robot/true_pose", self.pose_in_frame(gps.x, gps.y, gps.heading, t))
            self._log(self.tf, "/tf", self.transforms(TRUE_BASE, gps.x, gps.y, gps.heading, t))
        if event == "bump" and self.last_pose is not None and self.last_pose.usable:
            self.bump_points.append((self.last_pose.x, self.last_pose.y))
            self._log(self.bumps_ch, "/robot/bumps", self._points_scene(t, "bumps", self.bump_points, False))
        elif event in ("new episode", "episode number changed"):
            self.bump_points, self.trail = [], []
            self._log(self.bumps_ch, "/robot/bumps", self._points_scene(t, "bumps", [], False))
            self._log(self.state_ch, "/robot/state", self.state())
        self.tick(t)

    def stop(self) -> None:
        self.server.stop()
