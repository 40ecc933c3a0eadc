# SPDX-License-Identifier: MIT
"""dynaqpc-operator: command the robot's firmware over CAN, print its answer, read its status.

  start [--heading DEG]   TOOL_CMD START_EPISODE (the robot stands at its start; DEG: its heading
                          for a robot whose pose source has none, e.g. a gyro)
  stop                    STOP: ends the episode, wheels off, mode IDLE
  safe-stop               SAFE_STOP: wheels off, mode SAFE_STOP until the next start or stop
  save                    SAVE_LEARNED: what the agent learned into flash (the answer names the
                          record written: its sequence number and episodes)
  reset [--yes]           RESET_LEARNING: the agent starts from scratch (a stopped robot only).
                          Learning saved since boot or restored at boot is wiped only with
                          --yes; the firmware saves what it wipes first, and restore-previous
                          brings it back
  restore-previous        RESTORE_PREVIOUS: undoes a reset (a stopped robot only): the learning
                          it wiped back into the agent, also after saves of the new learning;
                          without a reset, the record before the newest
  status                  FW_STATUS decoded by name: mode, every error flag, uptime
  ping                    NOP: the firmware answers with the newest record in flash and the
                          episodes learned so far
  watch                   every command on the bus, its answer and each change of mode, as
                          they happen (until Ctrl-C or --duration)

The firmware answers every command with TOOL_ACK (docs/can-protocol.md "Answers"): done,
refused (evaluate mode, not idle, busy, needs --yes, no previous record, a device silent) or
failed (no flash, flash error), with the record's sequence number for save and restore-previous.
The tool prints the answer, then, for a command that changes the mode, waits (--timeout) for the
FW_STATUS that shows it. A command refused as busy (a robot that stands between actions saves
only while standing) or for a silent device (a start while the gyro, the range sensors or the
motor controller is not heard) is sent again until it is taken or --timeout passes; a command not answered within
1 s is sent again with the same counter (the firmware answers a repeat with its last answer and
never acts on it twice).

Exit status: 0 done, 1 refused, failed, no answer (the firmware is silent) or FAULT, 2 a usage or
bus error. --json prints one JSON object instead (watch: one per line).

Counters: the firmware refuses a TOOL_CMD whose Counter equals the last one it accepted (a
stuck sender; it answers such a repeat with its last answer again). A one-shot tool cannot know
that counter, so every command goes as two frames: a NOP with counter k, then the command with
k + 1. If k was the firmware's last counter the NOP is refused and the command accepted;
otherwise both are accepted. The command is never refused as a repeat and never runs twice.
"""

from __future__ import annotations

import argparse
import json
import random
import sys
import time
from typing import Dict, Optional

from .bus_decode import decode_frame
from .common import (
    ToolArgumentParser,
    ToolError,
    add_bus_arguments,
    bus_from_args,
    float_in,
    load_dbc,
    run_main,
    tool_cmd_crc,
)

COMMANDS = {
    "start": "START_EPISODE",
    "stop": "STOP",
    "safe-stop": "SAFE_STOP",
    "save": "SAVE_LEARNED",
    "reset": "RESET_LEARNING",
    "restore-previous": "RESTORE_PREVIOUS",
    "ping": "NOP",
}
#: The mode a command leaves the firmware in, as FW_STATUS names it (None: any).
EXPECT = {
    "start": "RUNNING",
    "stop": "IDLE",
    "safe-stop": "SAFE_STOP",
    "save": None,
    "reset": "IDLE",
    "restore-previous": None,
    "ping": None,
}
KEEP_HEADING = 0xFFFFFF
RESET_CONFIRM = 1  # RESET_LEARNING's Argument: wipe even learning saved since boot or restored at boot
RESEND_S = 1.0  # no answer for this long: the command frame again (same counter)

