#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The learning benchmark: every agent at the same planning budget per real step, on the paper's
# two scenarios and on the evaluation rooms (host_sim/rooms/eval, never used for tuning), with
# fresh seeds. Prints one Table 1 per comparison (dynaqpc-experiment table: real steps and robot
# time to learn over ALL sets, sets learned, planning updates per real step).
#
#   tools/bench_learning.sh [--seed S] [--out DIR] [--quick]
#
# --quick: fewer sets and rooms (a smoke run, not figures to quote). Needs the host-release build
# and the venv (tools/dev.sh setup; cmake --build --preset host-release).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
sim=$root/build/host-release/bin/dynaqpc-sim
exp=$root/.venv/bin/dynaqpc-experiment
seed=9001 out=$root/results/bench quick=0
. "$root/tools/script_options.sh"
script_options "usage: tools/bench_learning.sh [--seed S] [--out DIR] [--quick]" \
    "--seed=seed --out=out --quick=quick:1" "$@" || exit 2
[ -x "$sim" ] || { echo "bench_learning.sh: build host-release first ($sim missing)" >&2; exit 2; }
[ -x "$exp" ] || { echo "bench_learning.sh: run tools/dev.sh setup first ($exp missing)" >&2; exit 2; }
jobs=2
lab_sets=20 sim_sets=8 room_lab_sets=5 room_sim_sets=2 room_sim_eps=40 sim_rooms=6
((quick)) && lab_sets=4 sim_sets=2 room_lab_sets=1 room_sim_sets=1 room_sim_eps=10 sim_rooms=2

train() {  # train <scenario> <agent> <planning> <sets> <episodes> <csv>
    [ -s "$6" ] && return 0
    "$sim" train --scenario "$1" --agent "$2" --planning "$3" --sets "$4" --episodes "$5" \
        --seed "$seed" --jobs "$jobs" --quiet --no-wall-time --csv "$6.tmp" && mv "$6.tmp" "$6"
}

table() {  # table <title> <threshold> <csv>...
    local title=$1 thr=$2; shift 2
    echo
    echo "### $title"
    "$exp" table --scenario "$title" --learned-steps "$thr" --csv "$@"
}

for scn in paper-lab paper-sim; do
    if [ $scn = paper-lab ]; then sets=$lab_sets eps=20 thr=50; else sets=$sim_sets eps=60 thr=500; fi
    d=$out/$scn; mkdir -p "$d"
    csvs=()
    for n in 5 1000; do
        for a in dyna-q dyna-qpc; do
            train $scn $a $n $sets $eps "$d/$a-p$n.csv"; csvs+=("$d/$a-p$n.csv")
        done
    done
    train $scn q 0 $sets $eps "$d/q-p0.csv"; csvs+=("$d/q-p0.csv")
    # Idle time with the MCU's cost modelled (--planning 0): Dyna-Q never runs out of work and
    # plans tens of thousands of updates per real step (a minute or so per set here).
    for a in dyna-q dyna-qpc; do
        train $scn $a 0 $sets $eps "$d/$a-p0.csv"; csvs+=("$d/$a-p0.csv")
    done
    table "$scn ($sets sets x $eps episodes, seed $seed)" $thr "${csvs[@]}"
done

# Evaluation rooms: both Dyna agents at 1,000 planning updates per real step.
for robot in paper-lab paper-sim; do
    if [ $robot = paper-lab ]; then sets=$room_lab_sets eps=20 thr=50 n=99; else sets=$room_sim_sets eps=$room_sim_eps thr=500 n=$sim_rooms; fi
    ((quick)) && n=2
    d=$out/eval-$robot; mkdir -p "$d"
    rooms=$(ls "$root"/host_sim/rooms/eval/$robot-*.scn | head -n $n)
    for a in dyna-q dyna-qpc; do
        all=$d/$a-p1000.csv
        first=1 i=0
        for room in $rooms; do
            i=$((i + 1))
            c=$d/$(basename "$room" .scn)-$a.csv
            train "$room" $a 1000 $sets $eps "$c"
            # One CSV over all rooms: room i's set k becomes set 1000 i + k.
            if ((first)); then head -1 "$c" > "$all.tmp"; first=0; fi
            tail -n +2 "$c" | awk -F, -v OFS=, -v i=$i '{ $2 = 1000 * i + $2; print }' >> "$all.tmp"
        done
        mv "$all.tmp" "$all"
    done
    table "$robot evaluation rooms ($(echo $rooms | wc -w) rooms x $sets sets x $eps episodes, seed $seed)" $thr \
        "$d/dyna-q-p1000.csv" "$d/dyna-qpc-p1000.csv"
done
