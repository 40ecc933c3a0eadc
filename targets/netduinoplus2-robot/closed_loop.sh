#!/bin/sh
# SPDX-License-Identifier: MIT
# cortex-m4.emu.closed_loop: the emulated board (QEMU netduinoplus2) in closed loop with the
# simulated paper-lab robot's devices, through the SLCAN bridge (dynaqpc-emu run), inside a private
# network namespace so that the virtual CAN bus stays in it. Bounded: one episode of at most
# STEP_CAP real steps (~1.3 s each: a Cricket fix per step), 120 s of wall time at most. QEMU runs
# with -icount shift=3: the firmware sees 125 M instructions per second, a 168 MHz M4 at a CPI of
# 1.34, so a deadline it meets here it meets on the robot.
#   closed_loop.sh <image.elf> <dynaqpc-sim> <repo> [dynaqpc-emu run options...]
# Exit 0 pass, 1 fail, 77 skipped (no project venv).
ELF=$1
SIM=$2
REPO=$3
PY=$REPO/.venv/bin/python
STEP_CAP=${STEP_CAP:-6}

shift 3
if [ "$INSIDE" != 1 ]; then
    if [ ! -x "$PY" ] || ! "$PY" -c "import can, serial, cantools, msgpack" 2>/dev/null; then
        echo "SKIPPED: $PY with python-can, pyserial, cantools, msgpack missing; run tools/dev.sh setup"
        exit 77
    fi
    [ -f "$ELF" ] || { echo "FAIL: no image $ELF"; exit 1; }
    [ -x "$SIM" ] || { echo "FAIL: no dynaqpc-sim at $SIM"; exit 1; }
    if ! unshare -n true 2>/dev/null; then
        echo "FAIL: cannot create a private network namespace (unshare -n)"
        exit 1
    fi
    INSIDE=1 exec timeout -k 5 150 unshare -n sh "$0" "$ELF" "$SIM" "$REPO" "$@"
fi

ip link set lo up && ip route add 224.0.0.0/4 dev lo || { echo "FAIL: cannot route multicast over lo"; exit 1; }
cd "$REPO/tools" || exit 1
exec "$PY" -m dynaqpc_tools.emu run --elf "$ELF" --sim "$SIM" --duration 120 --step-cap "$STEP_CAP" \
    --episodes 1 --min-episodes 1 --report-s 2 --icount 3 "$@"
