# SPDX-License-Identifier: MIT
"""Recordings of the bus: MCAP (Foxglove) and python-can's ASC/BLF, written and read back.

An MCAP recording holds:

  /can/raw               every frame as received (JSON, dynaqpc.CanFrame: id, extended, dlc,
                         data_hex)
  /can/<MESSAGE>         one channel per DBC message, its signals decoded (JSON with a JSON
                         schema: numbers, and for a signal with a value table also <signal>_name,
                         e.g. Mode_name SAFE_STOP)
  /robot/pose            TLM_POSE, the firmware's estimate, as foxglove.PoseInFrame (frame "arena";
                         poses whose FixState is LOST are left out)
  /robot/true_pose       GPS_POSE, the simulator's true pose, when it is on the bus (Fix NONE left out)
  /tf                    foxglove.FrameTransforms: arena → base_link (TLM_POSE), arena →
                         true_base_link (GPS_POSE), so Foxglove's 3D panel can follow the robot
  /arena                 given an arena JSON: walls, obstacles, goal and beacons as
                         foxglove.SceneUpdate, once at the start

The foxglove.* topics are protobuf with the schemas Foxglove publishes, as foxglove-sdk encodes
them (the same messages `dynaqpc-monitor --foxglove` serves live); every channel's messages carry
a sequence number counted from 1. It is MCAP as Foxglove reads it, not a ROS 2 bag: `ros2 bag
play` reads only ROS 2 (CDR) messages. `--replay run.mcap` reads /can/raw; a recording that was
never finished (its recorder killed with SIGKILL, or a power cut) up to the cut, with a warning.

Time: a recording of a simulation run X times faster than real time (`--speed X`) is stamped
in robot time, t0 + (t - t0) * X, so its rates are the DBC's; the same holds for ASC and BLF.
"""

from __future__ import annotations

import json
import os
import sys
from typing import Iterator, Optional

from .bus_decode import PoseDecoder, decode_frame, e2e_ok
from .common import ToolError

CHUNK_BYTES = 32 * 1024  # the MCAP chunk's records: what a SIGKILL can lose (McapLog)
RAW_TOPIC = "/can/raw"
POSE_TOPIC = "/robot/pose"
TRUE_POSE_TOPIC = "/robot/true_pose"
TF_TOPIC = "/tf"
ARENA_TOPIC = "/arena"
FRAME_ID = "arena"

CAN_FRAME_SCHEMA = {
    "title": "dynaqpc.CanFrame",
    "type": "object",
    "properties": {
        "id": {"type": "integer"},
        "extended": {"type": "boolean"},
        "remote": {"type": "boolean"},
        "error": {"type": "boolean"},
        "dlc": {"type": "integer"},
        "data_hex": {"type": "string"},
    },
}


