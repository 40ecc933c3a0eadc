# SPDX-License-Identifier: MIT
"""Bus decoding shared by every view of the robot's bus: the pose frames (TLM_POSE, GPS_POSE)
into poses (PoseDecoder), and what a view shows besides the pose, episode, step, mode, range rays
and bumps (BusState), with the DBC only. Below every UI: dynaqpc-viewer (viewer.py), the
Foxglove live view (foxglove_live.py) and the MCAP recording (canlog.py) import it, and it
imports none of them.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass
from typing import Optional

from .common import ToolError, crc8_sae_j1850

_LENGTH_SCALE = {"mm": 1e-3, "cm": 1e-2, "m": 1.0}
_ANGLE_SCALE = {"deg": math.pi / 180.0, "rad": 1.0, "mrad": 1e-3, "": math.pi / 180.0}


@dataclass
class Pose:
    t: float
    x: float  # m
    y: float  # m
    heading: float  # rad, counter-clockwise from +x
    fix: Optional[int]
    fix_name: Optional[str] = None  # from the DBC's value table, when it has one
    #: False when the fix says there is no pose (LOST, NONE): its x, y mean nothing.
    usable: bool = True


#: Fix values that mean "no pose" (TLM_POSE FixState, GPS_POSE Fix).
NO_POSE = ("LOST", "NONE")


class WrongLength(ValueError):
    """A frame whose data is not its DBC length, longer or shorter: the firmware refuses it."""


def decode_frame(message, data, decode_choices: bool = False):
    """message.decode(data) for a frame of exactly the DBC's length; other lengths raise
    WrongLength (cantools reads only the first bytes of a longer frame, which would let a frame
    the firmware refuses pass as valid). cantools' own errors pass through."""
    data = bytes(data)
    if len(data) != message.length:
        raise WrongLength(f"wrong length: {len(data)} bytes, {message.name} has {message.length}")
    return message.decode(data, decode_choices=decode_choices)


def _crc8(frame_id: int, data: bytes) -> int:
    """CRC-8/SAE-J1850 over the id's two bytes (low first) and `data` (firmware can_link_crc8)."""
    return crc8_sae_j1850(bytes([frame_id & 0xFF, (frame_id >> 8) & 0xFF]) + bytes(data))


def _expected_crc(message, data: bytes):
    """(the frame's Crc as sent, the Crc its data calls for), or None for a frame without one."""
    try:
        sig = message.get_signal_by_name("Crc")
    except KeyError:
        return None
    data = bytes(data)
    if len(data) != message.length or not data:
        return None
    fid = message.frame_id
    if sig.length == 32:
        return int.from_bytes(data[-4:], "little"), zlib.crc32(bytes([fid & 0xFF, fid >> 8]) + data[:-4])
    return data[-1], _crc8(fid, data[:-1])


def e2e_ok(message, data) -> bool:
    """True unless the data is not the message's DBC length (longer or shorter: the firmware
    refuses it), or `message` carries a Crc (the end-to-end check, docs/can-protocol.md) that its
    data fails, or a Reserved signal (the sonar frames' unused bits, sent as 0) that is not 0:
    such a frame is noise, and no view draws it."""
    if len(bytes(data)) != message.length:
        return False
    got = _expected_crc(message, data)
    if got is not None and got[0] != got[1]:
        return False
    if got is not None and any(s.name == "Reserved" for s in message.signals):
        try:
            return decode_frame(message, data)["Reserved"] == 0
        except Exception:
            return False
    return True


