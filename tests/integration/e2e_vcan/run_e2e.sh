#!/bin/sh
# SPDX-License-Identifier: MIT
# e2e.vcan_episode: the firmware (dynaqpc-fw) and the simulated robot (dynaqpc-sim devices
# --supervise) as two processes on the virtual CAN bus, and a python-can listener decoding the
# telemetry with docs/dynaqpc.dbc, all inside a private network namespace. The scenario's own
# planning (paper-sim: planning 0, in the idle loop, as shipped): TLM_SCHED must show it.
#   run_e2e.sh <bin dir> <repo> [--inside]
# Exit 0 pass, 1 fail, 77 skipped (the project venv is missing). A namespace that cannot be
# created is a failure: this test must not run on the host's shared bus.
BIN=$1
REPO=$2
PY=$REPO/.venv/bin/python
SPEED=20
STEP_CAP=25
EPISODES=3

if [ "$3" != "--inside" ]; then
    if [ ! -x "$PY" ]; then
        echo "SKIPPED: $PY missing; run tools/dev.sh setup"
        exit 77
    fi
    if ! unshare -n true 2>/dev/null; then
        echo "FAIL: cannot create a private network namespace (unshare -n: needs root or user namespaces);"
        echo "      this test does not run on the host's shared bus"
        exit 1
    fi
    exec timeout -k 5 120 unshare -n sh "$0" "$BIN" "$REPO" --inside
fi

LOGS="listener fw devices"
. "$(dirname "$0")/netns.sh"

# Waits up to $2 seconds for a line matching $3 in file $1.
wait_for() {
    n=0
    while ! grep -q "$3" "$1" 2>/dev/null; do
        n=$((n + 1))
        [ $n -gt $(($2 * 10)) ] && return 1
        sleep 0.1
    done
}

timeout 60 "$PY" "$REPO/tests/integration/e2e_vcan/e2e_listener.py" --dbc "$REPO/docs/dynaqpc.dbc" \
    --episodes $EPISODES --step-cap $STEP_CAP --timeout 45 --idle-planning > "$TMP/listener.out" 2>&1 &
LISTENER=$!
PIDS="$LISTENER"
wait_for "$TMP/listener.out" 30 '^ready' || fail "the listener did not join the bus"

timeout 60 "$BIN/dynaqpc-fw" --scenario paper-sim --speed $SPEED --step-cap $STEP_CAP \
    --flash "$TMP/flash.bin" --duration 50 > "$TMP/fw.out" 2>&1 &
FW=$!
PIDS="$PIDS $FW"
wait_for "$TMP/fw.out" 10 'ready' || fail "dynaqpc-fw did not start"

timeout 60 "$BIN/dynaqpc-sim" devices --scenario paper-sim --speed $SPEED --supervise \
    --episodes $EPISODES --duration 50 > "$TMP/devices.out" 2>&1 &
DEV=$!
PIDS="$PIDS $DEV"

wait "$LISTENER"
LRC=$?
wait "$DEV"
DRC=$?
kill -TERM "$FW" 2>/dev/null
wait "$FW"
FRC=$?
PIDS=""
for f in listener devices fw; do echo "--- $f"; cat "$TMP/$f.out"; done
[ $LRC -eq 0 ] || fail "the listener's checks failed (exit $LRC)"
[ $DRC -eq 0 ] || fail "dynaqpc-sim devices exited with $DRC"
[ $FRC -eq 0 ] || fail "dynaqpc-fw exited with $FRC (SIGTERM must end it cleanly)"
n=$(grep -c '^episode=' "$TMP/devices.out")
[ "$n" -eq $EPISODES ] || fail "the supervisor printed $n episode lines, expected $EPISODES"
grep -q "saves=$EPISODES save_errors=0" "$TMP/fw.out" || fail "the firmware did not save once per episode"
grep -q "planning idle time" "$TMP/fw.out" || fail "the shipped scenario does not plan in idle time"
echo "PASS"
exit 0
