# SPDX-License-Identifier: MIT
# Sourced by the scripts that run the firmware against `dynaqpc-sim devices` (bench_bus.sh, soak.sh).

# wait_devices_ready OUT WHO: waits up to 10 s for the devices writing OUT to say they are ready,
# then prints their Cricket pty (cricket_tty=..., nothing without beacons). On a timeout: says so
# as WHO, with OUT, on stderr and returns 1.
wait_devices_ready() {
    n=0
    until grep -q ready "$1" 2>/dev/null; do
        n=$((n + 1)); [ $n -gt 100 ] && { echo "$2: dynaqpc-sim devices did not start" >&2; cat "$1" >&2; return 1; }
        sleep 0.1
    done
    sed -n 's/^cricket_tty=//p' "$1" | head -n 1
}
