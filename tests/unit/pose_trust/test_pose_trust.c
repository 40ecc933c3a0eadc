// SPDX-License-Identifier: MIT
// Tests of pose trust and the straight leg that finds the heading again (robot/pose_trust.h), on a
// kinematic robot whose fixes carry the lab's Cricket noise.
#include "test_common.h"

#include <math.h>
#include <stdio.h>

#include "robot/pose_trust.h"
#include "robot/robot_config.h"

static const robot_config_t *lab_ = &robot_config_paper_lab;

// A robot on the floor: true pose, a gyro with an unknown offset, fixes with Gaussian noise.
typedef struct bench {
    double x, y, th;        // true pose (rad)
    double gyro_offset;     // gyro heading - true heading, deg
    uint64_t now_us;
    uint64_t next_fix_us;   // a fix comes about every second while standing
    uint64_t moved_us;      // the last period the wheels turned
    uint32_t rng;
    double wall_x;          // a wall at x = wall_x (front range when facing +x), or 0: none
    bool blind;             // the wall is too low for the range sensor: only the bumper finds it
    bool bumped;
} bench_t;

static double uniform_(bench_t *b)
{
    b->rng = b->rng * 1664525u + 1013904223u;
    return ((double)(b->rng >> 8) + 0.5) / 16777216.0;
}

