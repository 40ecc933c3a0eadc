#!/bin/sh
# SPDX-License-Identifier: MIT
# Bus benchmark: does the virtual CAN bus drop frames at the robot's traffic rates?
# Runs dynaqpc-fw and dynaqpc-sim devices --supervise (the robot learning, as an operator would run
# it) at --speed X for --seconds S of wall time, with dynaqpc-monitor as an independent listener,
# all in a private network namespace (nothing else on the bus; never the host's network), and
# prints the frames each program sent against the frames received:
#   devices->firmware: frames_sent=N frames_received=N dropped=N     (exact: the devices run
#                      with --wait-firmware, so the firmware is on the bus before their first
#                      frame, and it leaves 2 s after their last)
#   all frames, monitor: frames_sent=N frames_received=N dropped=N counter_gaps=N
# then the firmware's control-task timing (misses against its tolerance, lateness percentiles in
# firmware and wall time) and, with Cricket beacons (paper-lab), the serial line's bytes.
# Exit 0 when nothing was dropped, 1 otherwise or on a failure.
#   tools/bench_bus.sh [--seconds S] [--speed X] [--scenario NAME] [--bin DIR]
# The issue's target is a 10-minute run at 10x: tools/bench_bus.sh --seconds 600 --speed 10.
# Defaults: 60 s at 10x, paper-sim, build/host-release/bin if built, else build/host/bin.
set -u
REPO=$(cd "$(dirname "$0")/.." && pwd)
. "$REPO/tools/devices_ready.sh"
SECONDS_WALL=60
SPEED=10
SCENARIO=paper-sim
BIN=""
INSIDE=0
. "$REPO/tools/script_options.sh"
script_options "usage: tools/bench_bus.sh [--seconds S] [--speed X] [--scenario NAME] [--bin DIR]" \
    "--seconds=SECONDS_WALL --speed=SPEED --scenario=SCENARIO --bin=BIN --inside=INSIDE:1" "$@" || exit 2
if [ -z "$BIN" ]; then
    BIN=$REPO/build/host/bin
    [ -x "$REPO/build/host-release/bin/dynaqpc-fw" ] && BIN=$REPO/build/host-release/bin
fi
MONITOR=$REPO/.venv/bin/dynaqpc-monitor
for f in "$BIN/dynaqpc-fw" "$BIN/dynaqpc-sim" "$MONITOR"; do
    [ -x "$f" ] || { echo "bench_bus: $f missing (build dynaqpc-fw and dynaqpc-sim; tools/dev.sh setup)" >&2; exit 1; }
done

if [ $INSIDE -eq 0 ]; then
    if ! unshare -n true 2>/dev/null; then
        echo "bench_bus: cannot create a private network namespace (unshare -n); not running on the host's bus" >&2
        exit 1
    fi
    exec unshare -n sh "$0" --inside --seconds "$SECONDS_WALL" --speed "$SPEED" --scenario "$SCENARIO" --bin "$BIN"
fi

ip link set lo up && ip route add 224.0.0.0/4 dev lo || { echo "bench_bus: cannot route multicast over lo" >&2; exit 1; }
TMP=$(mktemp -d) || exit 1
PIDS=""
trap 'for p in $PIDS; do kill $p 2>/dev/null; done; [ -n "${KEEP:-}" ] && cp "$TMP"/* "$KEEP"/; rm -rf "$TMP"' EXIT
trap 'exit 1' INT TERM
LIMIT=$((SECONDS_WALL + 60))

# The monitor joins first and leaves last; python needs a moment to start.
timeout $LIMIT "$MONITOR" --duration $((SECONDS_WALL + 8)) --refresh 0 > "$TMP/monitor.out" 2> "$TMP/monitor.err" &
PIDS="$!"
MON=$!
sleep 4
# The devices first: they open the Cricket pty (if the scenario has beacons) and wait, sending
# nothing, until they hear the firmware.
timeout $LIMIT "$BIN/dynaqpc-sim" devices --scenario "$SCENARIO" --speed "$SPEED" --supervise --wait-firmware \
    --duration "$SECONDS_WALL" > "$TMP/devices.out" 2>&1 &
DEV=$!
PIDS="$PIDS $DEV"
TTY=$(wait_devices_ready "$TMP/devices.out" bench_bus) || exit 1
timeout $LIMIT "$BIN/dynaqpc-fw" --scenario "$SCENARIO" --speed "$SPEED" --duration $((SECONDS_WALL + 2)) \
    ${TTY:+--cricket-tty "$TTY"} > "$TMP/fw.out" 2>&1 &
FW=$!
PIDS="$PIDS $FW"
wait $DEV; DRC=$?
wait $FW; FRC=$?
wait $MON; MRC=$?
PIDS=""
if [ $DRC -ne 0 ] || [ $FRC -ne 0 ] || [ $MRC -ne 0 ]; then
    echo "bench_bus: a program failed (devices $DRC, firmware $FRC, monitor $MRC)" >&2
    cat "$TMP/devices.out" "$TMP/fw.out" "$TMP/monitor.err" >&2
    exit 1
fi

field() { sed -n "s/^$2.*[ ]$3=\([0-9]*\).*/\1/p" "$1" | tail -n 1; }
dev_sent=$(field "$TMP/devices.out" bus: frames_sent)
dev_recv=$(field "$TMP/devices.out" bus: frames_received)
fw_sent=$(field "$TMP/fw.out" bus: frames_sent)
fw_recv=$(field "$TMP/fw.out" bus: frames_received)
mon_recv=$(sed -n 's/^\([0-9]*\) frames, .*/\1/p' "$TMP/monitor.out" | tail -n 1)
gaps=$(sed -n 's/.* \([0-9]*\) frames lost (counter gaps).*/\1/p' "$TMP/monitor.out" | tail -n 1)
episodes=$(grep -c '^episode=' "$TMP/devices.out")
grep -h '^devices: stopped\|^dynaqpc-fw: stopped\|^episodes=\|^control: \|^status: ' "$TMP/devices.out" "$TMP/fw.out"
echo "scenario=$SCENARIO speed=${SPEED}x wall_s=$SECONDS_WALL episodes=$episodes"
echo "devices->firmware: frames_sent=$dev_sent frames_received=$fw_recv dropped=$((dev_sent - fw_recv))"
echo "firmware->devices: firmware frames_sent=$fw_sent devices frames_received=$dev_recv (the devices leave 2 s earlier)"
total=$((dev_sent + fw_sent))
echo "all frames, monitor: frames_sent=$total frames_received=$mon_recv dropped=$((total - mon_recv)) counter_gaps=$gaps"
if [ -n "$TTY" ]; then
    echo "cricket serial: devices pty_bytes=$(field "$TMP/devices.out" devices: pty_bytes) pty_dropped=$(field "$TMP/devices.out" devices: pty_dropped)" \
        "firmware uart_rx_bytes=$(field "$TMP/fw.out" episodes uart_rx_bytes) uart_overruns=$(field "$TMP/fw.out" episodes uart_overruns)" \
        "uart_discarded=$(field "$TMP/fw.out" episodes uart_discarded)"
fi
[ $((dev_sent - fw_recv)) -eq 0 ] && [ $((total - mon_recv)) -eq 0 ] && [ "$gaps" -eq 0 ]