#: What each TOOL_ACK Reason means to the operator.
REASONS = {
    "NONE": "",
    "EVALUATE_MODE": "the firmware runs in evaluate mode, which locks what was learned",
    "NOT_IDLE": "the robot is not stopped: `dynaqpc-operator stop` first",
    "BUSY": "the robot is driving an action (it writes flash only while standing still), or it rebooted and its wheels"
    " have not yet reported still (it takes a heading only then)",
    "CONFIRM": (
        "learning was saved since boot or restored at boot: `dynaqpc-operator reset --yes` wipes it "
        "(saving it first: `dynaqpc-operator restore-previous` brings it back)"
    ),
    "NO_STORE": "the firmware has no flash store",
    "FLASH_ERROR": "erasing or programming the flash failed (FW_STATUS raises Flash)",
    "NO_ROOM": "the record does not fit a flash slot",
    "NO_PREVIOUS": "the flash holds no previous record of this agent's layout",
    "MALFORMED": "the firmware read a bad Crc or an unknown command",
    "RECORD_DAMAGED": "the previous record is damaged or fails its checks; nothing was changed",
    "DEVICE_SILENT": "a device the robot drives on is silent: the motor controller, the range sensors or the gyro"
    " (`dynaqpc-operator status` names it under errors); nothing was changed",
}
#: Refusals that pass by themselves: the command is sent again until --timeout.
RETRY_REASONS = ("BUSY", "DEVICE_SILENT")


def tool_cmd_frame(db, command: str, argument: int, counter: int):
    """One TOOL_CMD frame with its CRC, as (id, data)."""
    m = db.get_message_by_name("TOOL_CMD")
    data = bytearray(
        m.encode({"Command": command, "Argument": min(argument, 0xFFFFFF), "Counter": counter % 16, "Crc": 0})
    )
    data[4:8] = tool_cmd_crc(m.frame_id, bytes(data[:4])).to_bytes(4, "little")
    return m.frame_id, bytes(data)


def tool_cmd_frames(db, command: str, argument: int = 0, counter: Optional[int] = None):
    """The two TOOL_CMD frames (NOP with counter k, the command with k + 1) as (id, data)."""
    k = random.randrange(16) if counter is None else counter % 16
    return [tool_cmd_frame(db, "NOP", 0, k), tool_cmd_frame(db, command, argument, (k + 1) % 16)]


def decode_status(db, data: bytes) -> Dict[str, object]:
    """FW_STATUS with names: {'mode': 'RUNNING', 'uptime_s': 12, 'errors': {'MotorSilent': 0, ...}}."""
    m = db.get_message_by_name("FW_STATUS")
    v = decode_frame(m, data, decode_choices=True)
    errors = {k[3:]: int(val) for k, val in v.items() if k.startswith("Err")}
    return {
        "mode": str(v["Mode"]),
        "uptime_s": int(v["Uptime"]),
        "errors": errors,
        "pose_trusted": int(v.get("PoseTrusted", 0)),
        "trust_reason": str(v.get("TrustReason", "")),
        "reset_cause": str(v.get("ResetCause", "")),
        "boot_count": int(v.get("BootCount", 0)),
    }


def decode_ack(db, data: bytes) -> Dict[str, object]:
    """TOOL_ACK with names: {'command': 'SAVE_LEARNED', 'counter': 5, 'result': 'DONE', ...}."""
    m = db.get_message_by_name("TOOL_ACK")
    v = decode_frame(m, data, decode_choices=True)
    return {
        "command": str(v["Command"]),
        "counter": int(v["Counter"]),
        "result": str(v["Result"]),
        "reason": str(v["Reason"]),
        "sequence": int(v["Sequence"]),
        "episodes": int(v["Episodes"]),
    }


def decode_cmd(db, data: bytes) -> Dict[str, object]:
    m = db.get_message_by_name("TOOL_CMD")
    v = decode_frame(m, data, decode_choices=True)
    return {"command": str(v["Command"]), "counter": int(v["Counter"]), "argument": int(v["Argument"])}


