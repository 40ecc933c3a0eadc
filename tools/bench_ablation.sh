#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The ablation: where Dyna-QPC's speed comes from. Every registered algorithm (the firmware's
# registry, `dynaqpc-sim agents --json`: Q-learning, Dyna-Q, Dyna-Q keeping the majority outcome,
# Dyna-QPC, ...; or those --agents names), and Dyna-QPC with each of its departures from the
# paper switched off in turn (`train --ablate`: generalise = the relocatable model's predictions for untried pairs, majority = tried pairs keep
# the majority outcome, new-states = a new state queues its pairs, expected = backups over a
# place's codes, stay = a step that stays in its cell is a share of its move) and all of them off (prioritized sweeping over the exact model with the complete
# predecessor search), at the same planning budget, on paper-lab and paper-lab-motion (the
# paper's own motion), paper-sim, and the lab evaluation rooms; fresh seeds.
#
#   tools/bench_ablation.sh [--seed S] [--out DIR] [--budget N] [--agents A,B,...] [--quick]
#
# Prints one markdown table: sets learned and mean real steps (lab) or robot hours (sonar robot)
# to learn, a set that never learns counting its whole run (learned: trailing 5-episode mean
# <= 50 steps, lab, or 500, sonar robot). Needs the host-release build and the venv.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
sim=$root/build/host-release/bin/dynaqpc-sim
py=$root/.venv/bin/python
seed=9003 out=$root/results/ablation budget=1000 quick=0 agents=""
. "$root/tools/script_options.sh"
script_options "usage: tools/bench_ablation.sh [--seed S] [--out DIR] [--budget N] [--agents A,B] [--quick]" \
    "--seed=seed --out=out --budget=budget --agents=agents --quick=quick:1" "$@" || exit 2
agents=${agents//,/ }
[ -x "$sim" ] || { echo "bench_ablation.sh: build host-release first ($sim missing)" >&2; exit 2; }
[ -x "$py" ] || { echo "bench_ablation.sh: run tools/dev.sh setup first ($py missing)" >&2; exit 2; }
lab_sets=20 sim_sets=4 sim_eps=40 room_sets=2 rooms=12
((quick)) && lab_sets=2 sim_sets=1 sim_eps=5 room_sets=1 rooms=1
mkdir -p "$out"

# The algorithms from the registry, so a new one is in the table without an edit here.
[ -n "$agents" ] || agents=$("$py" -c 'import sys; from dynaqpc_tools.agents import registry
print(" ".join(a["name"] for a in registry(sys.argv[1])))' "$sim")
variants=()
for a in $agents; do variants+=("$a:$a:"); done
variants+=("no-generalise:dyna-qpc:generalise" "no-majority:dyna-qpc:majority" "no-new-states:dyna-qpc:new-states"
          "no-expected:dyna-qpc:expected" "no-stay:dyna-qpc:stay"
          "exact-model:dyna-qpc:generalise,majority,new-states,expected,stay")

run() {  # run <label> <scenario> <sets> <episodes> <csv>
    local name agent ablate
    IFS=: read -r name agent ablate <<<"$1"
    [ -s "$5" ] && return 0
    local n=$budget
    [ "$agent" = q ] && n=0
    "$sim" train --scenario "$2" --agent "$agent" ${ablate:+--ablate "$ablate"} --planning "$n" \
        --sets "$3" --episodes "$4" --seed "$seed" --jobs 2 --quiet --no-wall-time --csv "$5.tmp" && mv "$5.tmp" "$5"
}

for v in "${variants[@]}"; do
    name=${v%%:*}
    run "$v" paper-lab $lab_sets 20 "$out/paper-lab-$name.csv"
    run "$v" paper-lab-motion $lab_sets 20 "$out/paper-lab-motion-$name.csv"
    run "$v" paper-sim $sim_sets $sim_eps "$out/paper-sim-$name.csv"
    for room in $(ls "$root"/host_sim/rooms/eval/paper-lab-*.scn | head -n $rooms); do
        run "$v" "$room" $room_sets 20 "$out/eval-$(basename "$room" .scn)-$name.csv"
    done
done

"$py" - "$out" "$budget" "$seed" "${variants[@]}" <<'EOF'
import collections, csv, glob, os, sys
sys.path.insert(0, os.path.join(os.path.dirname(sys.executable), "..", "..", "tools"))
from dynaqpc_tools.agents import labels
from dynaqpc_tools.experiment.stats import learned_episode_index

out, budget, seed = sys.argv[1:4]
names = [v.split(":")[0] for v in sys.argv[4:]]

def cell(files, thr, hours):
    sets = learned = 0
    cost = []
    for f in files:
        rows = collections.defaultdict(list)
        for r in csv.DictReader(open(f)):
            rows[r["set"]].append((int(r["steps"]), float(r["robot_time_s"])))
        for ep in rows.values():
            steps = [e[0] for e in ep]
            i = learned_episode_index(steps, thr, 5)
            n = len(steps) if i is None else i + 1
            cost.append(sum(e[1] for e in ep[:n]) / 3600 if hours else sum(steps[:n]))
            sets += 1
            learned += i is not None
    if not sets:
        return "—"
    mean = sum(cost) / len(cost)
    return f"{learned}/{sets}, {mean:.2f} h" if hours else f"{learned}/{sets}, {mean:,.0f}"

print(f"| variant (N = {budget}, seed {seed}) | paper-lab | paper-lab-motion | paper-sim | lab evaluation rooms |")
print("|---|---:|---:|---:|---:|")
label = labels()
for n in names:
    print(f"| {label.get(n, n)} | {cell([f'{out}/paper-lab-{n}.csv'], 50, False)} "
          f"| {cell([f'{out}/paper-lab-motion-{n}.csv'], 50, False)} "
          f"| {cell([f'{out}/paper-sim-{n}.csv'], 500, True)} "
          f"| {cell(sorted(glob.glob(f'{out}/eval-*-{n}.csv')), 50, False)} |")
print()
print("Cells: sets learned, mean real steps (lab) or robot hours (paper-sim) to learn over all sets.")
EOF
