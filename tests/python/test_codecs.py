# SPDX-License-Identifier: MIT
"""The C codecs and docs/dynaqpc.dbc cannot drift apart.

1. The committed generated code is what tools/gen_codecs.py makes from the committed DBC.
2. The DBC keeps its own rules (standard ids, <= 8 bytes, a 4-bit Counter and a cycle time on
   every periodic frame, CRC on commands, 500 kbit/s).
3. Shared vectors: frames cantools encodes are decoded by the firmware's C calls to the same
   physical values; frames the C encoders build decode in cantools to the values asked for; and
   values outside a signal's DBC range are refused by the C side.
"""
import pathlib
import random
import zlib
import subprocess
import sys

import cantools
import pytest
from crccheck.crc import Crc8SaeJ1850

ROOT = pathlib.Path(__file__).resolve().parents[2]
DBC = ROOT / "docs" / "dynaqpc.dbc"
GENERATED = ROOT / "firmware" / "drivers" / "src" / "generated"
# The frames with a Crc: the commands, and the end-to-end protected frames that feed estimation.
COMMAND_FRAMES = {"MOTOR_CMD", "TOOL_CMD", "GYRO_RATE", "MOTOR_STATUS", "IR_RANGES", "SONAR_RANGES_A",
                  "SONAR_RANGES_B", "SONAR_RANGES_C", "GPS_POSE"}
SAMPLES = 60


@pytest.fixture(scope="module")
def db():
    return cantools.database.load_file(str(DBC))


