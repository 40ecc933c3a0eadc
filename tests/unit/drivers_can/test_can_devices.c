// SPDX-License-Identifier: MIT
// Device state over CAN: rolling-counter gaps and repeats, bus-silence detection, and the gyro's
// heading integration and bias estimate.
#include "test_common.h"

#include <math.h>

#include "drivers/candev.h"
#include "drivers/drivers_config.h"
#include "fw/fw_base.h"

static hal_can_frame_t motor_frame(uint8_t counter)
{
    uint8_t c = counter;
    const motor_status_t s = {.speed_left_mm_s = 10, .speed_right_mm_s = 10};
    hal_can_frame_t f;
    assert_int_equal(motor_encode_status(&c, &s, &f), FW_OK);
    return f;
}

static void test_counter_gaps_and_repeats(void **state)
{
    (void)state;
    motor_t m;
    motor_init(&m);
    uint64_t t = 0;
    // 0..15, 0..4 in order: nothing lost across the wrap.
    for (unsigned i = 0; i < 21u; i++) {
        hal_can_frame_t f = motor_frame((uint8_t)(i % 16u));
        assert_int_equal(motor_rx_status(&m, &f, t += 48000u), FW_OK);
    }
    assert_int_equal(m.rx.frames, 21);
    assert_int_equal(m.rx.lost, 0);
    // Skip 5 and 6: two lost.
    hal_can_frame_t f = motor_frame(7);
    assert_int_equal(motor_rx_status(&m, &f, t += 48000u), FW_OK);
    assert_int_equal(m.rx.lost, 2);
    // 7 again: a repeat is refused and leaves the timestamp alone.
    uint64_t last = m.rx.last_ok_us;
    assert_int_equal(motor_rx_status(&m, &f, t += 48000u), FW_ERR_NOENT);
    assert_int_equal(m.rx.repeated, 1);
    assert_int_equal(m.rx.last_ok_us, last);
    // Jumping to 15 (8 ahead: a reboot, or 7 lost, which a 4-bit counter cannot tell apart from
    // 23) is refused as implausible; 0 after it resynchronises, with nothing counted as lost.
    f = motor_frame(15);
    assert_int_equal(motor_rx_status(&m, &f, t += 48000u), FW_ERR_INVAL);
    assert_int_equal(m.rx.implausible, 1);
    f = motor_frame(0);
    assert_int_equal(motor_rx_status(&m, &f, t += 48000u), FW_OK);
    assert_int_equal(m.rx.lost, 2);
    assert_int_equal(m.rx.counter, 0);
}

static void test_silence_is_detected_from_the_last_good_frame(void **state)
{
    (void)state;
    motor_t m;
    motor_init(&m);
    assert_true(can_link_rx_silent(&m.rx, 0u, 150000u));  // nothing ever heard
    hal_can_frame_t f = motor_frame(0);
    assert_int_equal(motor_rx_status(&m, &f, 1000000u), FW_OK);
    assert_false(can_link_rx_silent(&m.rx, 1150000u, 150000u));
    // Malformed frames keep arriving but do not count as signs of life.
    hal_can_frame_t bad = f;
    bad.dlc = 2;
    assert_int_equal(motor_rx_status(&m, &bad, 1100000u), FW_ERR_INVAL);
    assert_true(can_link_rx_silent(&m.rx, 1150001u, 150000u));
}

static hal_can_frame_t gyro_frame(uint8_t *counter, int16_t rate_cdeg_s, uint8_t status)
{
    hal_can_frame_t f;
    assert_int_equal(gyro_encode_rate(counter, rate_cdeg_s, 25, status, &f), FW_OK);
    return f;
}

