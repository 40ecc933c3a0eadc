// SPDX-License-Identifier: MIT
// dynaqpc robot application: episodes and real steps.
#include "robot/controller.h"

#include <math.h>
#include <stddef.h>

void robot_ctrl_init(robot_ctrl_t *c, const robot_config_t *cfg, agent_t *agent)
{
    *c = (robot_ctrl_t){0};
    c->cfg = cfg;
    c->agent = agent;
    c->mode = ROBOT_MODE_IDLE;
    c->learning = true;
    robot_run_init(&c->run);
}

static void wheels_(robot_ctrl_t *c, float vl, float vr)
{
    c->v_left = vl;
    c->v_right = vr;
}

void robot_ctrl_start_episode(robot_ctrl_t *c)
{
    c->episode++;
    c->step = 0;
    c->bumps = 0;
    c->episode_reward = 0.0f;
    c->have_s = false;
    c->bump_latched = false;
    c->settle_phase = 0u;
    c->run_check = false;
    c->heading_offset = 0.0f;  // the operator gives the heading at a start
    c->episode_start_us = UINT64_MAX;  // set at the first period
    c->stopped_at_us = 0;
    c->safe_stop_held = false;
    c->mode = ROBOT_MODE_WAIT_FIX;
    wheels_(c, 0.0f, 0.0f);
}

void robot_ctrl_stop(robot_ctrl_t *c)
{
    c->mode = ROBOT_MODE_IDLE;
    c->have_s = false;
    c->safe_stop_held = false;
    wheels_(c, 0.0f, 0.0f);
}

void robot_ctrl_safe_stop(robot_ctrl_t *c)
{
    if (c->mode != ROBOT_MODE_SAFE_STOP) {
        c->safe_stops++;
        c->resume_mode = c->mode;
    }
    c->mode = ROBOT_MODE_SAFE_STOP;
    c->safe_stop_held = true;  // unlike a sensor's safe stop, only the operator lifts it
    c->have_s = false;
    wheels_(c, 0.0f, 0.0f);
}

// Starts a motion (an action's, the back-off's, settling's): its wheel speeds held for its
// periods, or in closed loop (robot_closes_loop()), a drive holding `hold` unless on the grid.
static void motion_start_(robot_ctrl_t *c, const robot_motion_t *m, const robot_sense_t *in, float hold)
{
    c->periods_left = m->periods;
    c->mode = ROBOT_MODE_ACTING;
    if (robot_closes_loop(c->cfg)) {
        float vl, vr;
        robot_run_start(&c->run, c->cfg, m, in->pose.heading, hold, in->odom_m, in->odom_ok, &vl, &vr);
        wheels_(c, vl, vr);
    } else {
        wheels_(c, m->v_left, m->v_right);
    }
}

