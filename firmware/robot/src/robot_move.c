// SPDX-License-Identifier: MIT
// dynaqpc robot application: a real step's whole life on the wheels (robot_move.h).
#include "robot/robot_move.h"

#include <math.h>
#include <stddef.h>

#include "fw/fw_assert.h"
#include "fw/fw_util.h"

// The gyro's scale (robot_move_t.gyro_share): the mark of no heading yet this episode; a
// normalised least-mean-squares step, each line moving the share toward what that line alone
// says (the gyro's error over the rotation t) by ROBOT_GYRO_FIT_GAIN t^2 / (t^2 +
// ROBOT_GYRO_FIT_TURN^2) of the way; never beyond 10 %.
#define ROBOT_GYRO_UNSEEN 1.0e9f
#define ROBOT_GYRO_FIT_GAIN 0.05f
#define ROBOT_GYRO_FIT_TURN 3.1415927f
#define ROBOT_GYRO_FIT_MAX 0.1f

void robot_move_init(robot_move_t *mv)
{
    FW_ASSERT(mv != NULL);
    *mv = (robot_move_t){0};
    mv->phase = ROBOT_MOVE_IDLE;
    mv->gyro_last = ROBOT_GYRO_UNSEEN;
    robot_run_init(&mv->run);
}

static void wheels_(robot_move_t *mv, float vl, float vr)
{
    mv->v_left = vl;
    mv->v_right = vr;
}

void robot_move_episode(robot_move_t *mv)
{
    mv->phase = ROBOT_MOVE_STANDING;
    mv->pending = false;
    mv->bumped = false;
    mv->backing_off = false;
    mv->settle_phase = 0u;
    mv->run_check = false;
    mv->heading_offset = 0.0f;  // the operator gives the heading at a start
    mv->gyro_turned = 0.0f;
    mv->gyro_last = ROBOT_GYRO_UNSEEN;
    mv->stopped_at_us = 0;
    wheels_(mv, 0.0f, 0.0f);
}

// Why: the Cricket listener learns that the robot moved from the wheels (cricket_note_motion()),
// and a robot carried to its start never turned them, so a fix of ranges taken before is "fresh"
// and of where the last episode ended. On a third user's base (host_sim/rooms/drawn/
// paper-lab-own-base-*, seed 9301) 287 of 48,030 states were observed over 0.2 m from the robot,
// 218 of them at the pose where the last episode had ended; 25 since
// (docs/results/realistic-robot.md, "A fix from before the start").
void robot_move_placed(robot_move_t *mv, uint64_t now_us)
{
    mv->stopped_at_us = now_us;
}

void robot_move_stop(robot_move_t *mv)
{
    mv->phase = ROBOT_MOVE_IDLE;
    mv->pending = false;
    wheels_(mv, 0.0f, 0.0f);
}

void robot_move_cut(robot_move_t *mv, uint64_t now_us)
{
    if (mv->phase != ROBOT_MOVE_DRIVING) {
        return;  // it stood: the fix it waits for is still the step's outcome
    }
    mv->pending = false;
    mv->settle_phase = 0u;
    mv->stopped_at_us = now_us;
    mv->phase = ROBOT_MOVE_STANDING;
}

bool robot_move_pending(const robot_move_t *mv)
{
    return mv->pending;
}

bool robot_move_bumped(const robot_move_t *mv)
{
    return mv->bumped;
}

float robot_move_heading(const robot_move_t *mv, float gyro_heading_rad)
{
    FW_ASSERT(mv != NULL);
    return gyro_heading_rad + (mv->heading_offset - mv->gyro_share * mv->gyro_turned);
}

// Starts a motion (a step's, the back-off's, settling's): its wheel speeds held for its periods,
// or in closed loop (robot_closes_loop()), a drive holding `hold` unless on the grid.
static void start_(robot_move_t *mv, const robot_config_t *cfg, const robot_motion_t *m,
                   const robot_pose_t *pose, const robot_sense_t *in, float hold)
{
    mv->periods_left = m->periods;
    mv->phase = ROBOT_MOVE_DRIVING;
    if (robot_closes_loop(cfg)) {
        float vl, vr;
        robot_run_start(&mv->run, cfg, m, pose->heading, hold, in->odom_m, in->odom_ok, &vl, &vr);
        wheels_(mv, vl, vr);
    } else {
        wheels_(mv, m->v_left, m->v_right);
    }
}