class Vectors:
    """can_vectors as a coprocess: one request line, one answer line."""

    def __init__(self, path):
        self.proc = subprocess.Popen([str(path)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     text=True)

    def ask(self, line):
        self.proc.stdin.write(line + "\n")
        self.proc.stdin.flush()
        answer = self.proc.stdout.readline().split()
        assert answer, f"can_vectors gave no answer to {line!r}"
        return answer

    def close(self):
        self.proc.stdin.close()
        assert self.proc.wait(timeout=10) == 0


@pytest.fixture(scope="module")
def vectors(can_vectors_path):
    v = Vectors(can_vectors_path)
    yield v
    v.close()


def crc8(frame_id, data):
    return Crc8SaeJ1850.calc(bytes([frame_id & 0xFF, frame_id >> 8]) + bytes(data))


def crc32(frame_id, data):
    """TOOL_CMD's Crc: CRC-32 (zlib's) over the id's two bytes and the data before it."""
    return zlib.crc32(bytes([frame_id & 0xFF, frame_id >> 8]) + bytes(data))


def with_crc(msg, data):
    """The frame `data` with its Crc: 32 bits on TOOL_CMD, else 8."""
    data = bytearray(data)
    if msg.name == "TOOL_CMD":
        data[-4:] = crc32(msg.frame_id, data[:-4]).to_bytes(4, "little")
    else:
        data[-1] = crc8(msg.frame_id, data[:-1])
    return bytes(data)


def raw_limits(sig):
    lo = round((sig.minimum - sig.offset) / sig.scale)
    hi = round((sig.maximum - sig.offset) / sig.scale)
    return lo, hi


def random_raw(msg, rng):
    raw = {}
    for sig in msg.signals:
        if sig.name == "Reserved":  # sent as 0 (no range in the DBC: [0|0] there means none)
            raw[sig.name] = 0
            continue
        lo, hi = raw_limits(sig)
        raw[sig.name] = rng.randint(lo, hi)
    if "Crc" in raw:
        raw["Crc"] = 0
    return raw


def encode_raw(msg, raw, strict=True):
    data = bytearray(msg.encode(raw, scaling=False, strict=strict))
    if msg.name in COMMAND_FRAMES:
        return with_crc(msg, data)
    return bytes(data)


def parse_ok(answer):
    assert answer[0] == "OK", " ".join(answer)
    return answer[1], {k: float(v) for k, v in (tok.split("=") for tok in answer[2:])}


# ---- 1. generated code ------------------------------------------------------------------------

def test_generated_codecs_match_the_dbc(tmp_path):
    subprocess.run([sys.executable, str(ROOT / "tools" / "gen_codecs.py"), "-o", str(tmp_path)],
                   check=True, stdout=subprocess.DEVNULL)
    for name in ("dynaqpc_can.h", "dynaqpc_can.c"):
        fresh = (tmp_path / name).read_text()
        committed = (GENERATED / name).read_text()
        assert fresh == committed, (
            f"{name} is stale: run `.venv/bin/python tools/gen_codecs.py` and commit the result")


# ---- 2. the DBC's own rules -------------------------------------------------------------------

def test_dbc_rules(db):
    assert db.dbc.attributes["Baudrate"].value == 500000
    ids = [m.frame_id for m in db.messages]
    assert len(ids) == len(set(ids))
    for msg in db.messages:
        assert not msg.is_extended_frame and msg.frame_id <= 0x7FF, msg.name
        assert msg.length <= 8, msg.name
        assert msg.senders, msg.name
        periodic = msg.cycle_time is not None and msg.cycle_time > 0
        if periodic:
            counter = msg.get_signal_by_name("Counter")
            assert counter.length == 4 and not counter.is_signed, msg.name
        if msg.name in COMMAND_FRAMES:
            crc = msg.get_signal_by_name("Crc")
            width = 32 if msg.name == "TOOL_CMD" else 8
            assert crc.length == width and crc.start == 8 * msg.length - width, msg.name
    cycles = {m.name: m.cycle_time for m in db.messages}
    assert cycles == {
        "TOOL_CMD": None, "TOOL_ACK": None, "MOTOR_CMD": 192, "MOTOR_STATUS": 48, "GYRO_RATE": 16, "IR_RANGES": 48,
        "SONAR_RANGES_A": 96, "SONAR_RANGES_B": 96, "SONAR_RANGES_C": 96, "GPS_POSE": 96, "FW_STATUS": 1000,
        "TLM_POSE": 192, "TLM_LEARN": None, "TLM_SCHED": 192, "TLM_EPISODE": None, "TLM_VALUE": None}
    # TLM_LEARN goes once per real learning step (several control periods), not every 192 ms.
    assert db.get_message_by_name("TLM_LEARN").dbc.attributes["GenMsgSendType"].value == 1  # Event
    assert db.get_message_by_name("TOOL_ACK").dbc.attributes["GenMsgSendType"].value == 1  # Event
    # An answer names every command TOOL_CMD can carry.
    cmd, ack = db.get_message_by_name("TOOL_CMD"), db.get_message_by_name("TOOL_ACK")
    assert (dict(cmd.get_signal_by_name("Command").choices)
            == dict(ack.get_signal_by_name("Command").choices))
    assert db.get_message_by_name("MOTOR_CMD").dbc.attributes["GenMsgTimeoutTime"].value == 500


# ---- 3. shared vectors ------------------------------------------------------------------------

def expected_decoded(msg, data):
    values = msg.decode(data, decode_choices=False)
    values.pop("Crc", None)
    return values


@pytest.mark.parametrize("name", [
    "TOOL_CMD", "TOOL_ACK", "MOTOR_CMD", "MOTOR_STATUS", "GYRO_RATE", "IR_RANGES", "SONAR_RANGES_A",
    "SONAR_RANGES_B", "SONAR_RANGES_C", "GPS_POSE", "FW_STATUS", "TLM_POSE", "TLM_LEARN", "TLM_SCHED", "TLM_EPISODE", "TLM_VALUE"])
def test_c_decodes_what_cantools_encodes(db, vectors, name):
    msg = db.get_message_by_name(name)
    rng = random.Random(name)
    for _ in range(SAMPLES):
        raw = random_raw(msg, rng)
        data = encode_raw(msg, raw)
        frame, got = parse_ok(vectors.ask(f"decode {msg.frame_id:03X} {data.hex()}"))
        assert frame == name
        want = expected_decoded(msg, data)
        # The tools' decoders do not return the counters of the firmware's own frames.
        if name.startswith("TLM_") or name == "FW_STATUS":
            want.pop("Counter", None)
        want.pop("Reserved", None)  # must be 0, as it is here: the C side refuses any other
        assert got.keys() == want.keys(), f"{name}: C prints {sorted(got)}, DBC has {sorted(want)}"
        for key, value in want.items():
            assert got[key] == pytest.approx(value, abs=1e-9), f"{name}.{key} raw {raw}"


@pytest.mark.parametrize("name", [
    "TOOL_CMD", "TOOL_ACK", "MOTOR_CMD", "MOTOR_STATUS", "GYRO_RATE", "IR_RANGES", "SONAR_RANGES_A",
    "SONAR_RANGES_B", "SONAR_RANGES_C", "GPS_POSE", "FW_STATUS", "TLM_POSE", "TLM_LEARN", "TLM_SCHED", "TLM_EPISODE", "TLM_VALUE"])
def test_cantools_decodes_what_c_encodes(db, vectors, name):
    msg = db.get_message_by_name(name)
    rng = random.Random("enc" + name)
    for _ in range(SAMPLES):
        raw = random_raw(msg, rng)
        raw.pop("Crc", None)
        phys = {s.name: raw[s.name] * s.scale + s.offset for s in msg.signals if s.name in raw}
        if name == "IR_RANGES":  # an invalid range is sent as 0
            for side in ("Left", "Front", "Right"):
                if not phys["Valid" + side]:
                    phys["Range" + side] = 0
        args = " ".join(f"{k}={v!r}" for k, v in phys.items())
        answer = vectors.ask(f"encode {name} {args}")
        assert answer[0] == "OK", f"{name} {args}: {answer}"
        assert int(answer[1], 16) == msg.frame_id
        data = bytes.fromhex(answer[2])
        assert len(data) == msg.length
        if name in COMMAND_FRAMES:
            assert data == with_crc(msg, data)
        got = expected_decoded(msg, data)
        for key, value in phys.items():
            assert got[key] == pytest.approx(value, abs=1e-9), f"{name}.{key}: sent {args}"


OUT_OF_RANGE = [
    ("MOTOR_CMD", "SpeedLeft", 1501), ("MOTOR_CMD", "SpeedRight", -1501),
    ("MOTOR_STATUS", "SpeedLeft", 2001), ("GYRO_RATE", "YawRate", -30001),
    ("GYRO_RATE", "Status", 3), ("IR_RANGES", "RangeFront", 2001),
    ("GPS_POSE", "Heading", 36000), ("GPS_POSE", "Fix", 3), ("TOOL_CMD", "Command", 7),
    ("TOOL_ACK", "Result", 3), ("TOOL_ACK", "Reason", 12),
    ("TLM_POSE", "Heading", 36000), ("TLM_SCHED", "IdlePercent", 201), ("FW_STATUS", "Mode", 5),
    ("SONAR_RANGES_A", "Reserved", 1), ("SONAR_RANGES_B", "Reserved", 4), ("SONAR_RANGES_C", "Reserved", 32),
]


@pytest.mark.parametrize("name,signal,raw_value", OUT_OF_RANGE)
def test_c_refuses_values_outside_the_dbc_range(db, vectors, name, signal, raw_value):
    msg = db.get_message_by_name(name)
    raw = random_raw(msg, random.Random(0))
    raw[signal] = raw_value
    data = encode_raw(msg, raw, strict=False)
    answer = vectors.ask(f"decode {msg.frame_id:03X} {data.hex()}")
    assert answer[0] == "ERR", f"{name}.{signal} raw {raw_value} accepted: {answer}"


@pytest.mark.parametrize("name", ["MOTOR_STATUS", "GYRO_RATE", "IR_RANGES", "GPS_POSE", "TOOL_CMD",
                                  "MOTOR_CMD", "SONAR_RANGES_A", "SONAR_RANGES_B", "SONAR_RANGES_C"])
def test_c_refuses_wrong_lengths_and_bad_crc(db, vectors, name):
    msg = db.get_message_by_name(name)
    data = encode_raw(msg, random_raw(msg, random.Random(1)))
    for length in (0, msg.length - 1, 8 if msg.length < 8 else 7):
        answer = vectors.ask(f"decode {msg.frame_id:03X} {(data + bytes(8))[:length].hex()}")
        assert answer[0] == "ERR", f"{name} with {length} bytes accepted"
    if name in COMMAND_FRAMES:
        bad = bytearray(data)
        bad[-1] ^= 0x50  # the Crc's bits
        assert vectors.ask(f"decode {msg.frame_id:03X} {bad.hex()}")[0] == "ERR"
