#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Rooms like users' rooms: Dyna-QPC and Dyna-Q at the same planning budget (N = 1,000) on the
# lab robot's rooms of host_sim/rooms/users-eval (never tuned on), each as generated (encode auto)
# and with paper-lab's equal grid copied in (encode x 3 y 3, what a user who copies paper-lab
# gets). Prints, per agent and grid: sets learned, relapses after learning (per set: after the
# first 3 episodes running that reach the goal within 50 steps, the episodes that miss it or take
# over 100; docs/results/users-rooms.md), sets with 3 relapses in a row, and the mean real steps
# before learning over ALL sets (a set that never learns counts its whole run).
#
#   tools/bench_users.sh [--seed S] [--sets N] [--set DIR] [--out DIR]
#
# A room whose goal holds no cell centre on the equal grid is left out of the equal-grid rows
# (said so). Needs the host-release build and the venv (tools/dev.sh setup).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
sim=$root/build/host-release/bin/dynaqpc-sim
py=$root/.venv/bin/python
seed=9001 sets=10 set=$root/host_sim/rooms/users-eval out=$root/results/bench-users
. "$root/tools/script_options.sh"
script_options "usage: tools/bench_users.sh [--seed S] [--sets N] [--set DIR] [--out DIR]" \
    "--seed=seed --sets=sets --set=set --out=out" "$@" || exit 2
mkdir -p "$out/auto" "$out/equal" "$out/rooms-equal"
for room in "$set"/paper-lab-*.scn; do
    name=$(basename "$room" .scn)
    sed 's/^encode auto heading 4 sensor 3.*/encode x 3 y 3 heading 4 sensor 3/' "$room" > "$out/rooms-equal/$name.scn"
    for grid in auto equal; do
        file=$room
        [ "$grid" = equal ] && file=$out/rooms-equal/$name.scn
        for agent in dyna-qpc dyna-q; do
            if ! "$sim" train --scenario "$file" --agent "$agent" --planning 1000 --sets "$sets" --episodes 20 \
                --seed "$seed" --jobs 2 --quiet --no-wall-time --csv "$out/$grid/$name-$agent.csv" \
                --sets-csv "$out/$grid/$name-$agent.sets.csv" 2> "$out/$grid/$name-$agent.err"; then
                echo "left out: $name on the $grid grid: $(tail -1 "$out/$grid/$name-$agent.err")" >&2
                rm -f "$out/$grid/$name-$agent.sets.csv"
            fi
        done
    done
done
"$py" - "$out" <<'PY'
import csv, glob, statistics, sys
out = sys.argv[1]
print("| agent | grid | rooms | sets learned | relapses after learning | sets with 3+ in a row | mean real steps (all sets) |")
print("|---|---|---:|---:|---:|---:|---:|")
for agent in ("dyna-qpc", "dyna-q"):
    for grid in ("auto", "equal"):
        files = sorted(glob.glob(f"{out}/{grid}/*-{agent}.sets.csv"))
        rows = [r for f in files for r in csv.DictReader(open(f))]
        if not rows:
            continue
        learned = [r for r in rows if r["learned_episode"] != "0"]
        rel = sum(int(r["relapses"]) for r in learned)
        after = sum(int(r["episodes_after"]) for r in learned)
        runs = sum(1 for r in learned if int(r["longest_relapse_run"]) >= 3)
        steps = statistics.mean(int(r["steps_to_learn"]) for r in rows)
        print(f"| {agent} | {grid} | {len(files)} | {len(learned)}/{len(rows)} ({100 * len(learned) / len(rows):.0f} %) | "
              f"{rel}/{after} ({100 * rel / max(after, 1):.1f} %) | {runs} | {steps:,.0f} |")
PY
