#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Rooms that change (docs/results/changing-rooms.md): the robot learns one room, the room
# changes at episode K (`train --change-at K --changed FILE`), and the robot keeps learning.
#
#   tools/bench_change.sh block    [options]   a change that blocks the learned path
#   tools/bench_change.sh shortcut [options]   a shortcut opens
#
# block: for each training seed k, train one set of K-1 episodes in the first room and E more in
# the changed one (episodes K..K+E-1; the file saved), then drive from 50 random starts of the
# changed room (`dynaqpc-sim run --learn`, seed 7, the scenario's 200-step cap) still learning,
# and frozen. E = 0 (--after 0) is the robot that meets the change during the replay itself.
# Prints, over all starts, how many reached the goal; and, from the training CSVs, how many of the
# episodes K..K+E-1 (exploring, epsilon as the scenario's) reached it.
#
# shortcut: S sets of K-1+M episodes, the room changing at K, against S sets of the changed room
# from scratch (the shortcut's level: its mean steps over episodes K..K-1+M, the same episodes of
# a robot that always had the shortcut) and S sets of the first room all along. Prints the mean
# steps per block of 5 episodes of each, and, over 10-episode windows of the same episodes of the
# three runs, the episodes after the change until the changed run is half-way from the closed
# room's steps to the shortcut's, and until it is within 10 % of the shortcut's.
#
# Options: --robot paper-lab|paper-sim (which shipped change, default paper-lab), --agent A
# (default dyna-qpc), --planning N (default: the scenario's, idle-time planning), --change-at K
# (default 20), --after E (block: episodes in the changed room before the replay, default 8),
# --episodes M (shortcut: episodes from K on, default 40), --seeds FIRST COUNT (block: training
# seeds, default 9101 20; shortcut: the experiment seed and the sets, default 9101 20), --jobs J
# (default 2), --explore MODE and --kappa K (the exploration, egreedy, plan-bonus or act-bonus,
# and its bonus's scale: docs/agent.md; default the scenario's, egreedy; block passes them to the
# learning replay too), --profile exact|real (default exact: the shipped files; real: the robot of
# docs/scenarios.md "The realistic profile" in the same rooms: each file of the pair copied into a
# temp dir as its arena, obstacle and goal lines followed by every other line, comments left out, of
# host_sim/scenarios/<robot>-real.scn; the copies pass `dynaqpc-sim rooms --check A --changed B`,
# and paper-lab's copy trains byte for byte as paper-lab-real). Needs the host-release build.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
sim=$root/build/host-release/bin/dynaqpc-sim
changes=$root/host_sim/rooms/changes
scenarios=$root/host_sim/scenarios
mode=${1:-}
[[ $mode == block || $mode == shortcut ]] || { echo "bench_change.sh: block or shortcut first (see the header)" >&2; exit 2; }
shift
robot=paper-lab agent=dyna-qpc planning= K=20 after=8 episodes=40 first=9101 count=20 jobs=2 explore=() profile=exact
while (($#)); do
    case $1 in
        --robot) robot=$2; shift 2 ;;
        --agent) agent=$2; shift 2 ;;
        --planning) planning=$2; shift 2 ;;
        --change-at) K=$2; shift 2 ;;
        --after) after=$2; shift 2 ;;
        --episodes) episodes=$2; shift 2 ;;
        --seeds) first=$2 count=$3; shift 3 ;;
        --jobs) jobs=$2; shift 2 ;;
        --explore|--kappa) explore+=("$1" "$2"); shift 2 ;;
        --profile) profile=$2; shift 2 ;;
        *) echo "bench_change.sh: unknown option '$1'" >&2; exit 2 ;;
    esac
done
[ -x "$sim" ] || { echo "bench_change.sh: build host-release first ($sim missing)" >&2; exit 2; }
case $robot in
    paper-lab) blocked=$changes/paper-lab-box.scn ;;
    paper-sim) blocked=$changes/paper-sim-blocked.scn ;;
    *) echo "bench_change.sh: --robot paper-lab or paper-sim" >&2; exit 2 ;;
esac
[[ $profile == exact || $profile == real ]] || { echo "bench_change.sh: --profile exact or real" >&2; exit 2; }
room=$robot closed=$changes/$robot-door-closed.scn open=$changes/$robot-door-open.scn
plan=()
[ -z "$planning" ] || plan=(--planning "$planning")
plan+=("${explore[@]}")  # train and run --learn take them alike
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
if [[ $profile == real ]]; then
    realistic() {  # realistic <file>: prints <out>/<name>-real.scn, FILE's layout on the realistic robot
        local to
        to=$out/$(basename "$1" .scn)-real.scn
        {
            echo "# $(basename "$1" .scn) on the realistic profile: its arena, obstacle and goal lines, then"
            echo "# every other line of $robot-real.scn (tools/bench_change.sh --profile real)."
            grep -E '^(arena|obstacle|goal)[[:space:]]' "$1"
            grep -vE '^(arena|obstacle|goal)[[:space:]]|^[[:space:]]*(#|$)' "$scenarios/$robot-real.scn"
        } > "$to"
        echo "$to"
    }
    if [[ $mode == block ]]; then
        room=$(realistic "$scenarios/$robot.scn") blocked=$(realistic "$blocked")
        "$sim" rooms --check "$room" --changed "$blocked" > /dev/null
    else
        closed=$(realistic "$closed") open=$(realistic "$open")
        "$sim" rooms --check "$closed" --changed "$open" > /dev/null
    fi
