#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The frozen greedy replay benchmark (docs/results/replay.md): for each training seed, train one set of
# 20 episodes, save the flash image, and drive its frozen greedy table from 30 random starts
# (`dynaqpc-sim run`, seed 7, the scenario's 200-step cap). Prints, over all starts, how many
# reached the goal and how many within 50 steps.
#
#   tools/bench_replay.sh [--scenario S] [--agent A] [--planning N] [--seeds FIRST COUNT] [--out DIR]
#
# Defaults: paper-lab, dyna-qpc, N = 1,000, seeds 9001..9048 (never tuned on). Needs the
# host-release build (cmake --build --preset host-release).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
sim=$root/build/host-release/bin/dynaqpc-sim
scenario=paper-lab agent=dyna-qpc planning=1000 first=9001 count=48 out=
. "$root/tools/script_options.sh"
script_options "usage: tools/bench_replay.sh [--scenario S] [--agent A] [--planning N] [--seeds FIRST COUNT] [--out DIR]" \
    "--scenario=scenario --agent=agent --planning=planning --seeds=first,count --out=out" "$@" || exit 2
[ -x "$sim" ] || { echo "bench_replay.sh: build host-release first ($sim missing)" >&2; exit 2; }
[[ $planning =~ ^[0-9]+$ && $first =~ ^[0-9]+$ && $count =~ ^[1-9][0-9]*$ ]] ||
    { echo "bench_replay.sh: --planning and --seeds take whole numbers" >&2; exit 2; }
if [ -z "$out" ]; then
    out=$(mktemp -d)
    trap 'rm -rf "$out"' EXIT
fi
mkdir -p "$out"

one() {  # one <seed>: train, save, replay; the replay CSV is $out/replay-<seed>.csv
    local k=$1
    "$sim" train --scenario "$scenario" --agent "$agent" --planning "$planning" --sets 1 \
        --episodes 20 --seed "$k" --quiet --save "$out/learned-$k.flash"
    "$sim" run --scenario "$scenario" --agent "$agent" --load "$out/learned-$k.flash" --starts 30 \
        --seed 7 > "$out/replay-$k.csv" 2>/dev/null
}
export -f one
export sim scenario agent planning out
seq "$first" $((first + count - 1)) | xargs -P 2 -I{} bash -c 'one {}'

# start,steps,reached_goal,bumps,robot_time_s
cat "$out"/replay-*.csv | awk -F, -v what="$agent on $scenario, N = $planning, seeds $first..$((first + count - 1))" '
    $1 == "start" { next }
    { n++; if ($3 == 1) { reached++; if ($2 <= 50) within++ } }
    END {
        if (n == 0) { print "bench_replay.sh: no replay rows" > "/dev/stderr"; exit 1 }
        printf "%s: frozen greedy replay from %d starts: reached the goal %d (%.1f %%), within 50 steps %d (%.1f %%)\n",
            what, n, reached, 100 * reached / n, within, 100 * within / n
    }'
