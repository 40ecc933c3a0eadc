# SPDX-License-Identifier: MIT
"""The emulated robot board in closed loop: the firmware image on QEMU's netduinoplus2
(hal/ports/stm32f4/boards/netduinoplus2), the simulated robot's devices (`dynaqpc-sim
devices`) and a bridge between them.

    dynaqpc-emu bridge --slcan /dev/pts/N        the bridge alone
    dynaqpc-emu run [--elf F] [--sim S] ...      QEMU + devices + bridge, one command

The board sends and receives CAN frames as SLCAN (Lawicel) lines on its USART1; the bridge reads
them with python-can's `slcan` interface and puts them on the project's virtual CAN bus (python-can
`udp_multicast`, where `dynaqpc-sim devices` is), and the devices' frames the other way. The
Cricket listener's lines need no bridge: QEMU opens the devices' Cricket pty as the board's USART2.

`run` reports, per run, the firmware's own counters: from the bus (TLM_SCHED: planning updates,
deadline misses, idle share; TLM_EPISODE) and from the board's console (its report lines over
semihosting: real steps, planning updates and the idle loop's share, the control task's worst run,
events dropped, the stack's unused bytes). Exit 0 when the checks pass, 1 when one fails
(no frames, no planning update, a deadline miss, a hard fault, too few episodes), 2 on a usage
or setup error.
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import subprocess
import sys
import threading
import time
from typing import Dict, List, Optional

from . import agents as registry
from .common import VCAN_CHANNEL, VCAN_INTERFACE, ToolError, default_dbc_path, load_dbc, open_bus, repo_root, run_main

FW_SENDER = "FW"


class Bridge:
    """Forwards frames between the board's SLCAN serial line and the virtual CAN bus, one thread
    each way. Frames the firmware sends are not sent back to it (the bus echoes a member's own
    datagrams)."""

    def __init__(self, slcan_channel: str, dbc_path: str, vcan_channel: str = VCAN_CHANNEL):
        db = load_dbc(dbc_path)
        self.fw_ids = {m.frame_id for m in db.messages if FW_SENDER in m.senders}
        self.slcan = open_bus("slcan", slcan_channel, bitrate=500000, sleep_after_open=0)
        self.vcan = open_bus(VCAN_INTERFACE, vcan_channel)
        self.to_bus = 0  # frames from the firmware put on the bus
        self.to_board = 0  # frames from the bus written to the board
        self.errors = 0
        self.last_error = ""
        self._stop = threading.Event()
        self._threads = [
            threading.Thread(target=self._board_to_bus, daemon=True),
            threading.Thread(target=self._bus_to_board, daemon=True),
        ]

    def start(self) -> "Bridge":
        for t in self._threads:
            t.start()
        return self

    def _board_to_bus(self) -> None:
        while not self._stop.is_set():
            try:
                msg = self.slcan.recv(timeout=0.05)
            except Exception as e:  # the pty closed: QEMU ended
                if not self._stop.is_set():
                    self._error("reading the board's SLCAN line", e)
                    time.sleep(0.05)
                continue
            if msg is None:
                continue
            try:
                self.vcan.send(msg)
                self.to_bus += 1
            except Exception as e:
                self._error("sending to the bus", e)

    def _bus_to_board(self) -> None:
        while not self._stop.is_set():
            try:
                msg = self.vcan.recv(timeout=0.05)
            except Exception as e:
                if not self._stop.is_set():
                    self._error("reading the bus", e)
                continue
            if msg is None or msg.is_extended_id or msg.arbitration_id in self.fw_ids:
                continue
            try:
                self.slcan.send(msg)
                self.to_board += 1
            except Exception as e:
                if not self._stop.is_set():
                    self._error("writing to the board's SLCAN line", e)

    def _error(self, doing: str, e: Exception) -> None:
        self.errors += 1
        self.last_error = f"{doing}: {e}"

    def closing(self) -> None:
        """The run is ending: QEMU and the devices are about to stop; what fails now is not an error."""
        self._stop.set()

    def stop(self) -> None:
        self._stop.set()
        for t in self._threads:
            t.join(timeout=1.0)
        for bus in (self.slcan, self.vcan):
            try:
                bus.shutdown()
            except Exception:
                pass


class Watcher:
    """A daemon thread that runs the subclass's _run() until stop(): BusWatch's and HostProbe's
    life (start() returns the watcher, stop() waits up to 1 s for the thread)."""

    def __init__(self):
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def start(self):
        self._thread.start()
        return self

    def _run(self) -> None:
        raise NotImplementedError

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=1.0)


class BusWatch(Watcher):
    """Counts the firmware's telemetry on the virtual bus: TLM_SCHED, FW_STATUS, TLM_EPISODE."""

    def __init__(self, dbc_path: str):
        self.db = load_dbc(dbc_path)
        self.ids = {n: self.db.get_message_by_name(n).frame_id for n in ("TLM_SCHED", "FW_STATUS", "TLM_EPISODE")}
        self.bus = open_bus(VCAN_INTERFACE, VCAN_CHANNEL)
        self.frames = 0
        self.sched = 0
        self.sched_planning = 0
        self.plan_updates = 0
        self.deadline_misses = 0
        self.idle_percent: List[float] = []
        self.status = 0
        self.episodes: List[dict] = []
        super().__init__()

    def _run(self) -> None:
        while not self._stop.is_set():
            msg = self.bus.recv(timeout=0.1)
            if msg is None or msg.is_extended_id:
                continue
            i = msg.arbitration_id
            if i == self.ids["TLM_SCHED"]:
                self.frames += 1
                s = self.db.decode_message(i, msg.data, decode_choices=False)
                self.sched += 1
                self.plan_updates += int(s["PlanUpdates"])
                self.sched_planning += int(s["PlanUpdates"]) > 0
                self.deadline_misses = max(self.deadline_misses, int(s["DeadlineMisses"]))
                self.idle_percent.append(float(s["IdlePercent"]))
            elif i == self.ids["FW_STATUS"]:
                self.frames += 1
                self.status += 1
            elif i == self.ids["TLM_EPISODE"]:
                self.frames += 1
                e = self.db.decode_message(i, msg.data, decode_choices=False)
                self.episodes.append({k: int(v) for k, v in e.items()})

    def stop(self) -> None:
        super().stop()
        self.bus.shutdown()


