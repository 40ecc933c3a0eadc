// SPDX-License-Identifier: MIT
// dynaqpc robot application: episodes and real steps.
#include "robot/controller.h"

#include <stddef.h>

// 0: the agent's action always (the controller before loops were left; docs/agent.md, 14.).
#ifndef ROBOT_LEAVE_LOOPS
#define ROBOT_LEAVE_LOOPS 1
#endif

void robot_ctrl_init(robot_ctrl_t *c, const robot_config_t *cfg, agent_t *agent)
{
    *c = (robot_ctrl_t){0};
    c->cfg = cfg;
    c->agent = agent;
    c->mode = ROBOT_MODE_IDLE;
    c->learning = true;
    robot_move_init(&c->move);
}

void robot_ctrl_start_episode(robot_ctrl_t *c)
{
    c->episode++;
    c->step = 0;
    c->bumps = 0;
    c->episode_reward = 0.0f;
    c->episode_start_us = UINT64_MAX;  // set at the first period
    c->safe_stop_held = false;
    c->mode = ROBOT_MODE_WAIT_FIX;
    c->recent_n = 0;
    c->recent_head = 0;
    robot_move_episode(&c->move);
}

void robot_ctrl_stop(robot_ctrl_t *c)
{
    c->mode = ROBOT_MODE_IDLE;
    c->safe_stop_held = false;
    robot_move_stop(&c->move);
}

void robot_ctrl_safe_stop(robot_ctrl_t *c)
{
    if (c->mode != ROBOT_MODE_SAFE_STOP) {
        c->safe_stops++;
        c->resume_mode = c->mode;
    }
    c->mode = ROBOT_MODE_SAFE_STOP;
    c->safe_stop_held = true;  // unlike a sensor's safe stop, only the operator lifts it
    robot_move_stop(&c->move);  // the step is dropped
}

// The action in `s`: the agent's (ε-greedy learning, greedy replaying), unless `s` came twice
// already within the episode's last real steps. Then the best-valued action taken least often from
// `s` within them: a loop (turning left and right on one spot, stepping back and forth between two
// cells, values planned through an outcome the state does not show) is left at its third visit. A
// frozen table cannot unlearn such a loop; a learning robot can, but only slowly, and a set that
// had learned relapsed into long episodes while it did (docs/agent.md, departure 14).
// With fixed steps (the paper's motion) a step often stays in its cell, and that is progress, not
// a return: there a run of `s` is one visit, and the rule acts only on arriving in `s`. Counting
// every step overruled a robot walking through a cell (paper-lab-motion, tuning seeds 11-15: 11
// of 40 sets learned against 25 without the rule, 24 counting arrivals).
FW_STATIC_ASSERT(FW_CFG_MAX_ACTIONS <= 4 && FW_CFG_LOOP_WINDOW <= 32, loop_ring_packs_actions_in_2_bits);
static uint8_t leave_loop_(robot_ctrl_t *c, agent_state_t s, uint8_t a)
{
    uint32_t visits = 0;
    uint32_t taken[FW_CFG_MAX_ACTIONS] = {0};
    const bool arrivals = c->cfg->aligned_actions == ROBOT_ACTIONS_FIXED;
    bool in_s = false;  // the ring's entry before the one read was `s`
    for (uint32_t k = 0; k < c->recent_n; k++) {
        const uint32_t i = (c->recent_head + FW_CFG_LOOP_WINDOW - c->recent_n + k) % FW_CFG_LOOP_WINDOW;
        const bool here = c->recent_s[i] == s;
        if (here) {
            visits += (arrivals && in_s) ? 0u : 1u;
            taken[(c->recent_a >> (2u * i)) & 3u]++;
        }
        in_s = here;
    }
    const bool arrived = !arrivals || !in_s;
    if (ROBOT_LEAVE_LOOPS && arrived && visits >= 2u) {
        uint8_t best = a;
        float best_q = agent_q(c->agent, s, a);
        for (uint8_t b = 0; b < c->agent->space->n_actions; b++) {
            const float q = agent_q(c->agent, s, b);
            if (taken[b] < taken[best] || (taken[b] == taken[best] && q > best_q)) {
                best = b;
                best_q = q;
            }
        }
        c->loop_escapes += best != a ? 1u : 0u;
        a = best;
    }
    c->recent_s[c->recent_head] = s;
    const uint32_t shift = 2u * c->recent_head;
    c->recent_a = (c->recent_a & ~((uint64_t)3u << shift)) | ((uint64_t)a << shift);
    c->recent_head = (uint8_t)((c->recent_head + 1u) % FW_CFG_LOOP_WINDOW);
    c->recent_n = c->recent_n < FW_CFG_LOOP_WINDOW ? (uint8_t)(c->recent_n + 1u) : c->recent_n;
    return a;
}

// Picks the action in state `s` and starts its step from `at`.
static void start_action_(robot_ctrl_t *c, agent_state_t s, const robot_pose_t *at,
                          const robot_sense_t *in)
{
    c->s = s;
    c->a = leave_loop_(c, s, c->learning ? agent_act(c->agent, s) : agent_act_greedy(c->agent, s));
    robot_move_step(&c->move, c->cfg, c->a, at, in);
}

