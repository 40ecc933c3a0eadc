# SPDX-License-Identifier: MIT
"""dynaqpc-operator: command the robot's firmware over CAN and read its status.

  start [--heading DEG]   TOOL_CMD START_EPISODE (the robot stands at its start; DEG: its heading
                          for a robot whose pose source has none, e.g. a gyro)
  stop                    STOP: ends the episode, wheels off, mode IDLE
  safe-stop               SAFE_STOP: wheels off, mode SAFE_STOP until the next start or stop
  save                    SAVE_LEARNED: what the agent learned into flash
  reset                   RESET_LEARNING: the agent starts from scratch (and stops)
  status                  FW_STATUS decoded by name: mode, every error flag, uptime

A command waits (--timeout) for the FW_STATUS that shows it took effect: start RUNNING, stop
IDLE, safe-stop SAFE_STOP, reset IDLE, save: any status after it. Exit status: 0 done, 1 the
firmware is silent, in FAULT or did not take the command, 2 a usage or bus error.

Counters: the firmware refuses a TOOL_CMD whose Counter equals the last one it accepted (a
stuck sender). A one-shot tool cannot know that counter, so every command goes as two frames:
a NOP with counter k, then the command with k + 1. If k was the firmware's last counter the
NOP is refused and the command accepted; otherwise both are accepted. The command is never
refused and never runs twice.
"""

from __future__ import annotations

import argparse
import random
import sys
import time
from typing import Dict, Optional

from .common import (ToolArgumentParser, ToolError, add_bus_arguments, bus_from_args, crc8_sae_j1850,
                     default_dbc_path, float_in, load_dbc, run_main)

COMMANDS = {"start": "START_EPISODE", "stop": "STOP", "safe-stop": "SAFE_STOP", "save": "SAVE_LEARNED",
            "reset": "RESET_LEARNING"}
#: The mode a command leaves the firmware in, as FW_STATUS names it (None: any).
EXPECT = {"start": "RUNNING", "stop": "IDLE", "safe-stop": "SAFE_STOP", "save": None, "reset": "IDLE"}
KEEP_HEADING = 0xFFFFFFFF


def tool_cmd_frames(db, command: str, argument: int = 0, counter: Optional[int] = None):
    """The two TOOL_CMD frames (NOP with counter k, the command with k + 1) as (id, data)."""
    m = db.get_message_by_name("TOOL_CMD")
    k = random.randrange(16) if counter is None else counter % 16
    frames = []
    for cmd, arg, c in (("NOP", 0, k), (command, argument, (k + 1) % 16)):
        data = bytearray(m.encode({"Command": cmd, "Argument": arg, "Counter": c, "Crc": 0}))
        data[-1] = crc8_sae_j1850(bytes([m.frame_id & 0xFF, m.frame_id >> 8]) + bytes(data[:-1]))
        frames.append((m.frame_id, bytes(data)))
    return frames


def decode_status(db, data: bytes) -> Dict[str, object]:
    """FW_STATUS with names: {'mode': 'RUNNING', 'uptime_s': 12, 'errors': {'MotorSilent': 0, ...}}."""
    m = db.get_message_by_name("FW_STATUS")
    v = m.decode(data, decode_choices=True)
    errors = {k[3:]: int(val) for k, val in v.items() if k.startswith("Err")}
    return {"mode": str(v["Mode"]), "uptime_s": int(v["Uptime"]), "errors": errors}


def status_text(st: Dict[str, object]) -> str:
    errs = st["errors"]
    raised = [k for k, val in errs.items() if val]
    return (f"mode {st['mode']}, uptime {st['uptime_s']} s, errors: "
            f"{', '.join(raised) if raised else 'none'}\n  "
            + " ".join(f"{k}={val}" for k, val in errs.items()))