static void start_action_(robot_ctrl_t *c, agent_state_t s, const robot_sense_t *in)
{
    const robot_pose_t *pose = &in->pose;
    c->s = s;
    c->a = c->learning ? agent_act(c->agent, s) : agent_act_greedy(c->agent, s);
    c->have_s = true;
    c->bump_latched = false;
    c->act_heading = pose->heading;
    c->step_x0 = pose->x;
    c->step_y0 = pose->y;
    const robot_motion_t m = robot_action_motion(c->cfg, c->a, pose);
    motion_start_(c, &m, in, pose->heading);
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

// Before the first state of an episode (or after a stop cut a step short), the robot settles
// onto the grid of aligned stops (robot_motion.h), one phase at a time, each from the pose the
// last one ended at. Returns whether a settling motion started.
static bool settle_(robot_ctrl_t *c, const robot_sense_t *in)
{
    if (!robot_settles(c->cfg)) {
        return false;
    }
    while (c->settle_phase < ROBOT_SETTLE_PHASES) {
        const robot_motion_t m = robot_settle_motion(c->cfg, c->settle_phase, &in->pose);
        c->settle_phase++;
        if (m.periods > 0u) {
            motion_start_(c, &m, in, in->pose.heading);
            return true;
        }
    }
    return false;
}

// The outcome of the pending step (or, at an episode's start, the first state) is observable.
// Why the heading takes the Cricket's word: the gyro integrates its rate, and a scale error
// (a few per cent on a MEMS gyro) turns every turn into a heading error that nothing else
// removes. A straight step in closed loop goes along the heading the gyro held, so the line from
// the still fix before it to the still fix after it is the true heading the gyro called `hold`;
// a share of the difference goes into the heading (ROBOT_HEADING_FROM_FIX). Only steps of at
// least ROBOT_HEADING_FIX_MIN_M, which did not bump: over 30 cm two fixes 1-2 cm off give the
// line within ~4 degrees.
#ifndef ROBOT_HEADING_FROM_FIX
#define ROBOT_HEADING_FROM_FIX 0.2f
#endif
#define ROBOT_HEADING_FIX_MIN_M 0.3f

static float heading_from_fix_(robot_ctrl_t *c, const robot_sense_t *in)
{
    if (!(ROBOT_HEADING_FROM_FIX > 0.0f) || !robot_closes_loop(c->cfg) || !c->have_s || c->bump_latched ||
        (c->a != ROBOT_FORWARD && c->a != ROBOT_BACKWARD)) {
        return 0.0f;
    }
    const float dx = in->pose.x - c->step_x0, dy = in->pose.y - c->step_y0;
    if (dx * dx + dy * dy < ROBOT_HEADING_FIX_MIN_M * ROBOT_HEADING_FIX_MIN_M) {
        return 0.0f;
    }
    float line = atan2f(dy, dx) + (c->a == ROBOT_BACKWARD ? FW_PI_F : 0.0f);
    float e = fmodf(line - c->run.hold, 2.0f * FW_PI_F);
    e = e > FW_PI_F ? e - 2.0f * FW_PI_F : e < -FW_PI_F ? e + 2.0f * FW_PI_F : e;
    if (fabsf(e) > 0.5f) {
        return 0.0f;  // not a straight step after all (a fix far off): no word on the heading
    }
    const float d = ROBOT_HEADING_FROM_FIX * e;
    c->heading_offset += d;
    return d;
}

static void observe_(robot_ctrl_t *c, const robot_sense_t *sensed)
{
    const robot_config_t *cfg = c->cfg;
    robot_sense_t adjusted = *sensed;
    adjusted.pose.heading += heading_from_fix_(c, sensed);
    const robot_sense_t *in = &adjusted;
    // A step that bumped backs off first (robot_motion.h): its outcome is observed where the
    // back-off ends, in the same cell, at the offset an aligned step leaves.
    if (c->have_s && c->bump_latched && !c->backing_off && robot_backs_off(cfg)) {
        const robot_motion_t m = robot_backoff_motion(cfg, c->a, c->act_heading, &in->pose);
        if (m.periods > 0u) {
            c->backing_off = true;
            // In closed loop it holds the heading the bumped step held.
            motion_start_(c, &m, in, c->run.hold);
            return;
        }
    }
    c->backing_off = false;
    if (!c->have_s && settle_(c, in)) {
        return;
    }
    const agent_state_t s_next =
        robot_encode_state(cfg, &in->pose, robot_range_code(cfg, in->range_m, in->n_ranges));
    if (!c->have_s) {
        start_action_(c, s_next, in);  // the episode's first state: nothing to learn yet
        c->last_step = (robot_step_report_t){s_next, c->a, 0.0f, 0};
        c->step_done = true;
        return;
    }
    const bool goal = robot_in_goal(cfg, &in->pose);
    // The goal outranks a bump on the way in: reaching it ends the episode either way.
    const float r = goal ? cfg->reward_goal : c->bump_latched ? cfg->reward_bump : cfg->reward_step;
    c->bumps += c->bump_latched ? 1u : 0u;
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
    start_action_(c, s_next, in);
    c->last_step = (robot_step_report_t){s_next, c->a, r, c->step};
    c->step_done = true;
}

static bool pose_usable_(const robot_ctrl_t *c, const robot_sense_t *in)
{
    return in->pose_ok && in->now_us - in->pose_time_us <= c->cfg->pose_timeout_us;
}

void robot_ctrl_period(robot_ctrl_t *c, const robot_sense_t *sensed, float *v_left, float *v_right)
{
    // The gyro's heading with what the Cricket fixes have said of it (heading_from_fix_()).
    robot_sense_t adjusted = *sensed;
    adjusted.pose.heading += c->heading_offset;
    const robot_sense_t *in = &adjusted;
    c->step_done = false;
    c->episode_done = false;
    if (c->mode != ROBOT_MODE_IDLE) {
        if (c->episode_start_us == UINT64_MAX) {
            c->episode_start_us = in->now_us;
        }
        c->bump_latched = c->bump_latched || in->bump;
        // Safety first: without the bus or a recent pose the robot does not know where it is
        // going. A pose can be missing for a while when waiting for a fix; not when driving.
        const bool pose_lost = !in->pose_ok && in->now_us - in->pose_time_us > c->cfg->pose_timeout_us;
        if (!in->bus_ok || pose_lost) {
            if (c->mode != ROBOT_MODE_SAFE_STOP) {
                c->safe_stops++;
                c->resume_mode = c->mode;
                c->mode = ROBOT_MODE_SAFE_STOP;
            }
            wheels_(c, 0.0f, 0.0f);
        } else if (c->mode == ROBOT_MODE_SAFE_STOP && !c->safe_stop_held) {
            // Back. An action the stop cut short has an unknown outcome: not learned from. One
            // that had ended (the robot stood still, waiting for its fix, as it did through the
            // stop) still has its outcome to observe: the wait goes on where it was.
            if (c->resume_mode != ROBOT_MODE_WAIT_FIX) {
                c->have_s = false;
                c->settle_phase = 0u;
                c->stopped_at_us = in->now_us;
            }
            c->mode = ROBOT_MODE_WAIT_FIX;
        }
    }
    switch (c->mode) {
    case ROBOT_MODE_ACTING:
        if (c->periods_left > 0u) {
            c->periods_left--;
        }
        if (robot_closes_loop(c->cfg)) {
            float vl, vr;
            if (robot_run_period(&c->run, c->cfg, in->pose.heading, in->odom_m, &vl, &vr)) {
                wheels_(c, vl, vr);
            }
        }
        if (c->periods_left == 0u) {
            if (c->cfg->wait_for_fix) {
                wheels_(c, 0.0f, 0.0f);
                c->stopped_at_us = in->now_us;
                c->mode = ROBOT_MODE_WAIT_FIX;
                c->run_check = robot_closes_loop(c->cfg);
            } else if (pose_usable_(c, in)) {
                observe_(c, in);
            } else {
                wheels_(c, 0.0f, 0.0f);  // no pose to observe the outcome with: stop and wait
                c->stopped_at_us = in->now_us;
                c->mode = ROBOT_MODE_WAIT_FIX;
            }
        }
        break;
    case ROBOT_MODE_WAIT_FIX:
        if (c->run_check) {
            // The robot stands: a motion that ended off its heading or distance is corrected
            // (robot_run_correction()); not after a step that bumped, unless this is its back-off.
            c->run_check = false;
            float vl, vr;
            if ((!c->bump_latched || c->backing_off) &&
                robot_run_correction(&c->run, c->cfg, in->pose.heading, in->odom_m, !c->bump_latched, &vl, &vr)) {
                c->periods_left = c->run.periods_left;
                c->mode = ROBOT_MODE_ACTING;
                wheels_(c, vl, vr);
                break;
            }
        }
        if (pose_usable_(c, in) && in->pose_time_us >= c->stopped_at_us) {
            observe_(c, in);
        }
        break;
    case ROBOT_MODE_IDLE:
    case ROBOT_MODE_SAFE_STOP:
    default:
        wheels_(c, 0.0f, 0.0f);
        break;
    }
    *v_left = c->v_left;
    *v_right = c->v_right;
}

bool robot_ctrl_plan(robot_ctrl_t *c)
{
    if (c->cfg->planning > 0u || !c->learning) {
        return false;
    }
    return agent_plan_step(c->agent);
}