fi
if [ -n "$planning" ]; then label="$agent, N = $planning"; else label="$agent, idle-time planning"; fi
((${#explore[@]} == 0)) || label="$label, ${explore[*]}"
[[ $profile == exact ]] || label="$label, the realistic profile"

if [[ $mode == block ]]; then
    one() {  # one <seed>
        local k=$1 n=$((K - 1 + after))
        if ((after > 0)); then
            "$sim" train --scenario "$room" --changed "$blocked" --change-at "$K" --agent "$agent" "${plan[@]}" \
                --sets 1 --episodes "$n" --seed "$k" --quiet --save "$out/l-$k.flash" --csv "$out/t-$k.csv"
        else
            "$sim" train --scenario "$room" --agent "$agent" "${plan[@]}" --sets 1 --episodes "$n" --seed "$k" \
                --quiet --save "$out/l-$k.flash"
        fi
        "$sim" run --scenario "$blocked" --agent "$agent" --load "$out/l-$k.flash" --starts 50 --seed 7 --learn \
            "${plan[@]}" > "$out/learn-$k.csv" 2>/dev/null
        "$sim" run --scenario "$blocked" --agent "$agent" --load "$out/l-$k.flash" --starts 50 --seed 7 \
            > "$out/frozen-$k.csv" 2>/dev/null
    }
    export -f one
    export sim room blocked agent K after out
    export plan_s="${plan[*]}"
    # arrays do not cross bash -c: rebuild plan from plan_s
    seq "$first" $((first + count - 1)) | xargs -P "$jobs" -I{} bash -c 'plan=($plan_s); one {}'
    what="$label on $robot -> $(basename "$blocked" .scn) at episode $K, $after episodes after it, seeds $first..$((first + count - 1))"
    for kind in learn frozen; do
        cat "$out"/$kind-*.csv | awk -F, -v what="$what" -v kind=$kind '
            $1 == "start" { next }
            { n++; if ($3 == 1) { reached++; if ($2 <= 50) within++ } }
            END { printf "%s: %s replay from %d starts of the changed room: reached the goal %d (%.1f %%), within 50 steps %d (%.1f %%)\n",
                  what, (kind == "learn" ? "learning (run --learn)" : "frozen"), n, reached, 100 * reached / n, within, 100 * within / n }'
    done
    if ((after > 0)); then
        cat "$out"/t-*.csv | awk -F, -v K="$K" -v what="$what" '
            $1 == "agent" || $3 < K { next }
            { n++; reached += $6; steps += $4 }
            END { printf "%s: training episodes %d.. in the changed room (exploring): %d of %d reached the goal (%.1f %%), mean %.1f steps\n",
                  what, K, reached, n, 100 * reached / n, steps / n }'
    fi
    exit 0
fi

# shortcut
n=$((K - 1 + episodes))
common=(--agent "$agent" "${plan[@]}" --sets "$count" --episodes "$n" --seed "$first" --jobs "$jobs" --quiet)
"$sim" train --scenario "$closed" --changed "$open" --change-at "$K" "${common[@]}" --csv "$out/change.csv"
"$sim" train --scenario "$open" "${common[@]}" --csv "$out/open.csv"
"$sim" train --scenario "$closed" "${common[@]}" --csv "$out/closed.csv"
awk -F, -v K="$K" -v n="$n" -v what="$label on $robot-door-closed -> door-open at episode $K, $count sets (seed $first)" '
    FNR == 1 { f++; next }
    { s[f, $3] += $4; c[f, $3]++ }
    END {
        for (e = 1; e <= n; e++) for (g = 1; g <= 3; g++) m[g, e] = s[g, e] / c[g, e]
        level = 0; for (e = K; e <= n; e++) level += m[2, e]; level /= (n - K + 1)
        before = 0; for (e = K - 5; e < K; e++) before += m[1, e]; before /= 5
        printf "%s\n", what
        printf "  mean steps per episode: before the change (episodes %d-%d) %.1f; the shortcut from scratch, episodes %d-%d (its level) %.1f\n",
            K - 5, K - 1, before, K, n, level
        printf "  %-14s %10s %10s %10s\n", "episodes", "changed", "open", "closed"
        for (e = K; e + 4 <= n; e += 5) {
            for (g = 1; g <= 3; g++) { b[g] = 0; for (i = e; i < e + 5; i++) b[g] += m[g, i]; b[g] /= 5 }
            printf "  %4d-%-9d %10.1f %10.1f %10.1f\n", e, e + 4, b[1], b[2], b[3]
        }
        # Over 10-episode windows ending at e, the same episodes of the three runs: how much of
        # the gap between the closed run and the open one that the changed run has closed.
        half = -1; near = -1
        for (e = K + 9; e <= n; e++) {
            cw = ow = dw = 0
            for (i = e - 9; i <= e; i++) { cw += m[1, i]; ow += m[2, i]; dw += m[3, i] }
            if (half < 0 && dw > ow && (dw - cw) >= 0.5 * (dw - ow)) half = e
            if (near < 0 && cw <= 1.1 * ow) near = e
        }
        h = "  half-way (10-episode mean of the changed run at least half-way from the closed run to the open one): "
        if (half < 0) printf "%snot within %d episodes after the change\n", h, n - K + 1
        else printf "%sepisodes %d-%d, %d episodes after the change\n", h, half - 9, half, half - K + 1
        h = "  at the shortcut level (10-episode mean within 10 %% of the open run): "
        if (near < 0) printf h "not within %d episodes after the change\n", n - K + 1
        else printf h "episodes %d-%d, %d episodes after the change\n", near - 9, near, near - K + 1
    }' "$out/change.csv" "$out/open.csv" "$out/closed.csv"