def _signal_schema(message) -> dict:
    props = {}
    for s in message.signals:
        props[s.name] = {"type": "number", "description": f"{s.unit or ''}".strip()}
        if s.choices:
            props[s.name + "_name"] = {"type": "string", "enum": [str(v) for v in s.choices.values()]}
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

        try:
            self._file = open(path, "wb")
        except OSError as e:
            raise ToolError(f"cannot write {path}: {e.strerror or e}") from None
        from .foxglove_live import BASE, TRUE_BASE, Build

        self.db, self.arena, self.scale = db, arena, TimeScale(speed)
        self.fox = Build()
        m = self.fox.m
        # A chunk is written out when it holds CHUNK_BYTES of records: a recorder killed with
        # SIGKILL (or a power cut) loses the one being filled, about 1 s of the lab robot's bus at
        # real time (31 KB/s measured) where mcap's default 1 MiB lost half a minute.
        self.w = Writer(self._file, chunk_size=CHUNK_BYTES)
        self.w.start(profile="", library="dynaqpc-monitor")
        self.messages = 0
        self._sequence = {}  # channel -> the last sequence number written
        self._schema_ids = {}
        self._raw = self._channel(RAW_TOPIC, CAN_FRAME_SCHEMA)
        self._by_id = {}
        for msg in db.messages:
            self._by_id[(msg.frame_id, bool(msg.is_extended_frame))] = (
                msg,
                self._channel(f"/can/{msg.name}", _signal_schema(msg)),
            )
        self._poses = []
        self._tf = self._proto_channel(TF_TOPIC, m.FrameTransforms)
        for name, topic, child in (("TLM_POSE", POSE_TOPIC, BASE), ("GPS_POSE", TRUE_POSE_TOPIC, TRUE_BASE)):
            try:
                dec = PoseDecoder(db, name)
            except ToolError:
                continue  # a DBC without this frame (another robot's)
            self._poses.append((dec, self._proto_channel(topic, m.PoseInFrame), child))
        self._scene = self._proto_channel(ARENA_TOPIC, m.SceneUpdate) if arena is not None else None

    def _channel(self, topic: str, schema: dict) -> int:
        sid = self.w.register_schema(name=schema["title"], encoding="jsonschema", data=json.dumps(schema).encode())
        return self.w.register_channel(topic=topic, message_encoding="json", schema_id=sid)

    def _proto_channel(self, topic: str, kind) -> int:
        """A channel of a Foxglove type: the sdk's protobuf schema (a FileDescriptorSet)."""
        schema = kind.get_schema()
        sid = self._schema_ids.get(schema.name)
        if sid is None:
            sid = self._schema_ids[schema.name] = self.w.register_schema(
                name=schema.name, encoding=schema.encoding, data=bytes(schema.data)
            )
        return self.w.register_channel(topic=topic, message_encoding="protobuf", schema_id=sid)

    def _add(self, channel: int, t: float, obj) -> None:
        ns = int(round(t * 1e9))
        seq = self._sequence.get(channel, 0) + 1
        self._sequence[channel] = seq
        data = obj.encode() if hasattr(obj, "encode") else json.dumps(obj).encode()
        self.w.add_message(channel_id=channel, log_time=ns, publish_time=ns, data=data, sequence=seq)
        self.messages += 1

    def __call__(self, msg) -> None:
        t = self.scale(float(msg.timestamp))
        if self._scene is not None:
            self._add(self._scene, t, self.fox.arena_scene(t, self.arena))
            self._scene = None
        data = bytes(msg.data)
        self._add(
            self._raw,
            t,
            {
                "id": msg.arbitration_id,
                "extended": bool(msg.is_extended_id),
                "remote": bool(msg.is_remote_frame),
                "error": bool(msg.is_error_frame),
                "dlc": msg.dlc,
                "data_hex": data.hex(),
            },
        )
        entry = self._by_id.get((msg.arbitration_id, bool(msg.is_extended_id)))
        if entry is None or msg.is_remote_frame or msg.is_error_frame:
            return
        m, channel = entry
        try:
            values = decode_frame(m, data)
        except Exception:
            return  # undecodable (a wrong length too): the raw frame is kept, the monitor counts it
        if not e2e_ok(m, data):
            return  # noise that decodes: its Crc fails, so its values are none (raw frame kept)
        out = {k: (float(v) if isinstance(v, float) else int(v)) for k, v in values.items()}
        for s in m.signals:
            if s.choices and s.name in values:
                out[s.name + "_name"] = str(s.choices.get(int(values[s.name]), int(values[s.name])))
        self._add(channel, t, out)
        for dec, pchannel, child in self._poses:
            if dec.message is not m:
                continue
            pose = dec.decode(msg)
            if pose is None or not dec.usable(values):
                continue
            self._add(pchannel, t, self.fox.pose_in_frame(pose.x, pose.y, pose.heading, t))
            self._add(self._tf, t, self.fox.transforms(child, pose.x, pose.y, pose.heading, t))

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
    python-can reads. A missing, unreadable or garbage file is a ToolError naming it. An MCAP
    recording that was cut (never finished) is read up to the cut, with a warning on stderr."""
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


MCAP_MAGIC = b"\x89MCAP0\r\n"


def _frame(log_time: int, data: bytes):
    """A /can/raw message as a python-can message."""
    import can

    d = json.loads(data)
    return can.Message(
        timestamp=log_time * 1e-9,
        arbitration_id=int(d["id"]),
        is_extended_id=bool(d["extended"]),
        is_remote_frame=bool(d.get("remote")),
        is_error_frame=bool(d.get("error")),
        dlc=int(d["dlc"]),
        data=bytes.fromhex(d["data_hex"]),
    )


def _read_mcap(path: str) -> Iterator:
    try:
        with open(path, "rb") as f:
            head = f.read(len(MCAP_MAGIC))
            f.seek(max(0, os.path.getsize(path) - len(MCAP_MAGIC)))
            tail = f.read()
    except OSError as e:
        raise ToolError(f"cannot read {path}: {e.strerror or e}") from None
    if head == MCAP_MAGIC and tail != MCAP_MAGIC:
        yield from _read_cut_mcap(path)
        return
    from mcap.reader import make_reader

    try:
        with open(path, "rb") as f:
            reader = make_reader(f)
            for _schema, _channel, message in reader.iter_messages(topics=[RAW_TOPIC]):
                yield _frame(message.log_time, message.data)
    except ToolError:
        raise
    except Exception as e:
        raise ToolError(f"cannot read {path}: not a dynaqpc MCAP recording ({type(e).__name__}: {e})") from None


def _read_cut_mcap(path: str) -> Iterator:
    """A recording whose writer never finished it (killed with SIGKILL, a power cut): it has no
    summary or end, so its records are read in order (mcap's StreamReader) up to the cut, and a
    warning on stderr says so. What the writer had not yet written out (the last chunk) is lost."""
    from mcap.records import Channel, Header, Message
    from mcap.stream_reader import StreamReader

    raw_ids = set()
    frames, last_t, first = 0, None, True
    with open(path, "rb") as f:
        records = StreamReader(f, record_size_limit=os.path.getsize(path)).records
        while True:
            try:
                rec = next(records)
                if first and not isinstance(rec, Header):
                    raise ValueError(f"starts with {type(rec).__name__}, not a Header")
                first = False
                if isinstance(rec, Channel) and rec.topic == RAW_TOPIC:
                    raw_ids.add(rec.id)
                if not isinstance(rec, Message) or rec.channel_id not in raw_ids:
                    continue
                msg = _frame(rec.log_time, rec.data)
            except StopIteration:
                break  # whole after all
            except Exception as e:
                if first:
                    raise ToolError(
                        f"cannot read {path}: not a dynaqpc MCAP recording ({type(e).__name__}: {e})"
                    ) from None
                break  # the cut
            frames += 1
            last_t = msg.timestamp
            yield msg
    upto = f", the last at {last_t:.6f}" if last_t is not None else ""
    print(
        f"warning: {path} was cut short (its recorder was killed or lost power, so it was never "
        f"finished): {frames} frames read up to the cut{upto}; what came after is lost",
        file=sys.stderr,
        flush=True,
    )
