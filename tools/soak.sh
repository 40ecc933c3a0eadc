#!/bin/sh
# SPDX-License-Identifier: MIT
# Soak: the firmware on the host (dynaqpc-fw, paper-lab, --auto-start, flash image) against the
# simulated robot (dynaqpc-sim devices --supervise) at 10x in a private network namespace, under
# a schedule of faults; one table row per run (docs/reliability.md):
#   cuts     power cuts: dynaqpc-fw killed (SIGKILL) and started again on the same flash image
#   stalls   the firmware stopped (SIGSTOP) for 1 s of wall time, then continued
#   frames   random well-formed frames on the firmware's receive ids and others, per second
#   garbage  random UDP datagrams on the bus's group, per second
#   commands random TOOL_CMD frames, per second
#
#   tools/soak.sh                       # the issue's table: 240 s a run, each fault, then all at once
#   tools/soak.sh --seconds 60 --only all --cuts 2 --stalls 3   # one short run
#   tools/soak.sh --only reboots --reboots 50   # power cuts at random times (seeded), then per boot:
#                                       # was the episode it cut reported interrupted, and the heading
#                                       # error of the first step learned after it
# Columns: episodes; the last quarter's mean steps and bumps per episode; interrupted episodes;
# the firmware's heading error at its learned steps (mean over episodes' means, and the steps
# learned with it over 20 deg); boots that restored the flash's record of the cuts; frames the
# firmware refused (final boot); episodes the firmware's trust logic ended and legs it drove; the
# host's stalls (tools/soak_probe.py): wake-ups of a process of its own more than 256 ms of robot
# time late (25.6 ms at 10x, as far as the gyro's frame counter reaches), and the worst in ms of
# wall time. The firmware and the devices stall with the host, and a stall that long is a gyro
# gap; a row whose run saw such stalls measured the host as much as the firmware.
set -u
REPO=$(cd "$(dirname "$0")/.." && pwd)
. "$REPO/tools/devices_ready.sh"
BIN=$REPO/build/host-release/bin
PY=$REPO/.venv/bin/python
SECS=240
SPEED=10
ONLY=""
CUTS=5; STALLS=10; GARBAGE=100; FRAMES=100; COMMANDS=1000; REBOOTS=50; SEED=1
RANDOM_CUTS=0
INSIDE=0
. "$REPO/tools/script_options.sh"
script_options "usage: tools/soak.sh [--seconds S] [--speed X] [--bin DIR] [--only FAULT] [--cuts N] [--stalls N] [--garbage N] [--frames N] [--commands N] [--reboots N] [--seed S]" \
    "--seconds=SECS --speed=SPEED --bin=BIN --only=ONLY --cuts=CUTS --stalls=STALLS --garbage=GARBAGE --frames=FRAMES --commands=COMMANDS --reboots=REBOOTS --seed=SEED --inside=INSIDE:1" "$@" || exit 2
for f in "$BIN/dynaqpc-fw" "$BIN/dynaqpc-sim" "$PY"; do
    [ -x "$f" ] || { echo "soak: $f missing (build host-release; tools/dev.sh setup)" >&2; exit 77; }
done
if [ $INSIDE -eq 0 ]; then
    unshare -n true 2>/dev/null || { echo "soak: cannot create a private network namespace (unshare -n)" >&2; exit 77; }
    exec unshare -n sh "$0" --inside --seconds "$SECS" --speed "$SPEED" --bin "$BIN" --only "${ONLY:-table}" \
        --cuts "$CUTS" --stalls "$STALLS" --garbage "$GARBAGE" --frames "$FRAMES" --commands "$COMMANDS" \
        --reboots "$REBOOTS" --seed "$SEED"
fi
ip link set lo up && ip route add 224.0.0.0/4 dev lo || { echo "soak: cannot route multicast over lo" >&2; exit 1; }
TMP=$(mktemp -d) || exit 1
trap 'kill $(jobs -p) 2>/dev/null; kill -CONT $FWPID 2>/dev/null; [ -n "${KEEP:-}" ] && cp -r "$TMP"/* "$KEEP"/; rm -rf "$TMP"' EXIT
FWPID=""