static void test_gyro_integrates_rate_over_receive_time(void **state)
{
    (void)state;
    gyro_t g;
    gyro_init(&g);
    uint8_t c = 0;
    uint64_t t = 5000000u;
    // 90 deg/s for 1 s at 16 ms: 62.5 frames; use 63 frames = 62 intervals of 16 ms = 0.992 s.
    for (unsigned i = 0; i < 63u; i++) {
        hal_can_frame_t f = gyro_frame(&c, 9000, GYRO_STATUS_OK);
        assert_int_equal(gyro_rx_rate(&g, &f, t), FW_OK);
        t += 16000u;
    }
    assert_float_equal(gyro_heading_deg(&g), 90.0f * 0.992f, 1e-3f);
    // Lost frames: the interval is bridged by the trapezoid of the two ends.
    hal_can_frame_t f = gyro_frame(&c, 9000, GYRO_STATUS_OK);
    assert_int_equal(gyro_rx_rate(&g, &f, t), FW_OK);
    gyro_set_heading(&g, 0.0f);
    c = (uint8_t)(c + 3u);  // three frames lost
    f = gyro_frame(&c, 9000, GYRO_STATUS_OK);
    assert_int_equal(gyro_rx_rate(&g, &f, t + 64000u), FW_OK);
    assert_float_equal(gyro_heading_deg(&g), 90.0f * 0.064f, 1e-3f);
    assert_int_equal(g.rx.lost, 3);
    // Clockwise rotation wraps below 0.
    gyro_set_heading(&g, 1.0f);
    f = gyro_frame(&c, -10000, GYRO_STATUS_OK);
    assert_int_equal(gyro_rx_rate(&g, &f, t + 80000u), FW_OK);
    f = gyro_frame(&c, -10000, GYRO_STATUS_OK);
    assert_int_equal(gyro_rx_rate(&g, &f, t + 100000u), FW_OK);
    // The first of those two intervals mixes 90 and -100 deg/s over 16 ms; then -100 over 20 ms.
    float want = 1.0f + 0.5f * (90.0f - 100.0f) * 0.016f - 100.0f * 0.020f + 360.0f;
    assert_float_equal(gyro_heading_deg(&g), want, 1e-3f);
}

static void test_gyro_skips_gaps_and_unusable_samples(void **state)
{
    (void)state;
    gyro_t g;
    gyro_init(&g);
    uint8_t c = 0;
    hal_can_frame_t f = gyro_frame(&c, 5000, GYRO_STATUS_OK);
    assert_int_equal(gyro_rx_rate(&g, &f, 0u), FW_OK);
    f = gyro_frame(&c, 5000, GYRO_STATUS_OK);
    assert_int_equal(gyro_rx_rate(&g, &f, FW_CFG_GYRO_MAX_DT_US + 1u), FW_OK);
    assert_float_equal(gyro_heading_deg(&g), 0.0f, 0.0f);
    assert_int_equal(g.gaps, 1);
    // INIT samples are received but not integrated.
    f = gyro_frame(&c, 5000, GYRO_STATUS_INIT);
    assert_int_equal(gyro_rx_rate(&g, &f, FW_CFG_GYRO_MAX_DT_US + 16001u), FW_OK);
    f = gyro_frame(&c, 5000, GYRO_STATUS_OK);
    assert_int_equal(gyro_rx_rate(&g, &f, FW_CFG_GYRO_MAX_DT_US + 32001u), FW_OK);
    assert_float_equal(gyro_heading_deg(&g), 0.0f, 0.0f);
}

static void test_gyro_learns_bias_while_stationary(void **state)
{
    (void)state;
    gyro_t g;
    gyro_init(&g);
    uint8_t c = 0;
    uint64_t t = 0;
    gyro_set_stationary(&g, true);
    for (unsigned i = 0; i < 1000u; i++) {  // 16 s standing still with a 0.5 deg/s offset
        hal_can_frame_t f = gyro_frame(&c, 50, GYRO_STATUS_OK);
        assert_int_equal(gyro_rx_rate(&g, &f, t += 16000u), FW_OK);
    }
    assert_float_equal(g.bias_deg_s, 0.5f, 1e-3f);
    // Drift over those 16 s stays well under the 8 deg an uncorrected gyro would show.
    float drift = gyro_heading_deg(&g);
    assert_true(drift < 1.0f || drift > 359.0f);
    // Moving: the bias is held and subtracted; 30.5 deg/s measured is 30 deg/s true.
    gyro_set_stationary(&g, false);
    for (unsigned i = 0; i < 101u; i++) {
        hal_can_frame_t f = gyro_frame(&c, 3050, GYRO_STATUS_OK);
        assert_int_equal(gyro_rx_rate(&g, &f, t += 10000u), FW_OK);
        if (i == 0u) {
            gyro_set_heading(&g, 0.0f);  // from the first moving sample on: 100 intervals of 10 ms
        }
    }
    assert_float_equal(gyro_heading_deg(&g), 30.0f, 0.01f);
}