def e2e_seal(message, data) -> bytes:
    """`data` with the Crc the firmware's senders put in (for tools and tests that build frames)."""
    data = bytearray(data)
    got = _expected_crc(message, bytes(data))
    if got is None:
        return bytes(data)
    sig = message.get_signal_by_name("Crc")
    if sig.length == 32:
        data[-4:] = got[1].to_bytes(4, "little")
    else:
        data[-1] = got[1]
    return bytes(data)


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

    def __init__(
        self,
        db,
        frame: str = "TLM_POSE",
        x: Optional[str] = None,
        y: Optional[str] = None,
        heading: Optional[str] = None,
        fix: Optional[str] = None,
    ):
        try:
            self.message = db.get_message_by_name(frame)
        except KeyError:
            raise ToolError(
                f"no frame {frame} in the DBC (frames: {', '.join(m.name for m in db.messages)}); pass --frame"
            ) from None
        self.db = db
        m = self.message
        self.x = _find_signal(m, lambda n: n in ("x", "x_mm", "x_m", "pos_x", "posx"), x)
        self.y = _find_signal(m, lambda n: n in ("y", "y_mm", "y_m", "pos_y", "posy"), y)
        self.heading = _find_signal(m, lambda n: "heading" in n or n in ("theta", "yaw"), heading)
        self.fix = _find_signal(m, lambda n: "fix" in n, fix)
        if self.x is None or self.y is None:
            raise ToolError(
                f"{m.name}: no x/y signals found (has {', '.join(s.name for s in m.signals)}); "
                "pass --x-signal/--y-signal"
            )
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
        if not e2e_ok(m, msg.data):
            return None  # noise: its Crc fails
        try:
            v = decode_frame(m, msg.data)
        except Exception:
            return None  # the monitor reports undecodable frames; the viewer just skips them
        heading = float(v[self.heading.name]) * self._hs if self.heading else 0.0
        fix = int(v[self.fix.name]) if self.fix else None
        name = self.fix_name(fix)
        return Pose(
            float(msg.timestamp),
            float(v[self.x.name]) * self._xs,
            float(v[self.y.name]) * self._ys,
            heading,
            fix,
            name,
            name not in NO_POSE,
        )

    def fix_name(self, fix: Optional[int]) -> Optional[str]:
        if fix is None or self.fix is None or not self.fix.choices:
            return None
        return str(self.fix.choices.get(fix, fix))

    def usable(self, values) -> bool:
        """Decoded values (decode_choices=False) of the pose frame carry a pose."""
        return self.fix is None or self.fix_name(int(values[self.fix.name])) not in NO_POSE


#: The IR board's rays (IR_RANGES), degrees counter-clockwise from the robot's heading.
IR_ANGLES = {"RangeLeft": 45.0, "RangeFront": 0.0, "RangeRight": -45.0}
#: Sonar k of the 16-sonar ring (paper-sim's `ray` lines).
SONAR_ANGLES = [11.25 + 22.5 * k for k in range(16)]


def _message(db, name):
    try:
        return db.get_message_by_name(name)
    except KeyError:
        return None


