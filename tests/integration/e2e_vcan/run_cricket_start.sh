#!/bin/sh
# SPDX-License-Identifier: MIT
# e2e.cricket_start: the Cricket listener streams before the firmware opens its serial line (as
# when dynaqpc-sim devices starts first, which it must to print the pty). The firmware must not
# count that backlog as UART overruns: it is discarded at the open (uart_discarded), and every
# byte after it is received (uart_overruns=0). paper-lab at 10x in a private network namespace.
#   run_cricket_start.sh <bin dir> [--inside]
# Exit 0 pass, 1 fail. A namespace that cannot be created is a failure (no run on the host's bus).
BIN=$1
SPEED=10

if [ "$2" != "--inside" ]; then
    if ! unshare -n true 2>/dev/null; then
        echo "FAIL: cannot create a private network namespace (unshare -n: needs root or user namespaces)"
        exit 1
    fi
    exec timeout -k 5 60 unshare -n sh "$0" "$BIN" --inside
fi

LOGS="devices fw"
. "$(dirname "$0")/netns.sh"

# Field $2 of the last line of file $1 that has it.
field() { sed -n "s/.*[ ]$2=\([0-9]*\).*/\1/p;s/^$2=\([0-9]*\).*/\1/p" "$1" | tail -n 1; }

# The devices stop first (the firmware then sees the line close), so every byte they wrote was
# either discarded at the open, received or lost while the firmware had the line open.
timeout 30 "$BIN/dynaqpc-sim" devices --scenario paper-lab --speed $SPEED --duration 5 > "$TMP/devices.out" 2>&1 &
DEV=$!
PIDS="$DEV"
TTY=$(cricket_tty_of "$TMP/devices.out") || exit 1
sleep 1.5  # 15 s of world time: a backlog larger than the UART's ring (several Cricket lines)
timeout 30 "$BIN/dynaqpc-fw" --scenario paper-lab --speed $SPEED --cricket-tty "$TTY" --duration 6 \
    > "$TMP/fw.out" 2>&1 &
FW=$!
PIDS="$PIDS $FW"
wait "$DEV"; DRC=$?
wait "$FW"; FRC=$?
PIDS=""
cat "$TMP/devices.out" "$TMP/fw.out"
[ $DRC -eq 0 ] || fail "dynaqpc-sim devices exited with $DRC"
[ $FRC -eq 0 ] || fail "dynaqpc-fw exited with $FRC"

written=$(field "$TMP/devices.out" pty_bytes)
rx=$(field "$TMP/fw.out" uart_rx_bytes)
overruns=$(field "$TMP/fw.out" uart_overruns)
discarded=$(field "$TMP/fw.out" uart_discarded)
stall_lost=$(field "$TMP/fw.out" uart_stall_lost)
[ -n "$written" ] && [ -n "$rx" ] && [ -n "$overruns" ] && [ -n "$discarded" ] && [ -n "$stall_lost" ] ||
    fail "counters missing"
echo "pty_bytes=$written uart_discarded=$discarded uart_rx_bytes=$rx uart_overruns=$overruns uart_stall_lost=$stall_lost"
[ "$discarded" -gt 256 ] || fail "no backlog was discarded at the open (uart_discarded=$discarded)"
# A machine too loaded to run the firmware for more than 50 ms stalls it: those bytes are lost as
# on the MCU (uart_stall_lost, part of uart_overruns), and are not what this test is about.
[ "$overruns" -eq "$stall_lost" ] ||
    fail "a normal start overran the UART's ring (uart_overruns=$overruns, of which $stall_lost in stalls)"
[ "$rx" -gt 0 ] || fail "no Cricket bytes received after the open"
[ $((discarded + rx + overruns)) -le "$written" ] || fail "the firmware counted more bytes than were written"
echo "PASS"
exit 0