// The wheels stop some time after the command: a robot told to stand still may still turn for a
// few samples (on the emulated board, ~20-60 ms of a 190 deg/s turn). Those samples are not bias;
// learning from them made the heading drift by degrees per turn (docs/results/emulated-board.md).
static void test_gyro_bias_ignores_a_turn_still_ending(void **state)
{
    (void)state;
    gyro_t g;
    gyro_init(&g);
    uint8_t c = 0;
    uint64_t t = 0;
    gyro_set_stationary(&g, true);
    for (unsigned i = 0; i < 1000u; i++) {  // 0.5 deg/s offset learnt
        hal_can_frame_t f = gyro_frame(&c, 50, GYRO_STATUS_OK);
        assert_int_equal(gyro_rx_rate(&g, &f, t += 16000u), FW_OK);
    }
    gyro_set_heading(&g, 90.0f);
    // Told to stop, it turns on at -190 deg/s for three samples (48 ms), then stands still 2 s.
    for (unsigned i = 0; i < 3u; i++) {
        hal_can_frame_t f = gyro_frame(&c, -19000, GYRO_STATUS_OK);
        assert_int_equal(gyro_rx_rate(&g, &f, t += 16000u), FW_OK);
    }
    for (unsigned i = 0; i < 125u; i++) {
        hal_can_frame_t f = gyro_frame(&c, 50, GYRO_STATUS_OK);
        assert_int_equal(gyro_rx_rate(&g, &f, t += 16000u), FW_OK);
    }
    assert_int_equal(g.bias_rejected, 3);
    assert_float_equal(g.bias_deg_s, 0.5f, 1e-3f);
    // The turn itself is integrated (trapezoids over its four intervals, the bias removed).
    const float turned = (0.5f * (0.5f - 190.0f) + 2.0f * -190.0f + 0.5f * (-190.0f + 0.5f) - 4.0f * 0.5f) * 0.016f;
    assert_float_equal(gyro_heading_deg(&g), 90.0f + turned, 0.01f);
}

// gyro_set_sample_period (dynaqpc-fw in real time): frames that arrive late and in a bunch
// (a loaded host, a stalled task) are integrated over the samples' own 16 ms, as the counter
// counts them, not over the receive times; 0 goes back to the receive times.
static void test_gyro_integrates_over_the_sample_clock_when_asked(void **state)
{
    (void)state;
    gyro_t g;
    gyro_init(&g);
    gyro_set_sample_period(&g, 16000u);
    uint8_t c = 0;
    hal_can_frame_t f = gyro_frame(&c, 9000, GYRO_STATUS_OK);
    assert_int_equal(gyro_rx_rate(&g, &f, 1000000u), FW_OK);
    for (unsigned i = 0; i < 10u; i++) {  // ten samples in 1 ms, 90 ms late
        f = gyro_frame(&c, 9000, GYRO_STATUS_OK);
        assert_int_equal(gyro_rx_rate(&g, &f, 1090000u + 100u * i), FW_OK);
    }
    assert_float_equal(gyro_heading_deg(&g), 90.0f * 0.160f, 1e-3f);
    assert_int_equal(g.gaps, 0);
    gyro_set_sample_period(&g, 0u);
    f = gyro_frame(&c, 9000, GYRO_STATUS_OK);
    assert_int_equal(gyro_rx_rate(&g, &f, 1092000u), FW_OK);  // 1.1 ms after the last: receive time
    assert_float_equal(gyro_heading_deg(&g), 90.0f * (0.160f + 0.0011f), 1e-3f);
}

static hal_can_frame_t motor_speeds_frame(uint8_t *counter, int16_t left, int16_t right)
{
    const motor_status_t s = {.speed_left_mm_s = left, .speed_right_mm_s = right};
    hal_can_frame_t f;
    assert_int_equal(motor_encode_status(counter, &s, &f), FW_OK);
    return f;
}

static void command_(motor_t *m, int16_t left, int16_t right)
{
    const motor_cmd_t cmd = {left, right, true};
    hal_can_frame_t f;
    assert_int_equal(motor_encode_cmd(m, &cmd, &f), FW_OK);
}