def ack_text(ack: Dict[str, object]) -> str:
    """One line: 'SAVE_LEARNED: done, record 3 written (157 episodes)'."""
    cmd, result, reason = ack["command"], ack["result"], ack["reason"]
    if result == "DONE":
        if cmd == "SAVE_LEARNED":
            detail = f", record {ack['sequence']} written ({ack['episodes']} episodes)"
        elif cmd == "RESTORE_PREVIOUS":
            detail = f", record {ack['sequence']} restored ({ack['episodes']} episodes) and saved as the newest"
        elif cmd == "RESET_LEARNING":
            newest = ack["sequence"]
            detail = (
                f"; what it wiped is record {newest} in flash (`dynaqpc-operator restore-previous` brings it back)"
                if newest
                else ""
            )
        elif cmd == "NOP":
            detail = f", newest record in flash {ack['sequence'] or 'none'}, {ack['episodes']} episodes learned"
        else:
            detail = ""
        return f"{cmd}: done{detail}"
    why = REASONS.get(reason, reason)
    return f"{cmd}: {result.lower()}, {reason}: {why}"


def status_text(st: Dict[str, object]) -> str:
    errs = st["errors"]
    raised = [k for k, val in errs.items() if val]
    trust = "trusted" if st.get("pose_trusted") else "NOT trusted"
    return (
        f"mode {st['mode']}, uptime {st['uptime_s']} s, pose {trust} ({st.get('trust_reason', '?')}), "
        f"boot {st.get('boot_count', '?')}, reset cause {st.get('reset_cause', '?')}, errors: "
        f"{', '.join(raised) if raised else 'none'}\n  " + " ".join(f"{k}={val}" for k, val in errs.items())
    )


def _frames(bus, deadline: float):
    """Standard data frames received until `deadline` (monotonic), as (id, data)."""
    while True:
        left = deadline - time.monotonic()
        if left <= 0:
            return
        msg = bus.recv(timeout=min(left, 0.2))
        if msg is None or msg.is_extended_id or msg.is_error_frame or getattr(msg, "is_remote_frame", False):
            continue
        yield msg.arbitration_id, bytes(msg.data)


def wait_status(bus, db, timeout_s: float, want_mode: Optional[str] = None, after: float = 0.0):
    """The first FW_STATUS (received after `after`, monotonic) whose mode is want_mode (any if
    None), or the last one seen, or None when the firmware stayed silent."""
    fid = db.get_message_by_name("FW_STATUS").frame_id
    last = None
    for fid_rx, data in _frames(bus, time.monotonic() + timeout_s):
        if fid_rx != fid:
            continue
        try:
            st = decode_status(db, data)
        except Exception:  # a frame with our id that does not decode is not the firmware's
            continue
        if time.monotonic() < after:
            continue
        last = st
        if want_mode is None or st["mode"] == want_mode:
            return st
    return last


def wait_ack(bus, db, command: str, counter: int, timeout_s: float):
    """The TOOL_ACK answering `command` sent with `counter`, or None within timeout_s."""
    fid = db.get_message_by_name("TOOL_ACK").frame_id
    for fid_rx, data in _frames(bus, time.monotonic() + timeout_s):
        if fid_rx != fid:
            continue
        try:
            ack = decode_ack(db, data)
        except Exception:
            continue
        if ack["command"] == command and ack["counter"] == counter % 16:
            return ack
    return None


def _send(bus, fid: int, data: bytes) -> None:
    import can

    try:
        bus.send(can.Message(arbitration_id=fid, is_extended_id=False, data=data))
    except Exception as e:
        raise ToolError(f"cannot send TOOL_CMD: {e}") from None


class Report:
    """What the command printed, as lines or (--json) one object."""

    def __init__(self, out, as_json: bool):
        self.out, self.as_json, self.obj = out, as_json, {}

    def line(self, text: str) -> None:
        if not self.as_json:
            print(text, file=self.out)

    def text(self, text: str) -> None:
        """The command's outcome in words: the line printed, and the JSON's "text"."""
        self.obj["text"] = text
        self.line(text)

    def silent(self, waited_for: str, timeout: float, tail: str = "") -> int:
        """No answer came: says so (exit status 1)."""
        self.text(
            f"no {waited_for} within {timeout:g} s: the firmware is silent (is dynaqpc-fw running on this bus?){tail}"
        )
        return self.done(1)

    def done(self, rc: int) -> int:
        if self.as_json:
            self.obj["exit"] = rc
            print(json.dumps(self.obj), file=self.out)
        return rc