# run NAME CUTS STALLS GARBAGE FRAMES COMMANDS
run() {
    name=$1; cuts=$2; stalls=$3; garbage=$4; frames=$5; commands=$6
    D=$TMP/$name; mkdir -p "$D"
    "$BIN/dynaqpc-sim" devices --scenario paper-lab --speed "$SPEED" --supervise --wait-firmware \
        --duration "$SECS" > "$D/devices.out" 2>&1 &
    DEV=$!
    TTY=$(wait_devices_ready "$D/devices.out" soak) || return 1
    boot=0
    start_fw() {
        boot=$((boot + 1))
        "$BIN/dynaqpc-fw" --scenario paper-lab --speed "$SPEED" --cricket-tty "$TTY" --flash "$D/fw.flash" \
            --auto-start --duration $((SECS + 10)) > "$D/fw.$boot.out" 2>&1 &
        FWPID=$!
    }
    start_fw
    "$PY" "$REPO/tools/soak_probe.py" --seconds "$SECS" \
        --threshold-ms "$(awk -v s="$SPEED" 'BEGIN { printf "%.2f", 256 / s }')" > "$D/probe.out" 2>&1 &
    PROBE=$!
    INJ=""
    if [ "$garbage$frames$commands" != "000" ]; then
        "$PY" "$REPO/tools/soak_inject.py" --garbage "$garbage" --frames "$frames" --commands "$commands" \
            --duration "$SECS" > "$D/inject.out" 2>&1 &
        INJ=$!
    fi
    # The schedule, in tenths of a second of wall time: cut k at k/(cuts+1) of the run (or, with
    # RANDOM_CUTS, at a uniform time within the k-th of `cuts` equal slots between 5 % and 85 % of
    # the run, at least 2 s after the slot's start so that every boot is heard; the schedule's
    # clock lags the wall by its own work, so the last 15 % keep the last cuts within the run),
    # stall k at (k-1/2)/stalls of it.
    t=0; end=$((SECS * 10)); k=1; s=1
    : > "$D/cut_times"
    if [ "$RANDOM_CUTS" -eq 1 ]; then
        awk -v n="$cuts" -v end="$end" -v seed="$SEED" 'BEGIN { srand(seed); b = end / 20; l = (end * 17 / 20 - b) / n
            for (i = 0; i < n; i++) printf "%d\n", b + i * l + 20 + rand() * (l - 20) }' > "$D/cut_times"
    fi
    cut_due() {  # cut_due K: the time (tenths of a second) of cut K
        if [ "$RANDOM_CUTS" -eq 1 ]; then sed -n "${1}p" "$D/cut_times"; else echo $((end * $1 / (cuts + 1))); fi
    }
    while [ $t -lt $end ] && kill -0 $DEV 2>/dev/null; do
        if [ $k -le "$cuts" ] && [ $t -ge "$(cut_due $k)" ]; then
            kill -9 $FWPID 2>/dev/null; wait $FWPID 2>/dev/null
            start_fw
            k=$((k + 1))
        fi
        if [ $s -le "$stalls" ] && [ $t -ge $((end * (2 * s - 1) / (2 * stalls))) ]; then
            kill -STOP $FWPID 2>/dev/null; sleep 1; kill -CONT $FWPID 2>/dev/null
            t=$((t + 10)); s=$((s + 1))
        fi
        sleep 0.1; t=$((t + 1))
    done
    wait $DEV
    wait $PROBE
    kill $FWPID 2>/dev/null; wait $FWPID 2>/dev/null
    [ -n "$INJ" ] && wait $INJ
    restored=$(cat "$D"/fw.*.out | grep -c 'restored yes')
    last=$D/fw.$boot.out
    field() { sed -n "s/.*[ ]$2=\([0-9]*\).*/\1/p" "$1" | tail -n 1; }
    bad=$(field "$last" frames_bad); malformed=$(field "$last" tool_malformed)
    over20=$(field "$D/devices.out" learned_over_20deg)
    trust=$(sed -n 's/^trust: //p' "$last" | tail -n 1)
    host=$(sed -n 's/^stalls=\([0-9]*\) worst_ms=\([0-9]*\).*/\1 (\2)/p' "$D/probe.out")
    grep '^episode=' "$D/devices.out" | awk -v name="$name" -v cuts="$cuts" -v restored="$restored" \
        -v bad="${bad:-?}" -v malformed="${malformed:-?}" -v over20="${over20:-?}" -v trust="$trust" -v host="${host:-?}" '
        { for (i = 1; i <= NF; i++) { split($i, kv, "="); v[NR, kv[1]] = kv[2] } }
        END {
            n = NR; q = int(n * 3 / 4) + 1; m = 0; st = 0; bu = 0; he = 0; it = 0
            for (i = 1; i <= n; i++) { he += v[i, "head_err_mean_deg"]; it += v[i, "interrupted"] }
            for (i = q; i <= n; i++) { st += v[i, "steps"]; bu += v[i, "bumps"]; m++ }
            printf "| %s | %d | %.1f | %.1f | %d | %.1f | %s | %s/%d | %s | %s | %s | %s |\n", name, n,
                m ? st / m : 0, m ? bu / m : 0, it, n ? he / n : 0, over20, restored, cuts, bad, malformed, trust, host
        }'
}