REPORT_RE = re.compile(r"^(report|final): (.*)$")
PTY_RE = re.compile(r"char device redirected to (\S+) \(label (\S+)\)")
# `dynaqpc-sim devices` names its seed (with --set K, the set's) on its ready line.
SEED_RE = re.compile(r"seed=(\d+); ready")


def parse_report(line: str) -> Optional[Dict[str, int]]:
    m = REPORT_RE.match(line.strip())
    if not m:
        return None
    out = {}
    for kv in m.group(2).split():
        k, _, v = kv.partition("=")
        if v.isdigit():
            out[k] = int(v)
    return out


def _default_elf() -> str:
    root = repo_root()
    for rel in ("build/cortex-m4/netduinoplus2/bin", "build/netduinoplus2/bin"):
        p = os.path.join(str(root or "."), rel, "dynaqpc-emu-paper-lab.elf")
        if os.path.isfile(p):
            return p
    return os.path.join(str(root or "."), "build/cortex-m4/netduinoplus2/bin/dynaqpc-emu-paper-lab.elf")


def _default_sim() -> str:
    root = str(repo_root() or ".")
    for rel in ("build/host-release/bin", "build/host/bin", "build/cortex-m4/host-sim/bin"):
        p = os.path.join(root, rel, "dynaqpc-sim")
        if os.access(p, os.X_OK):
            return p
    return "dynaqpc-sim"


class Lines:
    """A child's output lines, read by a thread, kept and optionally echoed with a prefix."""

    def __init__(self, proc: subprocess.Popen, prefix: str, echo: bool):
        self.proc, self.prefix, self.echo = proc, prefix, echo
        self.lines: List[str] = []
        self.times: List[float] = []  # time.monotonic() at each line's arrival
        self._cv = threading.Condition()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        for raw in iter(self.proc.stdout.readline, b""):
            line = raw.decode(errors="replace").rstrip("\n")
            with self._cv:
                self.lines.append(line)
                self.times.append(time.monotonic())
                self._cv.notify_all()
            if self.echo:
                print(f"{self.prefix}{line}", flush=True)

    def wait_for(self, pattern: re.Pattern, timeout: float) -> Optional[re.Match]:
        deadline = time.monotonic() + timeout
        seen = 0
        with self._cv:
            while True:
                for line in self.lines[seen:]:
                    m = pattern.search(line)
                    if m:
                        return m
                seen = len(self.lines)
                left = deadline - time.monotonic()
                if left <= 0 or self.proc.poll() is not None and seen == len(self.lines):
                    return None
                self._cv.wait(timeout=min(left, 0.2))