def wait_status(bus, db, timeout_s: float, want_mode: Optional[str] = None, after: float = 0.0):
    """The first FW_STATUS (received after `after`, monotonic) whose mode is want_mode (any if
    None), or the last one seen, or None when the firmware stayed silent."""
    fid = db.get_message_by_name("FW_STATUS").frame_id
    deadline = time.monotonic() + timeout_s
    last = None
    while True:
        left = deadline - time.monotonic()
        if left <= 0:
            return last
        msg = bus.recv(timeout=min(left, 0.2))
        if msg is None or msg.arbitration_id != fid or msg.is_extended_id or msg.is_error_frame:
            continue
        try:
            st = decode_status(db, bytes(msg.data))
        except Exception:  # a frame with our id that does not decode is not the firmware's
            continue
        if time.monotonic() < after:
            continue
        last = st
        if want_mode is None or st["mode"] == want_mode:
            return st


def run(args, out=None) -> int:
    import can

    out = out or sys.stdout
    db = load_dbc(args.dbc)
    bus = bus_from_args(args)
    try:
        if args.command == "status":
            st = wait_status(bus, db, args.timeout)
            if st is None:
                print(f"no FW_STATUS within {args.timeout:g} s: the firmware is silent "
                      "(is dynaqpc-fw running on this bus?)", file=out)
                return 1
            print(f"FW_STATUS: {status_text(st)}", file=out)
            return 1 if st["mode"] == "FAULT" else 0
        argument = 0
        if args.command == "start":
            argument = KEEP_HEADING if args.heading is None else int(round(args.heading * 100)) % 36000
        for fid, data in tool_cmd_frames(db, COMMANDS[args.command], argument):
            try:
                bus.send(can.Message(arbitration_id=fid, is_extended_id=False, data=data))
            except Exception as e:
                raise ToolError(f"cannot send TOOL_CMD: {e}") from None
        sent = time.monotonic()
        print(f"sent TOOL_CMD {COMMANDS[args.command]}" + (
            f" heading {args.heading:g} deg" if args.command == "start" and args.heading is not None else ""),
            file=out)
        if args.no_wait:
            return 0
        want = EXPECT[args.command]
        st = wait_status(bus, db, args.timeout, want, after=sent)
        if st is None:
            print(f"no FW_STATUS within {args.timeout:g} s: the firmware is silent", file=out)
            return 1
        print(f"FW_STATUS: {status_text(st)}", file=out)
        if want is not None and st["mode"] != want:
            print(f"the firmware did not reach {want} within {args.timeout:g} s", file=out)
            return 1
        return 1 if st["mode"] == "FAULT" else 0
    finally:
        bus.shutdown()


def build_parser() -> argparse.ArgumentParser:
    common = argparse.ArgumentParser(add_help=False)
    add_bus_arguments(common)
    common.add_argument("--dbc", default=default_dbc_path(), help="CAN database (default %(default)s)")
    common.add_argument("--timeout", type=float_in(0, 3600, lo_open=True), default=3.0,
                        help="seconds to wait for FW_STATUS (sent every second; default %(default)s)")
    common.add_argument("--no-wait", action="store_true", help="send the command and return")
    p = ToolArgumentParser(prog="dynaqpc-operator", description=__doc__,
                           formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("start", help="start an episode", parents=[common])
    s.add_argument("--heading", type=float_in(0, 360), default=None, metavar="DEG",
                   help="the robot's heading at the start, 0 <= DEG < 360 (default: keep the firmware's)")
    for name, text in (("stop", "end the episode, wheels off"), ("safe-stop", "wheels off until the next start"),
                       ("save", "save what was learned to flash"), ("reset", "forget what was learned"),
                       ("status", "print FW_STATUS by name")):
        sub.add_parser(name, help=text, parents=[common])
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    if getattr(args, "heading", None) is not None and args.heading >= 360:
        print("dynaqpc-operator: error: --heading: 360 is outside [0, 360)", file=sys.stderr)
        return 2
    return run_main(lambda: run(args))


if __name__ == "__main__":
    sys.exit(main())
