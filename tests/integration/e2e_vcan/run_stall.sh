#!/bin/sh
# SPDX-License-Identifier: MIT
# Measures how the Cricket line and the episodes survive stalls of the firmware: paper-lab at 10x
# in a private network namespace, dynaqpc-fw stopped (SIGSTOP) for STALL seconds three times.
# Prints the bytes the devices wrote to the line, what the firmware received, lost and discarded,
# the share received, and the episodes and safe stops. Not a ctest test (wall-clock timing on a
# shared machine); docs/realtime.md "Faults" gives the figures.
#   run_stall.sh <bin dir> [STALL seconds, default 1] [--inside]
BIN=$1
STALL=${2:-1}
SPEED=10
if [ "$3" != "--inside" ]; then
    unshare -n true 2>/dev/null || { echo "FAIL: cannot create a private network namespace"; exit 1; }
    exec timeout -k 5 120 unshare -n sh "$0" "$BIN" "$STALL" --inside
fi
LOGS="devices fw"
. "$(dirname "$0")/netns.sh"
field() { sed -n "s/.*[ ]$2=\([0-9]*\).*/\1/p;s/^$2=\([0-9]*\).*/\1/p" "$1" | tail -n 1; }

"$BIN/dynaqpc-sim" devices --scenario paper-lab --speed $SPEED --duration 26 > "$TMP/devices.out" 2>&1 &
DEV=$!
PIDS="$DEV"
n=0
until grep -q '^cricket_tty=' "$TMP/devices.out" 2>/dev/null; do
    n=$((n + 1)); [ $n -gt 100 ] && fail "no cricket_tty"
    sleep 0.1
done
TTY=$(sed -n 's/^cricket_tty=//p' "$TMP/devices.out" | head -n 1)
"$BIN/dynaqpc-fw" --scenario paper-lab --speed $SPEED --cricket-tty "$TTY" --auto-start --duration 24 \
    > "$TMP/fw.out" 2>&1 &
FW=$!
PIDS="$PIDS $FW"
sleep 4
for i in 1 2 3; do
    kill -STOP "$FW"; sleep "$STALL"; kill -CONT "$FW"; sleep 4
done
wait "$FW"
wait "$DEV"
PIDS=""
written=$(field "$TMP/devices.out" pty_bytes)
rx=$(field "$TMP/fw.out" uart_rx_bytes)
over=$(field "$TMP/fw.out" uart_overruns)
disc=$(field "$TMP/fw.out" uart_discarded)
eps=$(field "$TMP/fw.out" episodes)
stops=$(field "$TMP/fw.out" safe_stops)
grep -E "^(faults|cricket):" "$TMP/fw.out"
echo "stall_s=$STALL pty_bytes=$written uart_discarded=$disc uart_rx_bytes=$rx uart_overruns=$over episodes=$eps safe_stops=$stops"
awk -v w="$written" -v d="$disc" -v r="$rx" 'BEGIN { printf "received_share=%.3f (of the bytes written after the open)\n", r / (w - d) }'