def _stop(proc: Optional[subprocess.Popen]) -> Optional[int]:
    if proc is None:
        return None
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
        try:
            proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
    return proc.returncode


class HostProbe(Watcher):
    """How late the host wakes a sleeping thread: a 5 ms sleep, again and again, and how much
    longer each took. A host that cannot keep this process's timers cannot keep QEMU's vCPU or
    the devices on time either."""

    PERIOD_S = 0.005

    def __init__(self):
        self.late_ms: List[float] = []
        super().__init__()

    def _run(self) -> None:
        while not self._stop.is_set():
            t0 = time.monotonic()
            time.sleep(self.PERIOD_S)
            self.late_ms.append(max(0.0, (time.monotonic() - t0 - self.PERIOD_S) * 1000.0))

    def percentile(self, q: float) -> float:
        if not self.late_ms:
            return 0.0
        s = sorted(self.late_ms)
        return s[min(len(s) - 1, int(q / 100.0 * len(s)))]


#: The control period (ms of firmware time) and the lateness a period tolerates (10 %).
CONTROL_PERIOD_MS = 192.0
TOLERANCE_MS = 19.2


def speeds() -> List[int]:
    """The speeds the board takes: the divisors of 168 (its MHz)."""
    return [s for s in range(1, 169) if 168 % s == 0]


def emulated_rate(board: "Lines") -> Optional[float]:
    """Firmware seconds per wall second between the board's first and last report lines, or None
    with fewer than two."""
    pts = [
        (board.times[i], r["t_ms"])
        for i, r in ((i, parse_report(ln)) for i, ln in enumerate(board.lines))
        if r and "t_ms" in r and i < len(board.times)
    ]
    if len(pts) < 2 or pts[-1][0] - pts[0][0] < 1.0:
        return None
    return (pts[-1][1] - pts[0][1]) / 1000.0 / (pts[-1][0] - pts[0][0])


def behind(speed: int, rate: Optional[float], late_ms: float, misses: int) -> Optional[str]:
    """Whether the emulation fell behind the requested speed, and what to try: the host's time
    against the emulated time (with -icount QEMU's clock slows when its vCPU is starved), or the
    host waking this process (late_ms: its worst wake-up) later than a control period tolerates
    at that speed while the board missed deadlines."""
    slow_clock = rate is not None and rate < 0.9 * speed
    # At speed X a control period lasts 192/X ms of wall time and tolerates 19.2/X ms of lateness.
    late_host = misses > 0 and late_ms > TOLERANCE_MS / speed
    late_p99_ms = late_ms
    if not (slow_clock or late_host):
        return None
    fits = [
        s
        for s in speeds()
        if s <= speed
        and (not late_host or late_p99_ms <= TOLERANCE_MS / s)
        and (rate is None or not slow_clock or s <= 0.8 * rate)
    ]
    suggest = max(fits) if fits else None
    parts = []
    if slow_clock:
        parts.append(
            f"the board's clock ran {rate:.2f} s per wall second, not the {speed} asked for "
            f"(QEMU's vCPU got too little of the host)"
        )
    if late_host:
        parts.append(
            f"the host woke this process's 5 ms timers up to {late_p99_ms:.0f} ms late, "
            f"more than the {TOLERANCE_MS / speed:.1f} ms a control period tolerates at --speed {speed}"
        )
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else 0.0
    msg = (
        "the emulation fell behind: "
        + "; ".join(parts)
        + f" (load average {load:.1f} on {os.cpu_count()} cores): the host, not the firmware, was late"
    )
    if misses:
        msg += f", and the board's {misses} deadline misses follow from that"
    if suggest is not None and suggest < speed:
        msg += f"; try --speed {suggest}, or a quieter host"
    else:
        msg += "; run it on a quieter host (nothing else busy: docs/results/emulated-board.md)"
    return msg


