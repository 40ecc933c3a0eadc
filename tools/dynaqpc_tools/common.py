# SPDX-License-Identifier: MIT
"""What the tools share: where the repository is, the DBC, opening a CAN bus."""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import zlib
from pathlib import Path
from typing import Iterable, Optional

#: The virtual bus of the host simulator (python-can udp_multicast, design decision 8).
VCAN_INTERFACE = "udp_multicast"
VCAN_CHANNEL = "239.74.163.2"
VCAN_PORT = 43113


class ToolError(Exception):
    """A problem the user can fix (missing file, bad argument): printed without a traceback."""


def repo_root() -> Optional[Path]:
    """The dynaqpc checkout holding this package or the working directory, if any."""
    for start in (Path(__file__).resolve().parent, Path.cwd().resolve()):
        for d in (start, *start.parents):
            if (d / "CMakePresets.json").is_file() and (d / "docs").is_dir():
                return d
    return None


def default_dbc_path() -> str:
    root = repo_root()
    return str(root / "docs" / "dynaqpc.dbc") if root else "docs/dynaqpc.dbc"


def load_dbc(path: str):
    """Loads a DBC with cantools; a missing or broken file is a ToolError."""
    import cantools

    if not os.path.isfile(path):
        raise ToolError(f"DBC file not found: {path} (pass --dbc)")
    try:
        return cantools.database.load_file(path)
    except Exception as e:  # cantools raises several parser exception types
        raise ToolError(f"cannot parse DBC {path}: {e}") from e


def read_json(path: str, what: str = "") -> object:
    """A JSON file's value; one that cannot be read or parsed is a ToolError ("cannot read
    {what}{path}: why")."""
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        raise ToolError(f"cannot read {what}{path}: {e}") from e


def parse_bus_kwargs(items: Iterable[str]) -> dict:
    """KEY=VALUE strings to keyword arguments; ints and floats are converted."""
    out = {}
    for item in items:
        if "=" not in item:
            raise ToolError(f"--bus-kwarg wants KEY=VALUE, got {item!r}")
        key, value = item.split("=", 1)
        for conv in (int, float):
            try:
                value = conv(value)
                break
            except ValueError:
                pass
        out[key] = value
    return out


def open_bus(interface: str, channel: str, bitrate: Optional[int] = None, **kwargs):
    """Opens a python-can bus. On udp_multicast, frames stay on this host (hop_limit 0)."""
    import can

    if interface == VCAN_INTERFACE:
        kwargs.setdefault("hop_limit", 0)
    if bitrate is not None:
        kwargs["bitrate"] = bitrate
    try:
        return can.Bus(interface=interface, channel=channel, **kwargs)
    except Exception as e:
        hint = ""
        if interface == VCAN_INTERFACE:
            hint = (
                " (is msgpack installed? is there a route for 224.0.0.0/4? "
                "in a private namespace: ip link set lo up; ip route add 224.0.0.0/4 dev lo)"
            )
        raise ToolError(f"cannot open CAN bus {interface}:{channel}: {e}{hint}") from e


def add_bus_arguments(parser) -> None:
    """The bus to open (bus_from_args) and the CAN database that decodes it (--dbc, load_dbc)."""
    parser.add_argument(
        "--interface",
        "-i",
        default=VCAN_INTERFACE,
        help="python-can interface (default udp_multicast: the simulator's bus; "
        "socketcan or slcan for a USB-CAN adapter)",
    )
    parser.add_argument(
        "--channel",
        "-c",
        default=VCAN_CHANNEL,
        help="channel: multicast group, can0, /dev/ttyACM0... (default %(default)s)",
    )
    parser.add_argument(
        "--bitrate",
        type=int_in(1000, 10000000),
        default=None,
        help="bit rate for adapters that need it (the robot's bus: 500000)",
    )
    parser.add_argument(
        "--bus-kwarg",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="extra python-can bus argument, e.g. port=43114 (repeatable)",
    )
    parser.add_argument("--dbc", default=default_dbc_path(), help="CAN database (default %(default)s)")


def bus_from_args(args):
    return open_bus(args.interface, args.channel, args.bitrate, **parse_bus_kwargs(args.bus_kwarg))


def run_main(fn) -> int:
    """Runs a command's body, turning ToolError into a one-line message and exit status 2."""
    try:
        return fn()
    except ToolError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # The reader went away (`... | head`): nothing more to say, and no traceback at exit.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 1


def run_tool(build_parser, run, argv) -> int:
    """The main of a tool whose run(args) returns what it made (the tests read it), not an exit
    status: parses argv with build_parser(), runs, and exits 0, or as run_main says."""
    args = build_parser().parse_args(argv)
    return run_main(lambda: (run(args), 0)[1])


class ToolArgumentParser(argparse.ArgumentParser):
    """argparse with a user error as one line (naming the option) and exit status 2."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def int_in(lo: Optional[int] = None, hi: Optional[int] = None):
    """An argparse type: an integer in [lo, hi]."""

    def conv(text: str) -> int:
        try:
            v = int(text, 0)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            raise argparse.ArgumentTypeError(f"{v} is outside {_range_text(lo, hi)}")
        return v

    return conv


def float_in(lo: Optional[float] = None, hi: Optional[float] = None, lo_open: bool = False, hi_open: bool = False):
    """An argparse type: a finite number in [lo, hi] (open at lo with lo_open, at hi with hi_open)."""

    def conv(text: str) -> float:
        try:
            v = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
        bad = (
            not math.isfinite(v)
            or (lo is not None and (v <= lo if lo_open else v < lo))
            or (hi is not None and (v >= hi if hi_open else v > hi))
        )
        if bad:
            raise argparse.ArgumentTypeError(f"{text} is outside {_range_text(lo, hi, lo_open, hi_open)}")
        return v

    return conv


def _range_text(lo, hi, lo_open: bool = False, hi_open: bool = False) -> str:
    if hi is None:
        return f"{'>' if lo_open else '>='} {lo:g}" if lo is not None else "the range"
    if lo is None:
        return f"{'<' if hi_open else '<='} {hi:g}"
    return f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}"


def crc8_sae_j1850(data: bytes) -> int:
    """CRC-8/SAE-J1850 (poly 0x1D, init 0xFF, xorout 0xFF), the Crc of MOTOR_CMD over
    the id (low byte, high byte) and the data bytes before it (docs/can-protocol.md)."""
    crc = 0xFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1D) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc ^ 0xFF


def tool_cmd_crc(frame_id: int, data: bytes) -> int:
    """TOOL_CMD's Crc: CRC-32 (IEEE 802.3, as zlib) over the identifier (low byte, then high byte)
    and the four data bytes before it (docs/can-protocol.md)."""
    return zlib.crc32(bytes([frame_id & 0xFF, frame_id >> 8]) + bytes(data))
