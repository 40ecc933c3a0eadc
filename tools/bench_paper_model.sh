#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The paper's Dyna-QPC: Dyna-QPC with the paper's CMAC-Model and CMAC-R
# (`--model paper`) against table-based Dyna-Q (`--agent dyna-q`) and against Dyna-QPC with our
# model (the default, `--model relocatable`), at the same planning budget, on paper-lab
# (20 sets x 20 episodes) and paper-sim (8 sets x 60 episodes), on a seed no choice was tuned on.
#
#   tools/bench_paper_model.sh [--seed S] [--budgets 5[,1000]] [--out DIR] [--jobs J] [--quick]
#
# Prints one markdown table per budget: sets learned, mean real steps (paper-lab) or robot hours
# (paper-sim) to learn, mean and median over the sets, a set that never learns counting its whole run (learned: trailing
# 5-episode mean <= 50 steps, paper-lab, or <= 500, paper-sim), the ratio to Dyna-Q's, and the mean
# steps per episode over the whole run (the area under the learning curve, no threshold). Needs
# the host-release build and python3.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
sim=$root/build/host-release/bin/dynaqpc-sim
seed=9005 out=$root/results/paper-model budgets=5 jobs=2 quick=0
. "$root/tools/script_options.sh"
script_options "usage: tools/bench_paper_model.sh [--seed S] [--budgets 5[,1000]] [--out DIR] [--jobs J] [--quick]" \
    "--seed=seed --budgets=budgets --out=out --jobs=jobs --quick=quick:1" "$@" || exit 2
[ -x "$sim" ] || { echo "bench_paper_model.sh: build host-release first ($sim missing)" >&2; exit 2; }
lab_sets=20 lab_eps=20 sim_sets=8 sim_eps=60
((quick)) && lab_sets=2 lab_eps=5 sim_sets=1 sim_eps=2
mkdir -p "$out"

# name:agent:model:tiles ("": the firmware's default, the range code 2 values wide)
variants=("dyna-q:dyna-q::" "paper:dyna-qpc:paper:" "paper-xy:dyna-qpc:paper:1,1,0,0" "paper-exact:dyna-qpc:paper:0,0,0,0"
          "ours:dyna-qpc:relocatable:")

run() {  # run <variant> <scenario> <sets> <episodes> <budget> <csv>
    local name agent model tiles
    IFS=: read -r name agent model tiles <<<"$1"
    [ -s "$6" ] && return 0
    nice -n 10 "$sim" train --scenario "$2" --agent "$agent" ${model:+--model "$model"} ${tiles:+--model-tiles "$tiles"} --planning "$5" \
        --sets "$3" --episodes "$4" --seed "$seed" --jobs "$jobs" --quiet --no-wall-time --csv "$6.tmp" &&
        mv "$6.tmp" "$6"
}

IFS=, read -r -a budget_list <<<"$budgets"
for n in "${budget_list[@]}"; do
    for v in "${variants[@]}"; do
        name=${v%%:*}
        run "$v" paper-lab $lab_sets $lab_eps "$n" "$out/paper-lab-N$n-$name.csv"
        run "$v" paper-sim $sim_sets $sim_eps "$n" "$out/paper-sim-N$n-$name.csv"
    done
done

PYTHONPATH=$root/tools python3 - "$out" "$seed" "$budgets" "$lab_sets x $lab_eps" "$sim_sets x $sim_eps" <<'EOF'
import collections, csv, statistics, sys
from dynaqpc_tools.experiment.stats import learned_episode_index

out, seed, budgets, lab, simp = sys.argv[1], sys.argv[2], sys.argv[3].split(","), sys.argv[4], sys.argv[5]

def measure(path, thr, hours):
    rows = collections.defaultdict(list)
    for r in csv.DictReader(open(path)):
        rows[r["set"]].append((int(r["steps"]), float(r["robot_time_s"])))
    cost, learned, per_episode = [], 0, []
    for ep in rows.values():
        steps = [e[0] for e in ep]
        i = learned_episode_index(steps, thr, 5)
        n = len(steps) if i is None else i + 1
        cost.append(sum(e[1] for e in ep[:n]) / 3600 if hours else sum(steps[:n]))
        learned += i is not None
        per_episode.append(sum(steps) / len(steps))
    return learned, len(cost), sum(cost) / len(cost), statistics.median(cost), sum(per_episode) / len(per_episode)

for n in budgets:
    print(f"| N = {n}, seed {seed} | paper-lab ({lab}, threshold 50) | paper-sim ({simp}, threshold 500) |")
    print("|---|---|---|")
    base = {}
    for name, label in (("dyna-q", "Dyna-Q (table, random replay)"),
                        ("paper", "Dyna-QPC, the paper's model (`--model paper`, range code tiles 2 wide)"),
                        ("paper-xy", "the same, x and y tiles 2 cells wide (`--model-tiles 1,1,0,0`)"),
                        ("paper-exact", "the same, exact tiles (`0,0,0,0`: the 16 tilings collapse into one)"),
                        ("ours", "Dyna-QPC, our model (`--model relocatable`)")):
        cells = []
        for scen, thr, hours in (("paper-lab", 50, False), ("paper-sim", 500, True)):
            learned, sets, cost, median, mean_steps = measure(f"{out}/{scen}-N{n}-{name}.csv", thr, hours)
            base.setdefault(scen, cost) if name == "dyna-q" else None
            ratio = cost / base[scen] if base.get(scen) else float("nan")
            amount = f"{cost:.2f} h (median {median:.2f})" if hours else f"{cost:,.0f} steps (median {median:,.0f})"
            cells.append(f"{learned}/{sets} learned, {amount} to learn ({ratio:.2f} x Dyna-Q), "
                         f"{mean_steps:,.0f} steps/episode")
        print(f"| {label} | " + " | ".join(cells) + " |")
    print()
    # The paper's Fig. 13 reads the curves at about 50 episodes: Dyna-QPC within 500 steps,
    # Dyna-Q about 1,000. The same reading here: mean steps per episode, episodes 46-55.
    cells = []
    for name in ("dyna-q", "paper", "paper-xy", "paper-exact", "ours"):
        by_ep = collections.defaultdict(list)
        for r in csv.DictReader(open(f"{out}/paper-sim-N{n}-{name}.csv")):
            by_ep[int(r["episode"])].append(int(r["steps"]))
        window = [x for e in range(46, 56) for x in by_ep.get(e, [])]
        cells.append(f"{name} {statistics.mean(window):,.0f}" if window else f"{name} -")
    print(f"paper-sim, N = {n}, mean steps per episode over episodes 46-55 (the paper's Fig. 13 at ~50 "
          f"episodes: Dyna-QPC < 500, Dyna-Q ~1,000): " + ", ".join(cells))
    print()
EOF
