# SPDX-License-Identifier: MIT
"""Recordings of the bus: MCAP (ROS 2, Foxglove) and python-can's ASC/BLF, written and read back.

An MCAP recording holds, as JSON messages with a JSON schema each:

  /can/raw               every frame as received (dynaqpc.CanFrame: id, extended, dlc, data_hex)
  /can/<MESSAGE>         one channel per DBC message, its signals decoded (numbers, and for a
                         signal with a value table also <signal>_name, e.g. Mode_name SAFE_STOP)
  /robot/pose            TLM_POSE, the firmware's estimate, as foxglove.PoseInFrame (frame "arena";
                         poses whose FixState is LOST are left out)
  /robot/true_pose       GPS_POSE, the simulator's true pose, when it is on the bus (Fix NONE left out)
  /arena                 given an arena JSON: walls, obstacles, goal and beacons as
                         foxglove.SceneUpdate, once at the start

so a run opens in Foxglove with the robot drawn in its room. `--replay run.mcap` reads /can/raw.

Time: a recording of a simulation run X times faster than real time (`--speed X`) is stamped
in robot time, t0 + (t - t0) * X, so its rates are the DBC's; the same holds for ASC and BLF.
"""

from __future__ import annotations

import json
import math
import os
from typing import Iterator, Optional

from .common import ToolError

RAW_TOPIC = "/can/raw"
POSE_TOPIC = "/robot/pose"
TRUE_POSE_TOPIC = "/robot/true_pose"
ARENA_TOPIC = "/arena"
FRAME_ID = "arena"

_TIME = {"type": "object", "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer"}}}
_VEC3 = {"type": "object", "properties": {k: {"type": "number"} for k in "xyz"}}
_QUAT = {"type": "object", "properties": {k: {"type": "number"} for k in "xyzw"}}
_POSE = {"type": "object", "properties": {"position": _VEC3, "orientation": _QUAT}}
_COLOR = {"type": "object", "properties": {k: {"type": "number"} for k in "rgba"}}
POSE_IN_FRAME_SCHEMA = {
    "title": "foxglove.PoseInFrame", "type": "object",
    "properties": {"timestamp": _TIME, "frame_id": {"type": "string"}, "pose": _POSE},
}
_PRIMITIVE = {"type": "object", "properties": {"pose": _POSE, "size": _VEC3, "color": _COLOR}}
SCENE_UPDATE_SCHEMA = {
    "title": "foxglove.SceneUpdate", "type": "object",
    "properties": {
        "deletions": {"type": "array", "items": {"type": "object"}},
        "entities": {"type": "array", "items": {"type": "object", "properties": {
            "timestamp": _TIME, "frame_id": {"type": "string"}, "id": {"type": "string"},
            "lifetime": _TIME, "frame_locked": {"type": "boolean"},
            "metadata": {"type": "array", "items": {"type": "object"}},
            "arrows": {"type": "array", "items": _PRIMITIVE},
            "cubes": {"type": "array", "items": _PRIMITIVE},
            "spheres": {"type": "array", "items": _PRIMITIVE},
            "cylinders": {"type": "array", "items": {"type": "object", "properties": {
                "pose": _POSE, "size": _VEC3, "bottom_scale": {"type": "number"},
                "top_scale": {"type": "number"}, "color": _COLOR}}},
            "lines": {"type": "array", "items": {"type": "object"}},
            "triangles": {"type": "array", "items": {"type": "object"}},
            "texts": {"type": "array", "items": {"type": "object", "properties": {
                "pose": _POSE, "billboard": {"type": "boolean"}, "font_size": {"type": "number"},
                "scale_invariant": {"type": "boolean"}, "color": _COLOR, "text": {"type": "string"}}}},
            "models": {"type": "array", "items": {"type": "object"}},
        }}},
    },
}
CAN_FRAME_SCHEMA = {
    "title": "dynaqpc.CanFrame", "type": "object",
    "properties": {"id": {"type": "integer"}, "extended": {"type": "boolean"}, "remote": {"type": "boolean"},
                   "error": {"type": "boolean"}, "dlc": {"type": "integer"}, "data_hex": {"type": "string"}},
}


def _stamp(t: float) -> dict:
    sec = math.floor(t)
    return {"sec": int(sec), "nsec": int(round((t - sec) * 1e9)) % 1000000000}


def _quat_z(yaw: float) -> dict:
    return {"x": 0.0, "y": 0.0, "z": math.sin(yaw / 2), "w": math.cos(yaw / 2)}


def _pose(x: float, y: float, z: float = 0.0, yaw: float = 0.0) -> dict:
    return {"position": {"x": x, "y": y, "z": z}, "orientation": _quat_z(yaw)}


def _color(r, g, b, a=1.0) -> dict:
    return {"r": r, "g": g, "b": b, "a": a}