void robot_move_step(robot_move_t *mv, const robot_config_t *cfg, uint8_t action,
                     const robot_pose_t *at, const robot_sense_t *sensed)
{
    FW_ASSERT(mv != NULL && cfg != NULL && at != NULL && sensed != NULL);
    mv->pending = true;
    mv->action = action;
    mv->bumped = false;
    mv->act_heading = at->heading;
    mv->x0 = at->x;
    mv->y0 = at->y;
    const robot_motion_t m = robot_action_motion(cfg, action, at);
    start_(mv, cfg, &m, at, sensed, at->heading);
}

// Before the first state of an episode (or after a stop cut a motion short), the robot settles
// onto the grid of aligned stops (robot_motion.h), one phase at a time, each from the pose the
// last one ended at. Returns whether a settling motion started.
static bool settle_(robot_move_t *mv, const robot_config_t *cfg, const robot_pose_t *pose,
                    const robot_sense_t *in)
{
    if (!robot_settles(cfg)) {
        return false;
    }
    while (mv->settle_phase < ROBOT_SETTLE_PHASES) {
        const robot_motion_t m = robot_settle_motion(cfg, mv->settle_phase, pose);
        mv->settle_phase++;
        if (m.periods > 0u) {
            start_(mv, cfg, &m, pose, in, pose->heading);
            return true;
        }
    }
    return false;
}

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

static float heading_from_fix_(robot_move_t *mv, const robot_config_t *cfg,
                               const robot_pose_t *pose)
{
    if (!(ROBOT_HEADING_FROM_FIX > 0.0f) || !robot_closes_loop(cfg) || !mv->pending || mv->bumped ||
        (mv->action != ROBOT_FORWARD && mv->action != ROBOT_BACKWARD)) {
        return 0.0f;
    }
    const float dx = pose->x - mv->x0, dy = pose->y - mv->y0;
    if (dx * dx + dy * dy < ROBOT_HEADING_FIX_MIN_M * ROBOT_HEADING_FIX_MIN_M) {
        return 0.0f;
    }
    float line = atan2f(dy, dx) + (mv->action == ROBOT_BACKWARD ? FW_PI_F : 0.0f);
    float e = fmodf(line - mv->run.hold, 2.0f * FW_PI_F);
    e = e > FW_PI_F ? e - 2.0f * FW_PI_F : e < -FW_PI_F ? e + 2.0f * FW_PI_F : e;
    if (fabsf(e) > 0.5f) {
        return 0.0f;  // not a straight step after all (a fix far off): no word on the heading
    }
    // The gyro's own error here (raw - true: the share's and the offset's parts put back) says
    // what share of the rotation since the start it is; a new share keeps the heading as it is
    // (the offset takes the difference) and applies to the rotation from here on.
    const float t = mv->gyro_turned;
    const float raw_err = mv->gyro_share * t - mv->heading_offset - e;
    float share = mv->gyro_share + ROBOT_GYRO_FIT_GAIN * (raw_err - mv->gyro_share * t) * t /
                                       (t * t + ROBOT_GYRO_FIT_TURN * ROBOT_GYRO_FIT_TURN);
    share = share > ROBOT_GYRO_FIT_MAX    ? ROBOT_GYRO_FIT_MAX
            : share < -ROBOT_GYRO_FIT_MAX ? -ROBOT_GYRO_FIT_MAX
                                          : share;
    mv->heading_offset += (share - mv->gyro_share) * t;
    mv->gyro_share = share;
    const float d = ROBOT_HEADING_FROM_FIX * e;
    mv->heading_offset += d;
    return d;
}

// The motion has ended and the robot stands with a usable fix: the heading takes what the fix
// says, then a step that bumped backs off, or a robot without a pending step settles; otherwise
// the outcome is observable at *at.
static robot_move_event_t arrive_(robot_move_t *mv, const robot_config_t *cfg,
                                  const robot_sense_t *in, robot_pose_t *at)
{
    *at = in->pose;
    at->heading += heading_from_fix_(mv, cfg, &in->pose);
    // A step that bumped backs off first (robot_motion.h): its outcome is observed where the
    // back-off ends, in the same cell, at the offset an aligned step leaves.
    if (mv->pending && mv->bumped && !mv->backing_off && robot_backs_off(cfg)) {
        const robot_motion_t m = robot_backoff_motion(cfg, mv->action, mv->act_heading, at);
        if (m.periods > 0u) {
            mv->backing_off = true;
            // In closed loop it holds the heading the bumped step held.
            start_(mv, cfg, &m, at, in, mv->run.hold);
            return ROBOT_MOVE_BUSY;
        }
    }
    mv->backing_off = false;
    if (!mv->pending && settle_(mv, cfg, at, in)) {
        return ROBOT_MOVE_BUSY;
    }
    return ROBOT_MOVE_ARRIVED;
}

