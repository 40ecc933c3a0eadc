# SPDX-License-Identifier: MIT
"""Stalls the firmware and watches it come back: joins the virtual CAN bus with python-can, decodes
the telemetry with docs/dynaqpc.dbc (cantools), and stops the firmware's process (SIGSTOP) --count
times for --stall seconds, --every seconds apart, starting --first seconds after it joined. After
each stall it times, from the SIGCONT, the first TLM_POSE with a fresh fix (FixState FRESH: the
Cricket line delivers solvable lines again) and the first TLM_LEARN (a real step of an episode).

Prints "ready" once it has joined the bus, then one line per stall:
    stall=<i> stall_s=<s> fix_after_s=<t or none> step_after_s=<t or none>
and a summary line "stalls=<n> fix_resumed=<k> step_resumed=<k> worst_fix_s=.. worst_step_s=..".
Exit 0 when every stall was followed by both a fresh fix and a step before the next stall (or
--tail seconds after the last), 1 otherwise. The times are wall clock and load-sensitive: they are
printed, not asserted.
"""
import argparse
import os
import signal
import sys
import time

import can
import cantools


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--dbc", required=True)
    ap.add_argument("--pid", type=int, required=True, help="the firmware's process")
    ap.add_argument("--stall", type=float, nargs="+", default=[1.0],
                    help="seconds of each stall; fewer values than --count repeat the last")
    ap.add_argument("--count", type=int, default=3)
    ap.add_argument("--first", type=float, default=4.0)
    ap.add_argument("--every", type=float, default=5.0, help="seconds from one SIGCONT to the next SIGSTOP")
    ap.add_argument("--tail", type=float, default=4.0)
    args = ap.parse_args()
    if args.count < 1 or args.first < 0 or args.every <= 0 or args.tail <= 0 or min(args.stall) <= 0:
        print("stall_listener: --count, --first, --every, --tail and --stall must be positive", file=sys.stderr)
        return 2

    db = cantools.database.load_file(args.dbc)
    pose_id = db.get_message_by_name("TLM_POSE").frame_id
    learn_id = db.get_message_by_name("TLM_LEARN").frame_id
    bus = can.Bus(interface="udp_multicast", channel="239.74.163.2", hop_limit=0)
    print("ready", flush=True)

    results = []  # [stall_s, fix_after, step_after] per stall
    resumed_at = None
    next_stop = time.monotonic() + args.first
    done_at = None
    try:
        while True:
            now = time.monotonic()
            if done_at is not None and now >= done_at:
                break
            if done_at is None and now >= next_stop:
                i = len(results)
                stall = args.stall[min(i, len(args.stall) - 1)]
                os.kill(args.pid, signal.SIGSTOP)
                time.sleep(stall)
                # What the bus carried during the stall was not the firmware's (it was stopped).
                while bus.recv(timeout=0) is not None:
                    pass
                os.kill(args.pid, signal.SIGCONT)
                resumed_at = time.monotonic()
                results.append([stall, None, None])
                if len(results) == args.count:
                    done_at = resumed_at + args.tail
                else:
                    next_stop = resumed_at + args.every
                continue
            wait = (done_at if done_at is not None else next_stop) - now
            msg = bus.recv(timeout=max(0.0, min(0.1, wait)))
            if msg is None or msg.is_extended_id or not results:
                continue
            cur = results[-1]
            t = time.monotonic() - resumed_at
            if msg.arbitration_id == pose_id and cur[1] is None:
                p = db.decode_message(pose_id, msg.data, decode_choices=False)
                if int(p["FixState"]) == 0:
                    cur[1] = t
            elif msg.arbitration_id == learn_id and cur[2] is None:
                cur[2] = t
    except ProcessLookupError:
        print("stall_listener: the firmware's process is gone", file=sys.stderr)
        return 1
    finally:
        bus.shutdown()

    def fmt(v):
        return "none" if v is None else f"{v:.2f}"

    for i, (stall, fix, step) in enumerate(results, 1):
        print(f"stall={i} stall_s={stall:g} fix_after_s={fmt(fix)} step_after_s={fmt(step)}")
    fixes = [r[1] for r in results if r[1] is not None]
    steps = [r[2] for r in results if r[2] is not None]
    print(f"stalls={len(results)} fix_resumed={len(fixes)} step_resumed={len(steps)} "
          f"worst_fix_s={fmt(max(fixes) if fixes else None)} worst_step_s={fmt(max(steps) if steps else None)}")
    return 0 if len(fixes) == len(results) and len(steps) == len(results) else 1


if __name__ == "__main__":
    sys.exit(main())