static void end_episode_(robot_ctrl_t *c, uint64_t now, bool reached_goal)
{
    c->episode_done = true;
    c->last_episode = (robot_episode_report_t){
        .episode = c->episode,
        .steps = c->step,
        .reward = c->episode_reward,
        .reached_goal = reached_goal,
        .bumps = c->bumps,
        .start_us = c->episode_start_us,
        .end_us = now,
    };
    robot_ctrl_stop(c);
}

bool robot_ctrl_interrupt(robot_ctrl_t *c, uint64_t now_us)
{
    if (c->mode == ROBOT_MODE_IDLE) {
        return false;
    }
    if (c->episode_start_us == UINT64_MAX) {
        c->episode_start_us = now_us;  // cut before its first period
    }
    c->step_done = false;
    end_episode_(c, now_us, false);
    c->last_episode.interrupted = true;
    return true;
}

// The outcome of the pending step (or, at an episode's start, the first state) is observable at
// `at` (robot_move_period()): learn from it, and start the next step or end the episode.
static void observe_(robot_ctrl_t *c, const robot_sense_t *in, const robot_pose_t *at)
{
    const robot_config_t *cfg = c->cfg;
    const agent_state_t s_next =
        robot_encode_state(cfg, at, robot_range_code(cfg, in->range_m, in->n_ranges));
    if (!robot_move_pending(&c->move)) {
        start_action_(c, s_next, at, in);  // the episode's first state: nothing to learn yet
        c->last_step = (robot_step_report_t){s_next, c->a, 0.0f, 0};
        c->step_done = true;
        return;
    }
    const bool goal = robot_in_goal(cfg, at);
    const bool bumped = robot_move_bumped(&c->move);
    // The goal outranks a bump on the way in: reaching it ends the episode either way.
    const float r = goal ? cfg->reward_goal : bumped ? cfg->reward_bump : cfg->reward_step;
    c->bumps += bumped ? 1u : 0u;
    if (c->learning) {
        agent_observe(c->agent, c->s, c->a, r, s_next, goal);
    }
    c->step++;
    c->episode_reward += r;
    if (c->learning && cfg->planning > 0u) {
        (void)agent_plan(c->agent, cfg->planning);  // Fig. 3: N updates, then the next action
    } else if (c->learning) {
        // Idle-time planning: the first updates before the next action is chosen, so that it
        // acts on what this step taught, as with N; the idle time after plans on. (Choosing
        // first, Dyna-QPC took 611 real steps to learn on the paper-lab tuning rooms against 520
        // with these 64 first; 72 sets, docs/results/paper-lab.md.)
        (void)agent_plan(c->agent, ROBOT_PLAN_BEFORE_ACT);
    }
    if (goal || c->step >= cfg->step_cap) {
        c->last_step = (robot_step_report_t){s_next, 0, r, c->step};
        c->step_done = true;
        end_episode_(c, in->now_us, goal);
        return;
    }
    start_action_(c, s_next, at, in);
    c->last_step = (robot_step_report_t){s_next, c->a, r, c->step};
    c->step_done = true;
}

void robot_ctrl_period(robot_ctrl_t *c, const robot_sense_t *in, float *v_left, float *v_right)
{
    c->step_done = false;
    c->episode_done = false;
    if (c->mode != ROBOT_MODE_IDLE) {
        if (c->episode_start_us == UINT64_MAX) {
            c->episode_start_us = in->now_us;
            robot_move_placed(&c->move, in->now_us);
        }
        // Safety first: without the bus or a recent pose the robot does not know where it is
        // going, and without its ranges what is ahead (the last ranges would still encode the
        // state, and a step drive on them). A pose can be missing for a while when waiting for a
        // fix; not when driving.
        const bool pose_lost = !in->pose_ok && in->now_us - in->pose_time_us > c->cfg->pose_timeout_us;
        if (!in->bus_ok || in->ranges_silent || pose_lost) {
            if (c->mode != ROBOT_MODE_SAFE_STOP) {
                c->safe_stops++;
                c->resume_mode = c->mode;
                c->mode = ROBOT_MODE_SAFE_STOP;
            }
        } else if (c->mode == ROBOT_MODE_SAFE_STOP && !c->safe_stop_held) {
            // Back. An action the stop cut short has an unknown outcome: not learned from. One
            // that had ended (the robot stood still, waiting for its fix, as it did through the
            // stop) still has its outcome to observe: the wait goes on where it was.
            robot_move_cut(&c->move, in->now_us);
            c->mode = ROBOT_MODE_WAIT_FIX;
        }
    }
    if (c->mode != ROBOT_MODE_IDLE) {
        // The step's motion, one period of it (robot_move.h); its outcome observed when there.
        robot_pose_t at;
        const bool halted = c->mode == ROBOT_MODE_SAFE_STOP;
        if (robot_move_period(&c->move, c->cfg, in, halted, &at) == ROBOT_MOVE_ARRIVED) {
            observe_(c, in, &at);
        }
        if (c->mode != ROBOT_MODE_IDLE && c->mode != ROBOT_MODE_SAFE_STOP) {
            c->mode = c->move.phase == ROBOT_MOVE_DRIVING ? ROBOT_MODE_ACTING : ROBOT_MODE_WAIT_FIX;
        }
    }
    // The move's wheels: stopped whenever the controller is idle (it stopped the move).
    *v_left = c->move.v_left;
    *v_right = c->move.v_right;
}

bool robot_ctrl_plan(robot_ctrl_t *c)
{
    if (c->cfg->planning > 0u || !c->learning) {
        return false;
    }
    return agent_plan_step(c->agent);
}