def cmd_run(args) -> int:
    if not os.path.isfile(args.elf):
        raise ToolError(f"--elf {args.elf}: no such image (build the cortex-m4 preset)")
    sim = args.sim
    if not (os.access(sim, os.X_OK) or "/" not in sim):
        raise ToolError(f"--sim {sim}: not an executable (build dynaqpc-sim)")
    dbc = args.dbc or default_dbc_path()
    devices = qemu = None
    bridge = watch = None
    board = None
    try:
        dev_cmd = [
            sim,
            "devices",
            "--scenario",
            args.scenario,
            "--supervise",
            "--seed",
            str(args.seed),
            "--speed",
            str(args.speed),
            "--wait-firmware",
            "--duration",
            str(args.duration + 30),
        ]
        if args.episodes:
            dev_cmd += ["--episodes", str(args.episodes)]
        if args.set:
            dev_cmd += ["--set", str(args.set)]
        devices = subprocess.Popen(dev_cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        dev_lines = Lines(devices, "devices: " if not args.quiet else "", not args.quiet)
        m = dev_lines.wait_for(re.compile(r"^cricket_tty=(\S+)"), 15)
        if not m:
            raise ToolError("dynaqpc-sim devices did not name its Cricket pty")
        cricket_tty = m.group(1)
        # The seed the devices use (with --set, the set's seed mixed from --seed as `train` mixes
        # it) is the firmware's too: the same seed means the same run as the lock-step build's.
        m = dev_lines.wait_for(SEED_RE, 15)
        if not m:
            raise ToolError("dynaqpc-sim devices did not name its seed")
        board_seed = int(m.group(1))
        watch = BusWatch(dbc).start()
        args.probe = HostProbe().start()

        append = f"seed={board_seed} report_s={args.report_s} speed={args.speed}"
        if args.step_cap:
            append += f" step_cap={args.step_cap}"
        if args.planning is not None:
            append += f" planning={args.planning}"
        if args.no_persist:
            append += " persist=0"
        if args.agent is not None:
            append += f" agent={registry.number(args.agent)}"
        qemu_cmd = [
            args.qemu,
            "-M",
            "netduinoplus2",
            "-display",
            "none",
            "-monitor",
            "none",
            "-chardev",
            "stdio,id=sh0",
            "-semihosting-config",
            "enable=on,target=native,chardev=sh0",
            "-serial",
            "pty",
            "-serial",
            cricket_tty,
            "-kernel",
            args.elf,
            "-append",
            append,
        ]
        if args.icount is not None:
            qemu_cmd[1:1] = ["-icount", f"shift={args.icount},sleep=on"]
        qemu = subprocess.Popen(qemu_cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        board = Lines(qemu, "board: " if not args.quiet else "", not args.quiet)
        wall0 = time.monotonic()
        m = board.wait_for(PTY_RE, 15)
        if not m or m.group(2) != "serial0":
            raise ToolError("QEMU did not name the pty of its first serial port (the board's SLCAN line)")
        bridge = Bridge(m.group(1), dbc).start()
        print(
            f"emu: QEMU netduinoplus2 ({os.path.basename(args.elf)}), SLCAN on {m.group(1)}, "
            f"Cricket on {cricket_tty}, devices: {args.scenario}",
            flush=True,
        )

        # SIGTERM or SIGINT (also when started in the background, where SIGINT is ignored) end
        # the run early as --duration does: QEMU and the devices stopped, the counters printed.
        stop = threading.Event()
        for sig in (signal.SIGTERM, signal.SIGINT):
            signal.signal(sig, lambda *_: stop.set())
        deadline = time.monotonic() + args.duration
        while time.monotonic() < deadline and not stop.is_set():
            if qemu.poll() is not None or devices.poll() is not None:
                break
            time.sleep(0.2)
        if stop.is_set():
            print("emu: stopped by a signal", flush=True)
        time.sleep(0.5)  # the last frames and report line
        args.wall_s = time.monotonic() - wall0
    finally:
        if bridge is not None:
            bridge.closing()
        for p in (devices,):
            _stop(p)
        qrc = _stop(qemu)
        if bridge is not None:
            bridge.stop()
        if watch is not None:
            watch.stop()
        if getattr(args, "probe", None) is not None:
            args.probe.stop()
    return summarise(args, board, qrc, watch, bridge)


def _problems(args, last, reports, watch, bridge, plan, idle_loop, goals, fault, fell_behind) -> List[str]:
    """What failed the run, each a line for FAIL: (none: PASS)."""
    problems = []
    if bridge.to_bus == 0 or watch.frames == 0:
        problems.append("no frame from the firmware on the bus")
    if bridge.to_board == 0:
        problems.append("no frame from the devices reached the board")
    if watch.plan_updates == 0 or plan == 0:
        problems.append("no planning update")
    if watch.deadline_misses or last.get("misses", 0):
        # Exit 1 as before; the message says whose they are. A clock that fell behind without a
        # miss is only reported (above): the firmware met every deadline of its own time.
        problems.append(
            f"deadline misses: bus {watch.deadline_misses}, board {last.get('misses', 0)}"
            + (" — the emulation fell behind (above): the host's, not the firmware's" if fell_behind else "")
        )
    if fault:
        problems.append("hard fault (or an unexpected exception) on the board")
    if not reports:
        problems.append("no report line from the board")
    if idle_loop < args.min_idle_loop_updates:
        problems.append(
            f"{idle_loop} planning updates in the idle loop, expected at least {args.min_idle_loop_updates}"
        )
    if len(watch.episodes) < args.min_episodes:
        problems.append(f"{len(watch.episodes)} episodes finished, expected at least {args.min_episodes}")
    if goals < args.min_goals:
        problems.append(f"the goal reached in {goals} episodes, expected at least {args.min_goals}")
    return problems


def summarise(args, board: "Lines", qrc: Optional[int], watch: BusWatch, bridge: Bridge) -> int:
    reports = [r for r in (parse_report(ln) for ln in board.lines) if r]
    last = reports[-1] if reports else {}
    fault = any("HARD FAULT" in ln or "UNEXPECTED EXCEPTION" in ln for ln in board.lines) or qrc == 3
    steps = last.get("real_steps", 0)
    plan = last.get("planning_updates", 0)
    idle_loop = last.get("idle_loop_updates", 0)
    per = plan / steps if steps else 0.0
    idle_per = idle_loop / steps if steps else 0.0
    idle_pct = sum(watch.idle_percent) / len(watch.idle_percent) if watch.idle_percent else 0.0
    wall_s = getattr(args, "wall_s", 0.0)
    if wall_s > 0 and last.get("t_ms"):
        # The firmware's clock against the wall: below the speed, QEMU could not keep up with
        # -icount's instruction rate (a loaded host): the devices then see a slow firmware.
        print(
            f"emu: firmware clock {last['t_ms'] / 1000:.1f} s at the last report, wall {wall_s:.1f} s "
            f"(the report lags by up to --report-s)"
        )
    why = f" (last: {bridge.last_error})" if getattr(bridge, "errors", 0) and getattr(bridge, "last_error", "") else ""
    print(f"emu: bridge board->bus {bridge.to_bus} frames, bus->board {bridge.to_board}, errors {bridge.errors}{why}")
    print(
        f"emu: bus TLM_SCHED {watch.sched} frames ({watch.sched_planning} with PlanUpdates > 0, "
        f"{watch.plan_updates} planning updates), DeadlineMisses {watch.deadline_misses}, "
        f"IdlePercent mean {idle_pct:.1f} %, FW_STATUS {watch.status}, TLM_EPISODE {len(watch.episodes)}"
    )
    for e in watch.episodes:
        print(
            f"emu: episode {e.get('Episode')}: steps {e.get('Steps')} reached_goal {e.get('ReachedGoal')} "
            f"bumps {e.get('Bumps')} reward {e.get('TotalReward')}"
        )
    goals = sum(1 for e in watch.episodes if e.get("ReachedGoal"))
    print(
        f"emu: the robot reached the goal in {goals} of {len(watch.episodes)} episodes; the board planned "
        f"{idle_loop} updates in its idle loop ({idle_per:.1f} per real step) and {max(0, plan - idle_loop)} "
        f"before acting, over {steps} real steps",
        flush=True,
    )
    probe = getattr(args, "probe", None)
    late = probe.percentile(100) if probe is not None else 0.0
    if probe is not None and probe.late_ms:
        load = os.getloadavg()[0] if hasattr(os, "getloadavg") else 0.0
        print(
            f"emu: host: 5 ms timers woke up to {late:.1f} ms late (99th percentile {probe.percentile(99):.1f} ms); "
            f"load average {load:.1f} on {os.cpu_count()} cores",
            flush=True,
        )
    misses = max(watch.deadline_misses, last.get("misses", 0))
    fell_behind = behind(args.speed, emulated_rate(board), late, misses)
    if fell_behind:
        print(f"emu: {fell_behind}", flush=True)
    print(
        f"emu: board: real_steps={steps} planning_updates={plan} per_real_step={per:.1f} "
        f"idle_loop_updates={idle_loop} idle_loop_per_real_step={idle_per:.1f} "
        f"control_worst_run_us={last.get('control_worst_run_us', 0)} misses={last.get('misses', 0)} "
        f"idle_permille={last.get('idle_permille', 0)} events_dropped={last.get('events_dropped', 0)} "
        f"stack_unused={last.get('stack_unused', 0)} can_tx_dropped={last.get('can_tx_dropped', 0)} "
        f"slcan_errors={last.get('slcan_errors', 0)} qemu_exit={qrc}"
    )
    problems = _problems(args, last, reports, watch, bridge, plan, idle_loop, goals, fault, fell_behind)
    for p in problems:
        print(f"FAIL: {p}", flush=True)
    if not problems:
        print("emu: PASS", flush=True)
    return 1 if problems else 0


def cmd_bridge(args) -> int:
    bridge = Bridge(args.slcan, args.dbc or default_dbc_path()).start()
    print(f"bridge: {args.slcan} <-> {VCAN_INTERFACE} {VCAN_CHANNEL}; Ctrl-C ends", flush=True)
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        pass
    finally:
        bridge.stop()
    print(f"bridge: board->bus {bridge.to_bus}, bus->board {bridge.to_board}, errors {bridge.errors}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="dynaqpc-emu", description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="QEMU + the simulated devices + the bridge, then the run's counters")
    r.add_argument("--elf", default=_default_elf(), help="the board's image (default: the cortex-m4 build's)")
    r.add_argument("--sim", default=_default_sim(), help="dynaqpc-sim (default: a build's)")
    r.add_argument("--qemu", default="qemu-system-arm")
    r.add_argument("--dbc", default=None)
    r.add_argument("--duration", type=float, default=60.0, help="wall seconds at most (default 60)")
    r.add_argument("--episodes", type=int, default=0, help="stop after N episodes (the supervisor's count)")
    r.add_argument("--min-episodes", type=int, default=0, help="fail with fewer finished episodes")
    r.add_argument("--min-goals", type=int, default=0, help="fail with fewer episodes that reached the goal")
    r.add_argument(
        "--min-idle-loop-updates",
        type=int,
        default=0,
        help="fail with fewer planning updates made in the idle loop (the board's count)",
    )
    r.add_argument(
        "--scenario",
        default="paper-lab",
        help="the devices' world: paper-lab (default), paper-lab-real (the realistic profile: wheels "
        "that do not match, motor noise and deadband, slip, a gyro scale error, Cricket dropouts and "
        "outliers) or a scenario file with paper-lab's robot (the board runs the paper-lab image)",
    )
    r.add_argument("--step-cap", type=int, default=0, help="the board's step cap (default: the image's)")
    r.add_argument("--planning", type=int, default=None, help="the board's planning (default: the image's, 0)")
    r.add_argument(
        "--agent", choices=registry.names(), default=None, help="the board's agent (default: the image's, dyna-qpc)"
    )
    r.add_argument("--no-persist", action="store_true", help="the board saves nothing at episode ends")
    r.add_argument(
        "--seed",
        type=int,
        default=1,
        help="the world's and the firmware's seed (with --set: the experiment's, as train --seed)",
    )
    r.add_argument(
        "--set",
        type=int,
        default=0,
        metavar="K",
        help="run set K of `dynaqpc-sim train --seed S`: the devices and the firmware get that "
        "set's seed (default: --seed itself)",
    )
    r.add_argument(
        "--speed",
        type=int,
        default=1,
        help="the devices and the firmware's clock X times faster than real time (X divides 168); "
        "with --icount 0 at 8 the firmware sees 125 M instructions per second of its time",
    )
    r.add_argument("--report-s", type=int, default=2, help="the board's report period, firmware seconds")
    r.add_argument(
        "--icount",
        type=int,
        default=None,
        metavar="SHIFT",
        help="QEMU -icount shift=SHIFT,sleep=on: 2^SHIFT ns of emulated time per instruction",
    )
    r.add_argument("--quiet", action="store_true", help="do not echo the devices' and the board's lines")
    r.set_defaults(fn=cmd_run)
    b = sub.add_parser("bridge", help="only the bridge: an SLCAN serial line <-> the virtual CAN bus")
    b.add_argument("--slcan", required=True, help="the board's serial line (QEMU's -serial pty path)")
    b.add_argument("--dbc", default=None)
    b.set_defaults(fn=cmd_bridge)
    return ap


def main(argv: Optional[List[str]] = None) -> int:
    args = build_parser().parse_args(argv)
    return run_main(lambda: args.fn(args))


if __name__ == "__main__":
    sys.exit(main())