def arena_scene(arena: dict, t: float) -> dict:
    """The arena (simulator JSON, metres) as a foxglove.SceneUpdate."""
    w, h = arena["width"], arena["height"]
    wall, height = 0.02, 0.3
    grey, green, purple = _color(0.5, 0.5, 0.5), _color(0.1, 0.7, 0.2, 0.4), _color(0.5, 0.2, 0.7)
    cubes = [  # the four walls
        {"pose": _pose(w / 2, 0, height / 2), "size": {"x": w, "y": wall, "z": height}, "color": _color(0.2, 0.2, 0.2)},
        {"pose": _pose(w / 2, h, height / 2), "size": {"x": w, "y": wall, "z": height}, "color": _color(0.2, 0.2, 0.2)},
        {"pose": _pose(0, h / 2, height / 2), "size": {"x": wall, "y": h, "z": height}, "color": _color(0.2, 0.2, 0.2)},
        {"pose": _pose(w, h / 2, height / 2), "size": {"x": wall, "y": h, "z": height}, "color": _color(0.2, 0.2, 0.2)},
    ]
    cylinders, spheres, texts = [], [], []
    for ob in arena.get("obstacles", []):
        if ob["kind"] == "box":
            cubes.append({"pose": _pose(ob["cx"], ob["cy"], height / 2, math.radians(ob.get("angle_deg", 0.0))),
                          "size": {"x": ob["w"], "y": ob["h"], "z": height}, "color": grey})
        else:
            cylinders.append({"pose": _pose(ob["cx"], ob["cy"], height / 2),
                              "size": {"x": 2 * ob["r"], "y": 2 * ob["r"], "z": height},
                              "bottom_scale": 1.0, "top_scale": 1.0, "color": grey})
    goal = arena.get("goal")
    if goal and goal.get("cells"):
        for x0, y0, x1, y1 in goal["cells"]:
            cubes.append({"pose": _pose((x0 + x1) / 2, (y0 + y1) / 2, 0.005),
                          "size": {"x": x1 - x0, "y": y1 - y0, "z": 0.01}, "color": green})
    elif goal:
        cylinders.append({"pose": _pose(goal["cx"], goal["cy"], 0.005),
                          "size": {"x": 2 * goal["r"], "y": 2 * goal["r"], "z": 0.01},
                          "bottom_scale": 1.0, "top_scale": 1.0, "color": green})
    for b in arena.get("beacons", []):
        spheres.append({"pose": _pose(b["x"], b["y"], b["z"]), "size": {"x": 0.08, "y": 0.08, "z": 0.08},
                        "color": purple})
        texts.append({"pose": _pose(b["x"], b["y"], b["z"] + 0.1), "billboard": True, "font_size": 12.0,
                      "scale_invariant": True, "color": purple, "text": str(b.get("id", ""))})
    entity = {"timestamp": _stamp(t), "frame_id": FRAME_ID, "id": "arena", "lifetime": {"sec": 0, "nsec": 0},
              "frame_locked": False, "metadata": [], "arrows": [], "cubes": cubes, "spheres": spheres,
              "cylinders": cylinders, "lines": [], "triangles": [], "texts": texts, "models": []}
    return {"deletions": [], "entities": [entity]}


def _signal_schema(message) -> dict:
    props = {}
    for s in message.signals:
        props[s.name] = {"type": "number", "description": f"{s.unit or ''}".strip()}
        if s.choices:
            props[s.name + "_name"] = {"type": "string",
                                       "enum": [str(v) for v in s.choices.values()]}
    return {"title": f"dynaqpc.{message.name}", "type": "object", "properties": props}


class TimeScale:
    """Wall time to robot time for a simulation run `speed` times faster: t0 + (t - t0) * speed."""

    def __init__(self, speed: float = 1.0):
        self.speed = speed
        self.t0 = None

    def __call__(self, t: float) -> float:
        if self.t0 is None:
            self.t0 = t
        return self.t0 + (t - self.t0) * self.speed