static bool pose_usable_(const robot_config_t *cfg, const robot_sense_t *in)
{
    return in->pose_ok && in->now_us - in->pose_time_us <= cfg->pose_timeout_us;
}

static robot_move_event_t drive_(robot_move_t *mv, const robot_config_t *cfg,
                                 const robot_sense_t *in, robot_pose_t *at)
{
    if (mv->periods_left > 0u) {
        mv->periods_left--;
    }
    if (robot_closes_loop(cfg)) {
        float vl, vr;
        if (robot_run_period(&mv->run, cfg, in->pose.heading, in->odom_m, &vl, &vr)) {
            wheels_(mv, vl, vr);
        }
    }
    if (mv->periods_left > 0u) {
        return ROBOT_MOVE_BUSY;
    }
    if (!cfg->wait_for_fix && pose_usable_(cfg, in)) {
        return arrive_(mv, cfg, in, at);  // the pose as the motion ends is its outcome
    }
    // Stop and wait for a fix taken since (the lab robot always; the other without a pose).
    wheels_(mv, 0.0f, 0.0f);
    mv->stopped_at_us = in->now_us;
    mv->phase = ROBOT_MOVE_STANDING;
    mv->run_check = cfg->wait_for_fix && robot_closes_loop(cfg);
    return ROBOT_MOVE_BUSY;
}

static robot_move_event_t stand_(robot_move_t *mv, const robot_config_t *cfg,
                                 const robot_sense_t *in, robot_pose_t *at)
{
    if (mv->run_check) {
        // The robot stands: a motion that ended off its heading or distance is corrected
        // (robot_run_correction()); not after a step that bumped, unless this is its back-off.
        mv->run_check = false;
        float vl, vr;
        if ((!mv->bumped || mv->backing_off) &&
            robot_run_correction(&mv->run, cfg, in->pose.heading, in->odom_m, !mv->bumped, &vl,
                                 &vr)) {
            mv->periods_left = mv->run.periods_left;
            mv->phase = ROBOT_MOVE_DRIVING;
            wheels_(mv, vl, vr);
            return ROBOT_MOVE_BUSY;
        }
    }
    if (pose_usable_(cfg, in) && in->pose_time_us >= mv->stopped_at_us) {
        return arrive_(mv, cfg, in, at);
    }
    return ROBOT_MOVE_BUSY;
}

robot_move_event_t robot_move_period(robot_move_t *mv, const robot_config_t *cfg,
                                     const robot_sense_t *sensed, bool halted, robot_pose_t *at)
{
    FW_ASSERT(mv != NULL && cfg != NULL && sensed != NULL && at != NULL);
    mv->bumped = mv->bumped || sensed->bump;
    if (halted || mv->phase == ROBOT_MOVE_IDLE) {
        wheels_(mv, 0.0f, 0.0f);
        return ROBOT_MOVE_BUSY;
    }
    // The gyro's heading with what the Cricket fixes have said of it (heading_from_fix_()):
    // its scale's share of the rotation since the start, and the offset.
    if (robot_closes_loop(cfg)) {
        const float h = sensed->pose.heading;
        if (mv->gyro_last < ROBOT_GYRO_UNSEEN) {
            float dh = fmodf(h - mv->gyro_last, 2.0f * FW_PI_F);
            dh = dh > FW_PI_F ? dh - 2.0f * FW_PI_F : dh < -FW_PI_F ? dh + 2.0f * FW_PI_F : dh;
            mv->gyro_turned += dh;
        }
        mv->gyro_last = h;
    }
    robot_sense_t in = *sensed;
    in.pose.heading = robot_move_heading(mv, sensed->pose.heading);
    return mv->phase == ROBOT_MOVE_DRIVING ? drive_(mv, cfg, &in, at) : stand_(mv, cfg, &in, at);
}
