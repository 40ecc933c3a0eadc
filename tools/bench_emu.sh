#!/bin/sh
# SPDX-License-Identifier: MIT
# Host = MCU, in the loop: the paper-lab firmware on the emulated board (QEMU
# netduinoplus2, `dynaqpc-emu run`) learns sets of `dynaqpc-sim train --seed S`, each set with that
# set's seed (`--set K`: the same start poses, sensor noise and agent seed as the lock-step build's
# set K), in real time and in a private network namespace each; then the lock-step build learns
# the same sets, and one table compares them: real steps in the run, real steps to learn
# (experiment's rule: the trailing 5-episode mean stays <= 50 steps), goals, bumps per step,
# planning updates per real step (and the board's idle loop's), the board's deadline misses and
# worst lateness, the firmware's heading error against the simulated robot's (the supervisor's
# PoseCheck), and the host's load average over the run (the board's timing depends on it).
#   tools/bench_emu.sh [--seed S] [--sets "1 2 3"] [--episodes E] [--out DIR] [--minutes M]
# Defaults: seed 1, sets 1 2 3, 20 episodes, results in build/bench-emu, at most 45 minutes a set.
# Builds needed: the cortex-m4 preset (the board's image) and host-release (dynaqpc-sim).
# Real time: 15-30 minutes a set once the board learns as the lock-step build does. Run it on a
# machine that is not busy, niced as the rest: QEMU's vCPU then gets the CPU when it needs it.
set -u
REPO=$(cd "$(dirname "$0")/.." && pwd)
SEED=1
SETS="1 2 3"
EPISODES=20
OUT=$REPO/build/bench-emu
MINUTES=45
. "$REPO/tools/script_options.sh"
script_options "usage: tools/bench_emu.sh [--seed S] [--sets \"1 2 3\"] [--episodes E] [--out DIR] [--minutes M] [--summary]" \
    "--seed=SEED --sets=SETS --episodes=EPISODES --out=OUT --minutes=MINUTES --summary=SUMMARY_ONLY:1" "$@" || exit 2
SIM=$REPO/build/host-release/bin/dynaqpc-sim
EMU=$REPO/.venv/bin/dynaqpc-emu
PY=$REPO/.venv/bin/python
for f in "$SIM" "$EMU" "$PY" "$REPO/build/cortex-m4/netduinoplus2/bin/dynaqpc-emu-paper-lab.elf"; do
    [ -e "$f" ] || { echo "bench_emu: $f missing (build host-release and cortex-m4, tools/dev.sh)" >&2; exit 2; }
done
mkdir -p "$OUT" || exit 2
if [ "${SUMMARY_ONLY:-0}" != 1 ]; then
    unshare -n true 2>/dev/null || { echo "bench_emu: cannot create a private network namespace (unshare -n)" >&2; exit 2; }
    for K in $SETS; do
        echo "bench_emu: set $K of seed $SEED on the emulated board ($(date -u +%H:%M:%S))"
        # The host's load while the board runs, every 30 s.
        ( while :; do cut -d' ' -f1 /proc/loadavg; sleep 30; done ) > "$OUT/load-$K.txt" &
        LOADPID=$!
        cd "$REPO" && unshare -n sh -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo && exec "$@"' netns \
            "$EMU" run --seed "$SEED" --set "$K" --episodes "$EPISODES" --duration $((MINUTES * 60)) \
            --report-s 60 > "$OUT/board-$K.log" 2>&1
        kill "$LOADPID" 2>/dev/null
        "$SIM" train --scenario paper-lab --agent dyna-qpc --seed "$SEED" --first-set "$K" --sets 1 \
            --episodes "$EPISODES" --counters --quiet --csv "$OUT/lockstep-$K.csv" 2> "$OUT/lockstep-$K.counters"
    done
fi
SETS="$SETS" EPISODES="$EPISODES" OUT="$OUT" REPO="$REPO" "$PY" - <<'EOF'
import os, re, statistics, sys
sys.path.insert(0, os.path.join(os.environ["REPO"], "tools"))
from dynaqpc_tools.experiment.stats import learned_episode_index
out, sets, n_ep = os.environ["OUT"], os.environ["SETS"].split(), int(os.environ["EPISODES"])