class McapLog:
    """Writes an MCAP recording as described above. Call with each python-can message; stop()."""

    def __init__(self, path: str, db, arena: Optional[dict] = None, speed: float = 1.0):
        from mcap.writer import Writer

        from .viewer import PoseDecoder

        try:
            self._file = open(path, "wb")
        except OSError as e:
            raise ToolError(f"cannot write {path}: {e.strerror or e}") from None
        self.db, self.arena, self.scale = db, arena, TimeScale(speed)
        self.w = Writer(self._file)
        self.w.start(profile="", library="dynaqpc-monitor")
        self.messages = 0
        self._raw = self._channel(RAW_TOPIC, CAN_FRAME_SCHEMA)
        self._by_id = {}
        for m in db.messages:
            self._by_id[(m.frame_id, bool(m.is_extended_frame))] = (m, self._channel(f"/can/{m.name}", _signal_schema(m)))
        self._poses = []
        for name, topic in (("TLM_POSE", POSE_TOPIC), ("GPS_POSE", TRUE_POSE_TOPIC)):
            try:
                dec = PoseDecoder(db, name)
            except ToolError:
                continue  # a DBC without this frame (another robot's)
            self._poses.append((dec, self._channel(topic, POSE_IN_FRAME_SCHEMA)))
        self._scene = self._channel(ARENA_TOPIC, SCENE_UPDATE_SCHEMA) if arena is not None else None

    def _channel(self, topic: str, schema: dict) -> int:
        sid = self.w.register_schema(name=schema["title"], encoding="jsonschema",
                                     data=json.dumps(schema).encode())
        return self.w.register_channel(topic=topic, message_encoding="json", schema_id=sid)

    def _add(self, channel: int, t: float, obj: dict) -> None:
        ns = int(round(t * 1e9))
        self.w.add_message(channel_id=channel, log_time=ns, publish_time=ns, data=json.dumps(obj).encode())
        self.messages += 1

    def __call__(self, msg) -> None:
        t = self.scale(float(msg.timestamp))
        if self._scene is not None:
            self._add(self._scene, t, arena_scene(self.arena, t))
            self._scene = None
        data = bytes(msg.data)
        self._add(self._raw, t, {"id": msg.arbitration_id, "extended": bool(msg.is_extended_id),
                                 "remote": bool(msg.is_remote_frame), "error": bool(msg.is_error_frame),
                                 "dlc": msg.dlc, "data_hex": data.hex()})
        entry = self._by_id.get((msg.arbitration_id, bool(msg.is_extended_id)))
        if entry is None or msg.is_remote_frame or msg.is_error_frame:
            return
        m, channel = entry
        try:
            values = m.decode(data, decode_choices=False)
        except Exception:
            return  # undecodable: the raw frame is kept, the monitor counts it
        out = {k: (float(v) if isinstance(v, float) else int(v)) for k, v in values.items()}
        for s in m.signals:
            if s.choices and s.name in values:
                out[s.name + "_name"] = str(s.choices.get(int(values[s.name]), int(values[s.name])))
        self._add(channel, t, out)
        for dec, pchannel in self._poses:
            if dec.message is not m:
                continue
            pose = dec.decode(msg)
            if pose is None or not dec.usable(values):
                continue
            self._add(pchannel, t, {"timestamp": _stamp(t), "frame_id": FRAME_ID,
                                    "pose": _pose(pose.x, pose.y, 0.0, pose.heading)})

    def stop(self) -> None:
        self.w.finish()
        self._file.close()


class _ScaledLogger:
    """python-can's writer (ASC, BLF, ...) with the time stamps in robot time."""

    def __init__(self, path: str, speed: float):
        import can

        try:
            self.logger = can.Logger(path)
        except Exception as e:
            raise ToolError(f"cannot log to {path}: {e}") from None
        self.scale = TimeScale(speed)

    def __call__(self, msg) -> None:
        import copy

        if self.scale.speed != 1.0:
            msg = copy.copy(msg)
            msg.timestamp = self.scale(float(msg.timestamp))
        self.logger(msg)

    def stop(self) -> None:
        self.logger.stop()


def open_log(path: str, db, arena: Optional[dict] = None, speed: float = 1.0):
    """A recorder for `path`: MCAP for .mcap, else python-can's writer for the extension."""
    if path.lower().endswith(".mcap"):
        return McapLog(path, db, arena, speed)
    return _ScaledLogger(path, speed)


def read_log(path: str) -> Iterator:
    """The frames of a recording as python-can messages: MCAP (its /can/raw channel) or any log
    python-can reads. A missing, unreadable or garbage file is a ToolError naming it."""
    import can

    if not os.path.isfile(path):
        raise ToolError(f"cannot read {path}: no such file")
    if path.lower().endswith(".mcap"):
        yield from _read_mcap(path)
        return
    try:
        reader = can.LogReader(path)
        for msg in reader:
            yield msg
    except ToolError:
        raise
    except Exception as e:  # python-can's readers raise many types on garbage
        raise ToolError(f"cannot read {path}: not a readable CAN log ({type(e).__name__}: {e})") from None


def _read_mcap(path: str) -> Iterator:
    import can
    from mcap.reader import make_reader

    try:
        with open(path, "rb") as f:
            reader = make_reader(f)
            for _schema, channel, message in reader.iter_messages(topics=[RAW_TOPIC]):
                d = json.loads(message.data)
                yield can.Message(timestamp=message.log_time * 1e-9, arbitration_id=int(d["id"]),
                                  is_extended_id=bool(d["extended"]), is_remote_frame=bool(d.get("remote")),
                                  is_error_frame=bool(d.get("error")), dlc=int(d["dlc"]),
                                  data=bytes.fromhex(d["data_hex"]))
    except ToolError:
        raise
    except Exception as e:
        raise ToolError(f"cannot read {path}: not a dynaqpc MCAP recording ({type(e).__name__}: {e})") from None