echo "| faults | episodes | last-quarter steps | last-quarter bumps | interrupted | heading error, deg | learned steps > 20 deg | restored | frames refused | TOOL_CMD refused | firmware trust (last boot) | host stalls (worst, ms) |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|"
case "$ONLY" in
table)
    run none 0 0 0 0 0
    run cuts "$CUTS" 0 0 0 0
    run stalls 0 "$STALLS" 0 0 0
    run frames 0 0 0 "$FRAMES" 0
    run garbage 0 0 "$GARBAGE" 0 0
    run commands 0 0 0 0 "$COMMANDS"
    run all "$CUTS" "$STALLS" "$GARBAGE" "$FRAMES" 0
    ;;
none) run none 0 0 0 0 0 ;;
reboots)
    RANDOM_CUTS=1
    run reboots "$REBOOTS" 0 0 0 0
    # Per boot after a cut, from the supervisor's lines: the episode the cut ended reported as
    # interrupted (the firmware reports it in its first control period, 1 ms before its first
    # FW_STATUS tells the supervisor of the boot: the episode line just before the reboot line, or
    # else the next one), and the heading error of the first step learned after it.
    echo
    awk '/supervisor: the firmware rebooted/ { boots++; if (last_int) { rep++; last_int = 0 } else pending = 1; next }
        /^episode=/ { if (pending) { pending = 0; if ($0 ~ / interrupted=1 /) rep++; else notrep++ }
            else last_int = $0 ~ / interrupted=1 /; next }
        /supervisor: the start cut/ { if (pending) { pending = 0; rep++ } else last_int = 1; next }
        /first learned step after boot/ { sub(/.*head_err_deg=/, ""); n++; e = $1 + 0; s += e;
            if (e > m) m = e; if (e <= 10) ok++ }
        END { printf "reboots seen: %d; the episode each cut reported interrupted: %d, not: %d, none before the next boot: %d\n",
                boots, rep, notrep, boots - rep - notrep
              printf "first learned step after a reboot: %d steps, heading error <= 10 deg: %d, mean %.1f deg, worst %.1f deg\n",
                n, ok, n ? s / n : 0, m }' "$TMP/reboots/devices.out"
    # Boots after a cut that found no learned record in flash: their journal was the early one.
    early=0
    for f in "$TMP"/reboots/fw.*.out; do
        [ "$f" = "$TMP/reboots/fw.1.out" ] && continue
        grep -q 'restored no' "$f" && early=$((early + 1))
    done
    echo "boots after a cut with no learned record in flash yet (the early journal): $early"
    ;;
all) run all "$CUTS" "$STALLS" "$GARBAGE" "$FRAMES" 0 ;;
commands) run commands 0 0 0 0 "$COMMANDS" ;;
cuts) run cuts "$CUTS" 0 0 0 0 ;;
stalls) run stalls 0 "$STALLS" 0 0 0 ;;
frames) run frames 0 0 0 "$FRAMES" 0 ;;
garbage) run garbage 0 0 "$GARBAGE" 0 0 ;;
*) echo "soak: --only none|cuts|stalls|frames|garbage|commands|all|reboots (or leave it out for the whole table)" >&2; exit 2 ;;
esac