class BusState:
    """What the viewer shows besides the pose: episode and step (TLM_LEARN, TLM_EPISODE), mode
    (FW_STATUS), the latest range readings (IR_RANGES, SONAR_RANGES_A/B/C) and bumps (MOTOR_STATUS).
    Frames the DBC lacks are ignored.

    A sonar scan is three frames with one Counter (docs/can-protocol.md, "The sonar scan"): its
    rays change only once all three parts of one Counter are in, as the firmware takes a scan
    (ranges_rx_sonar). A part of another Counter drops the scan being assembled, and so does a
    second, different copy of a part that is in (the same copy again is a repeat); a dropped scan
    is counted (sonar_dropped) and the last whole scan stays drawn, never a mix of two. (The
    firmware's check of the scan Counter's step is not made: a view draws every whole scan.)"""

    def __init__(self, db, ray_angles=None):
        self.learn = _message(db, "TLM_LEARN")
        self.episode_end = _message(db, "TLM_EPISODE")
        self.status = _message(db, "FW_STATUS")
        self.ir = _message(db, "IR_RANGES")
        self.sonar = [m for m in db.messages if m.name.startswith("SONAR_RANGES_")]  # the parts of a scan
        self.motor = _message(db, "MOTOR_STATUS")
        self.ray_angles = ray_angles  # a scenario's, in ray order (sonar k, or IR left/front/right)
        self.by_id = {
            m.frame_id: m
            for m in (self.learn, self.episode_end, self.status, self.ir, self.motor, *self.sonar)
            if m is not None
        }
        self.episode: Optional[int] = None
        self.step: Optional[int] = None
        self.mode: Optional[str] = None
        self.trust: Optional[str] = None  # FW_STATUS PoseTrusted and TrustReason: "trusted (LEG)"
        self.episodes_ended = 0
        self._ended = False  # an episode's end was seen since TLM_LEARN's number last changed
        self.rays = {}  # signal name -> (angle rad relative to heading, range m or None)
        self.bumping = False
        self.sonar_scans = 0  # whole scans drawn
        self.sonar_dropped = 0  # scans dropped: a part missing, or two different copies of one
        self._scan_counter: Optional[int] = None
        self._scan_parts = {}  # the scan being assembled: message name -> (data, decoded values)
        self._scan_conflict = False  # two different copies of a part came: nothing more of this Counter

    def feed(self, msg) -> str:
        """Takes a frame; returns 'new episode' (TLM_EPISODE), 'episode number changed' (TLM_LEARN,
        no end seen), 'bump' or ''."""
        m = self.by_id.get(msg.arbitration_id)
        if m is None or msg.is_remote_frame or msg.is_error_frame or not e2e_ok(m, msg.data):
            return ""
        try:
            v = decode_frame(m, msg.data)
        except Exception:
            return ""
        if m is self.learn:
            ep = int(v["Episode"])
            changed = self.episode is not None and ep != self.episode
            self.episode, self.step = ep, int(v["Step"])
            # A new number without the last episode's end seen (a frame lost): a new trail too.
            missed_end = changed and not self._ended
            if changed:
                self._ended = False
            return "episode number changed" if missed_end else ""
        if m is self.episode_end:
            self.episodes_ended += 1
            self._ended = True
            self.step = None
            return "new episode"
        if m is self.status:
            sig = m.get_signal_by_name("Mode")
            mode = int(v["Mode"])
            self.mode = str(sig.choices.get(mode, mode)) if sig.choices else str(mode)
            if "PoseTrusted" in v:
                why = m.get_signal_by_name("TrustReason")
                r = int(v.get("TrustReason", 0))
                self.trust = (
                    ("trusted" if int(v["PoseTrusted"]) else "NOT trusted")
                    + " ("
                    + (str(why.choices.get(r, r)) if why.choices else str(r))
                    + ")"
                )
            return ""
        if m is self.motor:
            bump = bool(v.get("BumpFront", 0)) or bool(v.get("BumpRear", 0))
            rising = bump and not self.bumping
            self.bumping = bump
            return "bump" if rising else ""
        if m is self.ir:
            names = list(IR_ANGLES)
            for i, name in enumerate(names):
                if name not in v:
                    continue
                valid = int(v.get(name.replace("Range", "Valid"), 1))
                ang = self.ray_angles[i] if self.ray_angles and i < len(self.ray_angles) else IR_ANGLES[name]
                self.rays[name] = (math.radians(ang), float(v[name]) * 1e-3 if valid else None)
            return ""
        if self._sonar_part(m, bytes(msg.data), v):
            for fid, (_, values) in self._scan_parts.items():
                self._sonar_rays(self.by_id[fid], values)
            self.sonar_scans += 1
        return ""

    def _sonar_part(self, m, data: bytes, v) -> bool:
        """One sonar frame (its Crc passed) into the scan of its Counter; True when that scan is
        whole (the firmware's sonar_part_ rules: see the class)."""
        counter = int(v["Counter"])
        whole = len(self.sonar)
        if self._scan_parts and counter == self._scan_counter:
            kept = self._scan_parts.get(m.frame_id)
            if kept is not None and kept[0] == data:
                return False  # a repeat
            if kept is not None or self._scan_conflict:
                if not self._scan_conflict and len(self._scan_parts) < whole:
                    self.sonar_dropped += 1
                self._scan_conflict = True
                return False
        else:
            if self._scan_parts and len(self._scan_parts) < whole and not self._scan_conflict:
                self.sonar_dropped += 1  # a part never came
            self._scan_parts = {}
            self._scan_conflict = False
            self._scan_counter = counter
        self._scan_parts[m.frame_id] = (data, v)
        return len(self._scan_parts) == whole

    def _sonar_rays(self, m, v) -> None:
        for sig in m.signals:
            if not sig.name.startswith("Sonar"):
                continue
            k = int(sig.name[5:])
            cm = float(v[sig.name])  # decoded: cm already (2 cm per bit); raw 127, 254 cm, is no echo
            ang = self.ray_angles[k] if self.ray_angles and k < len(self.ray_angles) else SONAR_ANGLES[k % 16]
            self.rays[sig.name] = (math.radians(ang), None if cm >= 254 else cm * 1e-2)


def scenario_ray_angles(path: str):
    """The `ray` lines' angles (degrees) of a scenario file, in order."""
    angles = []
    try:
        with open(path, encoding="utf-8") as f:
            for line in f:
                words = line.split("#", 1)[0].split()
                if words and words[0] == "ray" and len(words) >= 2:
                    angles.append(float(words[1]))
    except (OSError, ValueError) as e:
        raise ToolError(f"--scenario: cannot read ray angles from {path}: {e}") from None
    if not angles:
        raise ToolError(f"--scenario: {path} has no `ray` lines")
    return angles