def command(bus, db, args, out) -> int:
    rep = Report(out, args.json)
    name = COMMANDS[args.command]
    argument = 0
    if args.command == "start":
        argument = KEEP_HEADING if args.heading is None else int(round(args.heading * 100)) % 36000
    elif args.command == "reset" and args.yes:
        argument = RESET_CONFIRM
    rep.obj.update(command=args.command, frame=name, argument=argument)
    k = random.randrange(16)
    frames = tool_cmd_frames(db, name, argument, counter=k)
    for fid, data in frames:
        _send(bus, fid, data)
    counter = (k + 1) % 16
    sent = time.monotonic()
    rep.line(
        f"sent TOOL_CMD {name}"
        + (f" heading {args.heading:g} deg" if args.command == "start" and args.heading is not None else "")
        + (" (confirmed: --yes)" if args.command == "reset" and args.yes else "")
    )
    if args.no_wait:
        return rep.done(0)
    deadline = sent + args.timeout
    ack, busy, retries, resent = None, None, 0, 0
    while True:
        left = deadline - time.monotonic()
        if left <= 0:
            break
        ack = wait_ack(bus, db, name, counter, min(left, RESEND_S))
        if ack is None:
            # A frame lost either way: the same frame again. The firmware acts on it if it had
            # not, and answers a repeat with its last answer, so it never runs twice.
            if time.monotonic() < deadline:
                _send(bus, *tool_cmd_frame(db, name, argument, counter))
                resent += 1
            continue
        if ack["reason"] not in RETRY_REASONS or time.monotonic() >= deadline:
            break
        time.sleep(0.1)  # a robot standing between actions: the next control period or so
        counter = (counter + 1) % 16  # the last counter the firmware took + 1: accepted
        _send(bus, *tool_cmd_frame(db, name, argument, counter))
        retries += 1
        busy, ack = ack, None
    if ack is None and retries:
        ack = busy  # still busy when --timeout passed
    rep.obj.update(
        answer=ack,
        retries=retries,
        resent=resent,
        answer_ms=round((time.monotonic() - sent) * 1000.0, 1) if ack is not None else None,
    )
    if ack is None:
        return rep.silent("answer (TOOL_ACK)", args.timeout, " or predates answers")
    rep.text(ack_text(ack) + (f" (sent {retries + 1} times while busy)" if retries else ""))
    if ack["result"] != "DONE":
        return rep.done(1)
    want = EXPECT[args.command]
    st = wait_status(bus, db, max(args.timeout, 1.5), want, after=sent)
    rep.obj["status"] = st
    if st is None:
        rep.line(f"no FW_STATUS within {args.timeout:g} s: the firmware is silent")
        return rep.done(1)
    rep.line(f"FW_STATUS: {status_text(st)}")
    if want is not None and st["mode"] != want:
        rep.line(f"the firmware did not reach {want} within {args.timeout:g} s")
        return rep.done(1)
    return rep.done(1 if st["mode"] == "FAULT" else 0)


