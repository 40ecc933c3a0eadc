#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The far-goal benchmark: Q-learning, Dyna-Q and Dyna-QPC at the same planning budget
# per real step (N = 5, N = 1,000 and the MCU's idle time) on the far-goal evaluation rooms
# (host_sim/rooms/far-eval, never used for tuning), fresh seeds, the shipped settings (gamma auto).
# Prints one Table 1 per robot and budget (dynaqpc-experiment table: real steps and robot time
# to learn over ALL sets, sets learned), then each room's longest shortest path.
#
#   tools/bench_far.sh [--seed S] [--out DIR] [--set DIR] [--quick]
#
# A set that never learns counts its whole run. Lab robot: 5 sets x 20 episodes per room,
# learned at a trailing mean of 50 steps; sonar robot: 2 sets x 60 episodes, 500 steps (the
# protocol of bench_learning.sh). Idle time with Dyna-Q plans tens of thousands of updates per
# real step, so N = 5 and idle time run on a subset of each robot's rooms, every third one (one
# per family; --idle-rooms N, default 4); N = 1,000 runs on all of them.
# Needs the host-release build and the venv (tools/dev.sh setup).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
sim=$root/build/host-release/bin/dynaqpc-sim
exp=$root/.venv/bin/dynaqpc-experiment
seed=9002 out=$root/results/bench-far set=$root/host_sim/rooms/far-eval quick=0 idle_rooms=4
. "$root/tools/script_options.sh"
script_options "usage: tools/bench_far.sh [--seed S] [--out DIR] [--set DIR] [--idle-rooms N] [--quick]" \
    "--seed=seed --out=out --set=set --idle-rooms=idle_rooms --quick=quick:1" "$@" || exit 2
[ -x "$sim" ] || { echo "bench_far.sh: build host-release first ($sim missing)" >&2; exit 2; }
[ -x "$exp" ] || { echo "bench_far.sh: run tools/dev.sh setup first ($exp missing)" >&2; exit 2; }
[ -d "$set" ] || { echo "bench_far.sh: no room set $set" >&2; exit 2; }
lab_sets=5 lab_eps=20 sim_sets=2 sim_eps=60 rooms=99
((quick)) && lab_sets=1 sim_sets=1 sim_eps=10 rooms=2 idle_rooms=1

train() {  # train <scenario> <agent> <planning> <sets> <episodes> <csv>
    [ -s "$6" ] && return 0
    "$sim" train --scenario "$1" --agent "$2" --planning "$3" --sets "$4" --episodes "$5" \
        --seed "$seed" --jobs 2 --quiet --no-wall-time --csv "$6.tmp" && mv "$6.tmp" "$6"
}

# One CSV over rooms: room i's set k becomes set 1000 i + k.
concat() {  # concat <out> <csv>...
    local out=$1 i=0; shift
    head -1 "$1" > "$out.tmp"
    for c in "$@"; do
        i=$((i + 1))
        tail -n +2 "$c" | awk -F, -v OFS=, -v i=$i '{ $2 = 1000 * i + $2; print }' >> "$out.tmp"
    done
    mv "$out.tmp" "$out"
}

for robot in paper-lab paper-sim; do
    if [ $robot = paper-lab ]; then sets=$lab_sets eps=$lab_eps thr=50; else sets=$sim_sets eps=$sim_eps thr=500; fi
    d=$out/$robot; mkdir -p "$d"
    mapfile -t all < <(ls "$set"/$robot-*.scn | head -n $rooms)
    for budget in 5 1000 0; do
        list=("${all[@]}")
        if ((budget != 1000)); then  # a subset: every third room, one per family
            list=()
            for ((i = 1; i < ${#all[@]} && ${#list[@]} < idle_rooms; i += 3)); do list+=("${all[$i]}"); done
            ((${#list[@]})) || list=("${all[0]}")
        fi
        csvs=()
        agents="dyna-q dyna-qpc"
        ((budget == 1000)) && agents="q dyna-q dyna-qpc"
        for a in $agents; do
            n=$budget
            [ $a = q ] && n=0
            per=()
            for room in "${list[@]}"; do
                c=$d/$(basename "$room" .scn)-$a-p$budget.csv
                train "$room" $a $n $sets $eps "$c"
                per+=("$c")
            done
            label=$a-p$budget
            [ $a = q ] && label=q-p0
            concat "$d/$label.csv" "${per[@]}"
            csvs+=("$d/$label.csv")
        done
        what="N = $budget"
        ((budget == 0)) && what="idle time"
        echo
        echo "### $robot far-goal evaluation rooms, $what (${#list[@]} rooms x $sets sets x $eps episodes, seed $seed)"
        "$exp" table --scenario "$robot far-goal" --learned-steps $thr --csv "${csvs[@]}"
    done
    echo
    echo "longest shortest path from a start, in actions:"
    for room in "${all[@]}"; do
        printf '  %s %s\n' "$(basename "$room" .scn)" "$(grep -m1 -o 'longest_path_actions [0-9]*' "$room" | cut -d' ' -f2)"
    done
done
