#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The host's stalls during a soak (tools/soak.sh): a process of its own that sleeps 2 ms at a time
and counts the wake-ups that came more than --threshold-ms late. The soak's firmware and devices
stall with it: at 10x, 25.6 ms of wall time is 256 ms of robot time, as far as the gyro's 4-bit
frame counter reaches (16 samples of 16 ms), and the firmware counts any longer silence as a gyro
gap (docs/reliability.md). Prints one line: stalls=N worst_ms=W stalled_ms=S.

    .venv/bin/python tools/soak_probe.py --seconds 240 --threshold-ms 25.6
"""

import argparse
import time


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seconds", type=float, required=True, help="how long to watch")
    p.add_argument("--threshold-ms", type=float, required=True, help="a wake-up this late is a stall")
    p.add_argument("--period-ms", type=float, default=2.0, help="the sleep between looks")
    a = p.parse_args()
    period = a.period_ms * 1e-3
    start = prev = time.monotonic()
    stalls, worst_ms, stalled_ms = 0, 0.0, 0.0
    while prev - start < a.seconds:
        time.sleep(period)
        now = time.monotonic()
        late_ms = (now - prev - period) * 1e3
        prev = now
        worst_ms = max(worst_ms, late_ms)
        if late_ms > a.threshold_ms:
            stalls += 1
            stalled_ms += late_ms
    print(f"stalls={stalls} worst_ms={worst_ms:.0f} stalled_ms={stalled_ms:.0f}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