def watch(bus, db, args, out) -> int:
    """Commands, answers and mode changes as they pass on the bus."""
    ids = {db.get_message_by_name(n).frame_id: n for n in ("TOOL_CMD", "TOOL_ACK", "FW_STATUS")}
    t0 = time.monotonic()
    deadline = t0 + args.duration if args.duration else float("inf")
    mode = None
    if not args.json:
        print("watching TOOL_CMD, TOOL_ACK and FW_STATUS's mode (Ctrl-C ends)", file=out, flush=True)
    while time.monotonic() < deadline:
        for fid, data in _frames(bus, min(deadline, time.monotonic() + 1.0)):
            name = ids.get(fid)
            if name is None:
                continue
            t = time.monotonic() - t0
            try:
                if name == "TOOL_CMD":
                    v = decode_cmd(db, data)
                    line = f"TOOL_CMD {v['command']} counter {v['counter']} argument {v['argument']:#x}"
                elif name == "TOOL_ACK":
                    v = decode_ack(db, data)
                    line = f"TOOL_ACK counter {v['counter']}: {ack_text(v)}"
                else:
                    v = decode_status(db, data)
                    if v["mode"] == mode:
                        continue
                    line = f"FW_STATUS mode {mode or '?'} -> {v['mode']}"
                    mode = v["mode"]
            except Exception:
                line, v = f"{name} undecodable: {data.hex()}", {"data": data.hex()}
            if args.json:
                print(json.dumps({"t": round(t, 3), "frame": name, **v}), file=out, flush=True)
            else:
                print(f"{t:8.3f}  {line}", file=out, flush=True)
    return 0


def run(args, out=None) -> int:
    out = out or sys.stdout
    db = load_dbc(args.dbc)
    try:
        db.get_message_by_name("TOOL_ACK")
    except KeyError:
        raise ToolError(f"{args.dbc}: no TOOL_ACK frame: an older DBC than this tool") from None
    bus = bus_from_args(args)
    try:
        if args.command == "watch":
            return watch(bus, db, args, out)
        if args.command == "status":
            rep = Report(out, args.json)
            st = wait_status(bus, db, args.timeout)
            rep.obj.update(command="status", status=st)
            if st is None:
                return rep.silent("FW_STATUS", args.timeout)
            rep.line(f"FW_STATUS: {status_text(st)}")
            return rep.done(1 if st["mode"] == "FAULT" else 0)
        return command(bus, db, args, out)
    finally:
        bus.shutdown()


def build_parser() -> argparse.ArgumentParser:
    common = argparse.ArgumentParser(add_help=False)
    add_bus_arguments(common)
    common.add_argument("--json", action="store_true", help="print one JSON object (watch: one per line)")
    timed = argparse.ArgumentParser(add_help=False)
    timed.add_argument(
        "--timeout",
        type=float_in(0, 3600, lo_open=True),
        default=3.0,
        help="seconds to wait for the answer and FW_STATUS (sent every second; default %(default)s)",
    )
    cmd = argparse.ArgumentParser(add_help=False)
    cmd.add_argument("--no-wait", action="store_true", help="send the command and return")
    p = ToolArgumentParser(
        prog="dynaqpc-operator", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("start", help="start an episode", parents=[common, timed, cmd])
    s.add_argument(
        "--heading",
        type=float_in(0, 360, hi_open=True),
        default=None,
        metavar="DEG",
        help="the robot's heading at the start, 0 <= DEG < 360 (default: keep the firmware's)",
    )
    r = sub.add_parser("reset", help="forget what was learned (a stopped robot)", parents=[common, timed, cmd])
    r.add_argument(
        "--yes",
        action="store_true",
        help="wipe even learning saved since boot or restored at boot (restore-previous brings it back)",
    )
    for name, text in (
        ("stop", "end the episode, wheels off"),
        ("safe-stop", "wheels off until the next start"),
        ("save", "save what was learned to flash"),
        ("restore-previous", "undo a reset: the learning it wiped back (else the record before the newest)"),
        ("ping", "NOP: answered with the newest record in flash and the episodes learned"),
    ):
        sub.add_parser(name, help=text, parents=[common, timed, cmd])
    sub.add_parser("status", help="print FW_STATUS by name", parents=[common, timed])
    w = sub.add_parser("watch", help="print commands, answers and mode changes as they pass", parents=[common])
    w.add_argument(
        "--duration",
        type=float_in(0, 10**6, lo_open=True),
        default=None,
        metavar="S",
        help="stop after S seconds (default: until Ctrl-C)",
    )
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    return run_main(lambda: run(args))


if __name__ == "__main__":
    sys.exit(main())
