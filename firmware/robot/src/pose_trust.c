// SPDX-License-Identifier: MIT
// dynaqpc robot application: pose trust and the straight leg (see pose_trust.h).
#include "robot/pose_trust.h"

#include <math.h>
#include <string.h>

#include "fw/fw_assert.h"

#define DEG_PER_RAD 57.2957795f
#define HALF_PI 1.5707964f

static float wrap180_(float deg)
{
    while (deg > 180.0f) {
        deg -= 360.0f;
    }
    while (deg <= -180.0f) {
        deg += 360.0f;
    }
    return deg;
}

void pose_trust_init(pose_trust_t *t, bool absolute)
{
    FW_ASSERT(t != NULL);
    memset(t, 0, sizeof *t);
    t->trusted = absolute;
    t->reason = absolute ? (uint8_t)POSE_TRUST_WHY_ABSOLUTE : (uint8_t)POSE_TRUST_WHY_BOOT;
}

void pose_trust_lose(pose_trust_t *t, pose_trust_reason_t reason)
{
    FW_ASSERT(t != NULL);
    if (t->reason == POSE_TRUST_WHY_ABSOLUTE) {
        return;
    }
    if (t->trusted) {
        t->losses++;
        t->losses_by[(uint32_t)reason & 3u]++;
    }
    t->trusted = false;
    t->reason = (uint8_t)reason;
    t->phase = POSE_TRUST_LEG_IDLE;
}

void pose_trust_grant(pose_trust_t *t, pose_trust_reason_t reason)
{
    FW_ASSERT(t != NULL);
    t->trusted = true;
    if (t->reason != POSE_TRUST_WHY_ABSOLUTE) {
        t->reason = (uint8_t)reason;
    }
    t->phase = POSE_TRUST_LEG_IDLE;
}

void pose_trust_cancel(pose_trust_t *t)
{
    FW_ASSERT(t != NULL);
    t->phase = POSE_TRUST_LEG_IDLE;
}

static float period_s_(const robot_config_t *cfg)
{
    return (float)cfg->period_us * 1e-6f;
}

static void turn_(pose_trust_t *t, const robot_config_t *cfg, float *v_left, float *v_right)
{
    const float w = HALF_PI / ((float)POSE_TRUST_TURN_PERIODS * period_s_(cfg));  // rad/s, counter-clockwise
    const float v = w * cfg->track_m * 0.5f;
    t->phase = POSE_TRUST_LEG_TURN;
    t->periods_left = (uint8_t)POSE_TRUST_TURN_PERIODS;
    *v_left = -v;
    *v_right = v;
}

static void stand_(pose_trust_t *t, pose_trust_phase_t phase, uint64_t now_us)
{
    t->phase = (uint8_t)phase;
    t->stopped_us = now_us;
}

// The leg's second fix: a track long enough gives the heading's correction and trust (true); a
// short one (the robot was blocked) turns and tries again.
static bool leg_end_(pose_trust_t *t, const robot_config_t *cfg, const pose_trust_in_t *in, float *v_left,
                     float *v_right, float *correction_deg)
{
    const float dx = in->x_m - t->ax_m;
    const float dy = in->y_m - t->ay_m;
    if (sqrtf(dx * dx + dy * dy) < POSE_TRUST_MIN_TRACK_M) {
        t->legs_failed++;
        t->turns = 0u;
        turn_(t, cfg, v_left, v_right);
        return false;
    }
    // The robot drove straight: the track's direction is its heading over the leg, which the
    // gyro measured as the mean of its readings at either end.
    const float track_deg = atan2f(dy, dx) * DEG_PER_RAD;
    const float mid_deg = t->a_heading_deg + 0.5f * wrap180_(in->heading_deg - t->a_heading_deg);
    t->correction_deg = wrap180_(track_deg - mid_deg);
    *correction_deg = t->correction_deg;
    t->legs++;
    pose_trust_grant(t, POSE_TRUST_WHY_LEG);
    return true;
}

bool pose_trust_leg_period(pose_trust_t *t, const robot_config_t *cfg, const pose_trust_in_t *in,
                           float *v_left, float *v_right, float *correction_deg)
{
    FW_ASSERT(t != NULL && cfg != NULL && in != NULL);
    *v_left = 0.0f;
    *v_right = 0.0f;
    if (t->trusted) {
        t->phase = POSE_TRUST_LEG_IDLE;
        return false;
    }
    const bool fix_since_stop = in->fix_fresh && in->fix_us >= t->stopped_us;
    switch ((pose_trust_phase_t)t->phase) {
    case POSE_TRUST_LEG_IDLE:
        t->turns = 0u;
        stand_(t, POSE_TRUST_LEG_FIX_A, in->now_us);
        break;
    case POSE_TRUST_LEG_FIX_A:
        if (!fix_since_stop) {
            break;
        }
        if (in->front_m < POSE_TRUST_CLEAR_M && t->turns < 3u) {
            t->turns++;
            turn_(t, cfg, v_left, v_right);
            break;
        }
        t->ax_m = in->x_m;
        t->ay_m = in->y_m;
        t->a_heading_deg = in->heading_deg;
        t->phase = POSE_TRUST_LEG_DRIVE;
        {
            const long n = lrintf(POSE_TRUST_LEG_M / (POSE_TRUST_LEG_SPEED_M_S * period_s_(cfg)));
            t->periods_left = (uint8_t)(n < 1 ? 1 : n > 255 ? 255 : n);
        }
        *v_left = POSE_TRUST_LEG_SPEED_M_S;
        *v_right = POSE_TRUST_LEG_SPEED_M_S;
        break;
    case POSE_TRUST_LEG_DRIVE:
        if (t->periods_left > 0u) {
            t->periods_left--;
        }
        if (in->bump || t->periods_left == 0u) {
            stand_(t, POSE_TRUST_LEG_FIX_B, in->now_us);
        } else {
            *v_left = POSE_TRUST_LEG_SPEED_M_S;
            *v_right = POSE_TRUST_LEG_SPEED_M_S;
        }
        break;
    case POSE_TRUST_LEG_FIX_B:
        return fix_since_stop && leg_end_(t, cfg, in, v_left, v_right, correction_deg);
    case POSE_TRUST_LEG_TURN:
    default:
        if (t->periods_left > 0u) {
            t->periods_left--;
        }
        if (t->periods_left == 0u) {
            stand_(t, POSE_TRUST_LEG_FIX_A, in->now_us);
        } else {
            const uint8_t left = t->periods_left;
            turn_(t, cfg, v_left, v_right);
            t->periods_left = left;  // turn_ starts a new count: keep this one
        }
        break;
    }
    return false;
}
