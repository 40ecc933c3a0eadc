# SPDX-License-Identifier: MIT
"""The tool's end of the end-to-end test: listens on the virtual CAN bus with python-can, decodes
the firmware's telemetry with docs/dynaqpc.dbc (cantools), and checks that the robot completed
episodes, that each TLM_EPISODE agrees with the TLM_LEARN frames of its steps, and that every
TOOL_CMD on the bus (the supervisor's START_EPISODE) was answered by a TOOL_ACK; with
--idle-planning, that TLM_SCHED reports planning updates (PlanUpdates > 0 in some frame). Deadline misses are reported, not failed: on a shared host they are the host's.

Prints "ready" once it has joined the bus. Exit 0: --episodes episodes seen and consistent;
1: an inconsistency or too few episodes before --timeout (each problem on its own line).
"""
import argparse
import sys
import time

import can
import cantools


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--dbc", required=True)
    ap.add_argument("--episodes", type=int, default=2)
    ap.add_argument("--step-cap", type=int, required=True)
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--arena", type=float, nargs=2, default=(8.0, 8.0), help="width height, m")
    ap.add_argument("--rewards", type=int, nargs=3, default=(-100, 100, -1), help="bump goal step")
    ap.add_argument("--idle-planning", action="store_true",
                    help="the firmware plans in idle time (the shipped scenarios' planning 0): TLM_SCHED "
                         "must report PlanUpdates > 0")
    args = ap.parse_args()

    db = cantools.database.load_file(args.dbc)
    pose_id = db.get_message_by_name("TLM_POSE").frame_id
    learn_id = db.get_message_by_name("TLM_LEARN").frame_id
    episode_id = db.get_message_by_name("TLM_EPISODE").frame_id
    cmd_id = db.get_message_by_name("TOOL_CMD").frame_id
    ack_id = db.get_message_by_name("TOOL_ACK").frame_id
    pending = {}       # (Command, Counter) of a TOOL_CMD not answered yet -> when seen
    answered = 0
    sched_id = db.get_message_by_name("TLM_SCHED").frame_id
    bump_r, goal_r, step_r = args.rewards

    bus = can.Bus(interface="udp_multicast", channel="239.74.163.2",
                  hop_limit=0)
    print("ready", flush=True)
    learns = {}        # episode (mod 2048) -> list of decoded TLM_LEARN, in arrival order
    episodes = []
    poses = 0
    poses_outside = 0
    scheds = 0
    sched_planning = 0      # TLM_SCHED frames with PlanUpdates > 0
    plan_updates = 0        # summed over all TLM_SCHED frames
    max_misses = 0
    problems = []
    deadline = time.monotonic() + args.timeout
    try:
        while len(episodes) < args.episodes and time.monotonic() < deadline:
            msg = bus.recv(timeout=0.5)
            if msg is None or msg.is_extended_id:
                continue
            if msg.arbitration_id == pose_id:
                p = db.decode_message(pose_id, msg.data, decode_choices=False)
                poses += 1
                if p["FixState"] == 0 and not (0 <= p["X"] <= args.arena[0] * 1000 and 0 <= p["Y"] <= args.arena[1] * 1000):
                    poses_outside += 1
            elif msg.arbitration_id == sched_id:
                sc = db.decode_message(sched_id, msg.data, decode_choices=False)
                scheds += 1
                plan_updates += int(sc["PlanUpdates"])
                sched_planning += int(sc["PlanUpdates"]) > 0
                max_misses = max(max_misses, int(sc["DeadlineMisses"]))
            elif msg.arbitration_id == learn_id:
                m = db.decode_message(learn_id, msg.data, decode_choices=False)
                learns.setdefault(int(m["Episode"]), []).append(m)
            elif msg.arbitration_id == cmd_id:
                c = db.decode_message(cmd_id, msg.data, decode_choices=False)
                pending[(int(c["Command"]), int(c["Counter"]))] = time.monotonic()
            elif msg.arbitration_id == ack_id:
                a = db.decode_message(ack_id, msg.data, decode_choices=False)
                if pending.pop((int(a["Command"]), int(a["Counter"])), None) is not None:
                    answered += 1
            elif msg.arbitration_id == episode_id:
                e = db.decode_message(episode_id, msg.data, decode_choices=False)
                episodes.append(e)
                print("TLM_EPISODE", {k: (int(v) if not isinstance(v, str) else v) for k, v in e.items()}, flush=True)
    finally:
        bus.shutdown()

    if len(episodes) < args.episodes:
        problems.append(f"only {len(episodes)} of {args.episodes} episodes ended within {args.timeout} s")
    if poses == 0:
        problems.append("no TLM_POSE frame seen")
    if answered == 0:
        problems.append("no TOOL_CMD answered by a TOOL_ACK")
    stale = [k for k, t in pending.items() if time.monotonic() - t > 2.0]
    if stale:
        problems.append(f"TOOL_CMDs (command, counter) never answered: {stale}")
    if poses_outside:
        problems.append(f"{poses_outside} fresh TLM_POSE frames outside the arena")
    if args.idle_planning:
        if scheds == 0:
            problems.append("no TLM_SCHED frame seen")
        elif sched_planning == 0:
            problems.append(f"TLM_SCHED: PlanUpdates 0 in all {scheds} frames: the firmware does not plan")
    for e in episodes:
        n = int(e["Episode"])
        steps = learns.get(n % 2048, [])
        name = f"episode {n}"
        if not steps:
            problems.append(f"{name}: no TLM_LEARN frames")
            continue
        # Step 0 reports a start state (nothing learned, reward 0): the episode's first, and the
        # first after a safe stop cut an action short (a loaded host can starve the bus for the
        # motor timeout). Steps 1..n are the real steps, each with its reward, in order.
        step_numbers = [int(s["Step"]) for s in steps]
        starts = [s for s in steps if int(s["Step"]) == 0]
        if step_numbers[0] != 0:
            problems.append(f"{name}: the first TLM_LEARN is step {step_numbers[0]}, not the start state 0")
        for s in starts:
            if int(s["Reward"]) != 0:
                problems.append(f"{name}: a start state's TLM_LEARN carries reward {int(s['Reward'])}")
        steps = [s for s in steps if int(s["Step"]) >= 1]
        real_numbers = [int(s["Step"]) for s in steps]
        if real_numbers != list(range(1, len(steps) + 1)):
            problems.append(f"{name}: TLM_LEARN real steps are not 1..n in order: {step_numbers}")
        if len(starts) > 1:
            print(f"{name}: {len(starts) - 1} restart(s) after a safe stop", flush=True)
        rewards = [int(s["Reward"]) for s in steps]
        if not steps:
            problems.append(f"{name}: no real step")
            continue
        if int(e["Steps"]) != len(steps):
            problems.append(f"{name}: TLM_EPISODE says {int(e['Steps'])} steps, TLM_LEARN frames of {len(steps)} real steps seen")
        if int(e["TotalReward"]) != sum(rewards):
            problems.append(f"{name}: TLM_EPISODE total reward {int(e['TotalReward'])}, TLM_LEARN rewards sum to {sum(rewards)}")
        if int(e["Bumps"]) != rewards.count(bump_r):
            problems.append(f"{name}: TLM_EPISODE says {int(e['Bumps'])} bumps, {rewards.count(bump_r)} steps rewarded {bump_r}")
        goal = bool(int(e["ReachedGoal"]))
        if goal != (rewards[-1] == goal_r):
            problems.append(f"{name}: ReachedGoal {goal} but the last step's reward is {rewards[-1]}")
        if not goal and int(e["Steps"]) != args.step_cap:
            problems.append(f"{name}: ended without the goal after {int(e['Steps'])} steps, not the cap {args.step_cap}")
        if int(e["Steps"]) > args.step_cap:
            problems.append(f"{name}: {int(e['Steps'])} steps, more than the cap {args.step_cap}")
        bad = [r for r in rewards if r not in (bump_r, goal_r, step_r)]
        if bad:
            problems.append(f"{name}: rewards other than bump/goal/step: {bad[:5]}")
    for p in problems:
        print("FAIL:", p, flush=True)
    if not problems:
        print(f"ok: {len(episodes)} episodes consistent with {sum(len(v) for v in learns.values())} TLM_LEARN frames, "
              f"{poses} TLM_POSE frames, {answered} TOOL_CMDs answered; TLM_SCHED: {scheds} frames, "
              f"{sched_planning} with planning updates, {plan_updates} planning updates, {max_misses} deadline misses",
              flush=True)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