static double gauss_(bench_t *b)
{
    const double u1 = uniform_(b), u2 = uniform_(b);
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

static double wrap180_(double d)
{
    while (d > 180.0) d -= 360.0;
    while (d <= -180.0) d += 360.0;
    return d;
}

// One control period: the leg decides the wheels from what the robot senses, then it moves.
static bool period_(bench_t *b, pose_trust_t *t, double fix_sd_m, float *corr)
{
    const double period = (double)lab_->period_us * 1e-6;
    pose_trust_in_t in = {0};
    in.now_us = b->now_us;
    if (b->now_us >= b->next_fix_us && b->now_us - b->moved_us > 400000u) {
        in.fix_fresh = true;
        in.x_m = (float)(b->x + fix_sd_m * gauss_(b));
        in.y_m = (float)(b->y + fix_sd_m * gauss_(b));
        in.fix_us = b->now_us - 100000u;
        b->next_fix_us = b->now_us + 1000000u;
    }
    double h = fmod(b->th * 57.29577951308232 + b->gyro_offset, 360.0);
    in.heading_deg = (float)(h < 0 ? h + 360.0 : h);
    in.front_m = 100.0f;
    if (b->wall_x > 0.0 && !b->blind && cos(b->th) > 0.7) {
        in.front_m = (float)((b->wall_x - b->x) / cos(b->th));
    }
    in.bump = b->bumped;
    b->bumped = false;
    float vl, vr;
    const bool done = pose_trust_leg_period(t, lab_, &in, &vl, &vr, corr);
    const double v = 0.5 * (vl + vr), w = (vr - vl) / lab_->track_m;
    if (vl != 0.0f || vr != 0.0f) {
        b->moved_us = b->now_us;
        b->next_fix_us = b->now_us + 400000u + 1000000u;
    }
    b->x += v * cos(b->th) * period;
    b->y += v * sin(b->th) * period;
    b->th += w * period;
    if (b->wall_x > 0.0 && b->x > b->wall_x - 0.05) {
        b->x = b->wall_x - 0.05;
        b->bumped = true;
    }
    b->now_us += lab_->period_us;
    return done;
}

// Runs one leg to its end; returns the heading error after it, deg.
static double leg_(bench_t *b, double fix_sd_m, uint32_t *periods)
{
    pose_trust_t t;
    pose_trust_init(&t, false);
    assert_false(t.trusted);
    assert_int_equal(t.reason, POSE_TRUST_WHY_BOOT);
    float corr = 0.0f;
    uint32_t n = 0;
    while (!period_(b, &t, fix_sd_m, &corr)) {
        n++;
        assert_true(n < 2000u);
    }
    assert_true(t.trusted);
    assert_int_equal(t.reason, POSE_TRUST_WHY_LEG);
    *periods = n;
    b->gyro_offset += corr;
    return fabs(wrap180_(b->gyro_offset));
}

static void test_leg_finds_the_heading_exactly_without_noise(void **state)
{
    (void)state;
    bench_t b = {.x = 1.0, .y = 1.0, .th = 0.7, .gyro_offset = -123.0, .rng = 1u};
    uint32_t periods;
    const double err = leg_(&b, 0.0, &periods);
    assert_true(err < 0.01);
    assert_true(periods < 60u);  // about 12 s: two fixes and a 2 s drive
}

// The lab's Cricket noise: 8.7 mm RMS per fix (docs/can-protocol.md), 6.2 mm per axis.
static void test_leg_heading_error_under_cricket_noise(void **state)
{
    (void)state;
    double sum2 = 0.0, worst = 0.0;
    const int n = 2000;
    uint32_t periods_max = 0;
    for (int i = 0; i < n; i++) {
        bench_t b = {.x = 1.0, .y = 1.0, .rng = 77u + (uint32_t)i * 2654435761u};
        b.th = uniform_(&b) * 6.283185307179586;
        b.gyro_offset = uniform_(&b) * 360.0;
        uint32_t periods;
        const double err = leg_(&b, 0.0087 / sqrt(2.0), &periods);
        sum2 += err * err;
        worst = err > worst ? err : worst;
        periods_max = periods > periods_max ? periods : periods_max;
    }
    const double rms = sqrt(sum2 / n);
    printf("straight leg under Cricket noise: heading error %.2f deg RMS, %.2f deg worst of %d; "
           "at most %u periods\n", rms, worst, n, periods_max);
    assert_true(rms < 2.5);
    assert_true(worst < 10.0);
}

static void test_leg_turns_away_from_a_wall_and_survives_a_bump(void **state)
{
    (void)state;
    // Facing a wall 0.3 m ahead: it turns a quarter turn before driving.
    bench_t b = {.x = 1.0, .y = 1.0, .th = 0.0, .gyro_offset = 40.0, .rng = 5u, .wall_x = 1.3};
    uint32_t periods;
    assert_true(leg_(&b, 0.0, &periods) < 0.01);
    // Facing a wall 0.7 m ahead: clear, and the 0.4 m leg ends short of it.
    bench_t c = {.x = 1.0, .y = 1.0, .th = 0.0, .gyro_offset = 40.0, .rng = 5u, .wall_x = 1.7};
    assert_true(leg_(&c, 0.0, &periods) < 0.01);
    // A low wall the range sensor misses, bumped 0.15 m on: the short track gives no heading; it
    // turns a quarter turn and tries again.
    bench_t d = {.x = 1.0, .y = 1.0, .th = 0.0, .gyro_offset = 40.0, .rng = 5u, .wall_x = 1.2, .blind = true};
    pose_trust_t t;
    pose_trust_init(&t, false);
    float corr = 0.0f;
    uint32_t k = 0;
    while (!period_(&d, &t, 0.0, &corr)) {
        assert_true(++k < 2000u);
    }
    assert_int_equal(t.legs, 1);
    assert_int_equal(t.legs_failed, 1);  // the bump cut the first track to 0.15 m
    d.gyro_offset += corr;
    assert_true(fabs(wrap180_(d.gyro_offset)) < 0.01);
}

static void test_trust_is_lost_and_granted(void **state)
{
    (void)state;
    pose_trust_t t;
    pose_trust_init(&t, false);
    pose_trust_grant(&t, POSE_TRUST_WHY_OPERATOR);
    assert_true(t.trusted);
    assert_int_equal(t.reason, POSE_TRUST_WHY_OPERATOR);
    pose_trust_lose(&t, POSE_TRUST_WHY_STALL);
    pose_trust_lose(&t, POSE_TRUST_WHY_GYRO_GAP);
    assert_false(t.trusted);
    assert_int_equal(t.reason, POSE_TRUST_WHY_GYRO_GAP);
    assert_int_equal(t.losses, 1);  // counted once: it was trusted once
    // While trusted the leg does nothing and the wheels stand.
    pose_trust_grant(&t, POSE_TRUST_WHY_OPERATOR);
    const pose_trust_in_t in = {.now_us = 1000000u, .fix_fresh = true, .fix_us = 1000000u, .front_m = 100.0f};
    float vl = 1.0f, vr = 1.0f, corr = 0.0f;
    assert_false(pose_trust_leg_period(&t, lab_, &in, &vl, &vr, &corr));
    assert_true(vl == 0.0f && vr == 0.0f);
    // A pose source that measures the heading is always trusted.
    pose_trust_init(&t, true);
    pose_trust_lose(&t, POSE_TRUST_WHY_STALL);
    assert_true(t.trusted);
    assert_int_equal(t.reason, POSE_TRUST_WHY_ABSOLUTE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_leg_finds_the_heading_exactly_without_noise),
        cmocka_unit_test(test_leg_heading_error_under_cricket_noise),
        cmocka_unit_test(test_leg_turns_away_from_a_wall_and_survives_a_bump),
        cmocka_unit_test(test_trust_is_lost_and_granted),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