// MOTOR_STATUS against the firmware's own commands: a wheel faster than the recent commands'
// peak by half again plus the slack is refused as implausible and counted, the status holds, and
// the next good frame is taken (a lost frame's worth). Unchecked until MOTOR_PEAK_CMDS commands;
// a stop's run-down passes while the faster commands are within the window, and is forgotten after.
static void test_motor_status_beyond_the_commands_is_implausible(void **state)
{
    (void)state;
    motor_t m;
    motor_init(&m);
    uint8_t c = 0;
    uint64_t t = 0;
    assert_int_equal(motor_cmd_peak_mm_s(&m), -1);
    hal_can_frame_t f = motor_speeds_frame(&c, 1900, -1900);  // nothing commanded yet: unchecked
    assert_int_equal(motor_rx_status(&m, &f, t += 48000u), FW_OK);
    for (unsigned i = 0; i < MOTOR_PEAK_CMDS; i++) {
        command_(&m, 300, 280);
    }
    assert_int_equal(motor_cmd_peak_mm_s(&m), 300);
    const int16_t limit = 300 + 150 + MOTOR_PLAUSIBLE_SLACK_MM_S;
    f = motor_speeds_frame(&c, limit, -limit);
    assert_int_equal(motor_rx_status(&m, &f, t += 48000u), FW_OK);
    f = motor_speeds_frame(&c, 10, (int16_t)(limit + 1));
    assert_int_equal(motor_rx_status(&m, &f, t += 48000u), FW_ERR_INVAL);
    assert_int_equal(m.rx.implausible, 1);
    assert_int_equal(m.status.speed_right_mm_s, -limit);  // held
    f = motor_speeds_frame(&c, 290, 290);
    assert_int_equal(motor_rx_status(&m, &f, t += 48000u), FW_OK);
    assert_int_equal(m.rx.lost, 1);  // the refused frame: bridged as a lost one
    assert_int_equal(m.status.speed_left_mm_s, 290);
    // Stopping: the run-down passes while the window holds the drive's commands...
    for (unsigned i = 0; i + 1u < MOTOR_PEAK_CMDS; i++) {
        command_(&m, 0, 0);
    }
    assert_int_equal(motor_cmd_peak_mm_s(&m), 300);
    f = motor_speeds_frame(&c, 200, 200);
    assert_int_equal(motor_rx_status(&m, &f, t += 48000u), FW_OK);
    // ...and once the window holds stopped commands only (here MOTOR_PEAK_CMDS; at most
    // 2 x MOTOR_PEAK_CMDS - 1), only the slack is left.
    command_(&m, 0, 0);
    assert_int_equal(motor_cmd_peak_mm_s(&m), 0);
    f = motor_speeds_frame(&c, MOTOR_PLAUSIBLE_SLACK_MM_S, 0);
    assert_int_equal(motor_rx_status(&m, &f, t += 48000u), FW_OK);
    f = motor_speeds_frame(&c, 0, -(MOTOR_PLAUSIBLE_SLACK_MM_S + 1));
    assert_int_equal(motor_rx_status(&m, &f, t += 48000u), FW_ERR_INVAL);
    assert_int_equal(m.rx.implausible, 2);
    assert_int_equal(m.rx.malformed, 0);
}

// A gyro sample faster than the robot can turn (gyro_set_rate_limit) is refused as implausible,
// never integrated, and bridged: the next good sample integrates over both intervals. 0: no limit.
static void test_gyro_rate_beyond_the_limit_is_implausible(void **state)
{
    (void)state;
    gyro_t g;
    gyro_init(&g);
    gyro_set_sample_period(&g, 16000u);
    gyro_set_rate_limit(&g, 6000u);  // 60 deg/s
    uint8_t c = 0;
    uint64_t t = 1000000u;
    hal_can_frame_t f = gyro_frame(&c, 5000, GYRO_STATUS_OK);
    assert_int_equal(gyro_rx_rate(&g, &f, t), FW_OK);
    f = gyro_frame(&c, -6001, GYRO_STATUS_OK);
    assert_int_equal(gyro_rx_rate(&g, &f, t += 16000u), FW_ERR_INVAL);
    assert_int_equal(g.rx.implausible, 1);
    assert_float_equal(gyro_heading_deg(&g), 0.0f, 0.0f);
    f = gyro_frame(&c, 5000, GYRO_STATUS_OK);
    assert_int_equal(gyro_rx_rate(&g, &f, t += 16000u), FW_OK);
    assert_float_equal(gyro_heading_deg(&g), 50.0f * 0.032f, 1e-4f);  // over both intervals
    assert_int_equal(g.gaps, 0);
    f = gyro_frame(&c, 6000, GYRO_STATUS_OK);  // at the limit: taken
    assert_int_equal(gyro_rx_rate(&g, &f, t += 16000u), FW_OK);
    gyro_set_rate_limit(&g, 0u);
    f = gyro_frame(&c, -29000, GYRO_STATUS_OK);
    assert_int_equal(gyro_rx_rate(&g, &f, t += 16000u), FW_OK);
    assert_int_equal(g.rx.implausible, 1);
    assert_int_equal(g.rx.malformed, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_counter_gaps_and_repeats),
        cmocka_unit_test(test_silence_is_detected_from_the_last_good_frame),
        cmocka_unit_test(test_gyro_integrates_rate_over_receive_time),
        cmocka_unit_test(test_gyro_integrates_over_the_sample_clock_when_asked),
        cmocka_unit_test(test_gyro_skips_gaps_and_unusable_samples),
        cmocka_unit_test(test_gyro_learns_bias_while_stationary),
        cmocka_unit_test(test_gyro_bias_ignores_a_turn_still_ending),
        cmocka_unit_test(test_motor_status_beyond_the_commands_is_implausible),
        cmocka_unit_test(test_gyro_rate_beyond_the_limit_is_implausible),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