def to_learn(steps):
    i = learned_episode_index(steps, 50.0, smooth=5)
    return (sum(steps[: i + 1]), True) if i is not None else (sum(steps), False)

def row(name, steps, goals, bumps, per_step, idle_per, misses, late_ms, head, load):
    tl, ok = to_learn(steps)
    print(f"| {name} | {len(steps)} | {sum(steps):,} | {tl:,}{'' if ok else ' (not learned)'} | {goals} | "
          f"{bumps / max(1, sum(steps)):.2f} | {per_step} | {idle_per} | {misses} | {late_ms} | {head} | {load} |")
    return sum(steps), tl

print("| paper-lab, Dyna-QPC, idle time | episodes | real steps | real steps to learn | goals | bumps / step "
      "| planning updates / real step | idle loop's | misses | worst lateness (ms) | heading error, mean of episodes (deg) | load average |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
tot = {"board": [0, 0], "lock": [0, 0]}
for k in sets:
    board_done = False
    blog = os.path.join(out, f"board-{k}.log")
    if os.path.exists(blog):
        text = open(blog).read()
        eps = [dict(re.findall(r"(\w+)=([-\d.,]+)", l)) for l in text.splitlines() if re.match(r"devices: episode=\d", l)]
        steps = [int(e["steps"]) for e in eps][:n_ep]
        b = re.findall(r"emu: board: real_steps=(\d+) planning_updates=(\d+) per_real_step=([\d.]+) idle_loop_updates=\d+ "
                       r"idle_loop_per_real_step=([\d.]+)", text)
        rep = [dict(re.findall(r"(\w+)=(\d+)", l)) for l in text.splitlines() if l.startswith("board: report:") or l.startswith("board: final:")]
        last = rep[-1] if rep else {}
        heads = [float(e["head_err_mean_deg"]) for e in eps if "head_err_mean_deg" in e]
        loads = [float(x) for x in open(os.path.join(out, f"load-{k}.txt")).read().split()] if os.path.exists(os.path.join(out, f"load-{k}.txt")) else []
        s, t = row(f"board, set {k}", steps, sum(int(e["reached_goal"]) for e in eps[:n_ep]),
                   sum(int(e["bumps"]) for e in eps[:n_ep]), b[-1][2] if b else "?", b[-1][3] if b else "?",
                   last.get("misses", "?"), f"{int(last.get('control_worst_lateness_us', 0)) / 1000:.1f}",
                   f"{statistics.mean(heads):.1f}" if heads else "?",
                   f"{statistics.median(loads):.1f} (max {max(loads):.1f})" if loads else "?")
        if len(steps) == n_ep:
            tot["board"][0] += s; tot["board"][1] += t
            board_done = True
    csv = os.path.join(out, f"lockstep-{k}.csv")
    if os.path.exists(csv):
        rows = [l.split(",") for l in open(csv).read().splitlines()[1:]]
        steps = [int(r[3]) for r in rows]
        upd = sum(int(r[8]) for r in rows)
        cnt = open(os.path.join(out, f"lockstep-{k}.counters")).read()
        h = re.search(r"head_err_mean_deg=([\d.]+)", cnt)
        s, t = row(f"lock-step, set {k}", steps, sum(int(r[5]) for r in rows), sum(int(r[6]) for r in rows),
                   f"{(upd - sum(steps)) / max(1, sum(steps)):.1f}", "", "0", "", h.group(1) if h else "?", "")
        if board_done:
            tot["lock"][0] += s; tot["lock"][1] += t
if tot["lock"][0] and tot["board"][0]:
    print(f"\nboard / lock-step over the sets the board finished: real steps {tot['board'][0] / tot['lock'][0]:.2f}, "
          f"real steps to learn {tot['board'][1] / max(1, tot['lock'][1]):.2f}")
EOF
