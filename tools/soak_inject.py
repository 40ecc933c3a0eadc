#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Bus faults for tools/soak.sh, on the simulator's virtual bus (udp_multicast, this host only):
garbage datagrams, random well-formed frames on the firmware's receive ids and others, random
TOOL_CMD frames. Paced at the given rates until --duration; prints what it sent.

    .venv/bin/python tools/soak_inject.py --garbage 100 --frames 100 --commands 1000 --duration 240
"""

import argparse
import pathlib
import random
import socket
import struct
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
GROUP, PORT = "239.74.163.2", 43113  # host_sim/transport/vcan.h


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--garbage", type=float, default=0.0, help="random datagrams per second")
    p.add_argument("--frames", type=float, default=0.0, help="random well-formed frames per second")
    p.add_argument("--commands", type=float, default=0.0, help="random TOOL_CMD frames per second")
    p.add_argument("--duration", type=float, required=True, help="seconds")
    p.add_argument("--seed", type=int, default=1)
    a = p.parse_args()
    rng = random.Random(a.seed)
    import can
    import cantools

    db = cantools.database.load_file(str(ROOT / "docs" / "dynaqpc.dbc"))
    lengths = {m.frame_id: m.length for m in db.messages}
    fw_rx = [
        db.get_message_by_name(n).frame_id
        for n in (
            "MOTOR_STATUS",
            "GYRO_RATE",
            "IR_RANGES",
            "SONAR_RANGES_A",
            "SONAR_RANGES_B",
            "SONAR_RANGES_C",
            "GPS_POSE",
        )
    ]
    others = [0x123, 0x200, 0x7FF, 0x050]
    tool_cmd = db.get_message_by_name("TOOL_CMD").frame_id
    bus = can.Bus(interface="udp_multicast", channel=GROUP, hop_limit=0)
    raw = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    raw.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, struct.pack("b", 0))
    raw.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
    sent = {"garbage": 0, "frames": 0, "commands": 0}
    rates = {"garbage": a.garbage, "frames": a.frames, "commands": a.commands}
    t0 = time.monotonic()
    due = {k: t0 for k in rates}
    while True:
        now = time.monotonic()
        if now - t0 >= a.duration:
            break
        for kind, rate in rates.items():
            if rate <= 0:
                continue
            while due[kind] <= now:
                due[kind] += 1.0 / rate
                if kind == "garbage":
                    raw.sendto(bytes(rng.randrange(256) for _ in range(rng.randrange(1, 64))), (GROUP, PORT))
                elif kind == "frames":
                    fid = rng.choice(fw_rx + others)
                    n = lengths.get(fid, rng.randrange(9))
                    bus.send(
                        can.Message(
                            arbitration_id=fid, is_extended_id=False, data=bytes(rng.randrange(256) for _ in range(n))
                        )
                    )
                else:
                    bus.send(
                        can.Message(
                            arbitration_id=tool_cmd,
                            is_extended_id=False,
                            data=bytes(rng.randrange(256) for _ in range(lengths[tool_cmd])),
                        )
                    )
                sent[kind] += 1
        nxt = min((due[k] for k, r in rates.items() if r > 0), default=now + 0.1)
        time.sleep(max(0.0, min(0.1, nxt - time.monotonic())))
    bus.shutdown()
    print("inject: " + " ".join(f"{k}={v}" for k, v in sent.items()), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
