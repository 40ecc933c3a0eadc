// SPDX-License-Identifier: MIT
// The gyro's heading integrated over the samples' own spacing (FW_CFG_GYRO_PERIOD_US = 16 ms:
// the frame counter's steps times the period), whatever the receive times: frames a bridge
// bunches, or delivers late, integrate as the sensor sampled them.
#include "test_common.h"

#include "drivers/drivers_config.h"
#include "drivers/gyro.h"

#if FW_CFG_GYRO_PERIOD_US != 16000u
#error "this test is built with FW_CFG_GYRO_PERIOD_US=16000u"
#endif

static hal_can_frame_t gyro_frame(uint8_t *counter, int16_t rate_cdeg_s)
{
    hal_can_frame_t f;
    assert_int_equal(gyro_encode_rate(counter, rate_cdeg_s, 25, GYRO_STATUS_OK, &f), FW_OK);
    return f;
}

static void test_bunched_frames_integrate_over_the_sample_period(void **state)
{
    (void)state;
    gyro_t g;
    gyro_init(&g);
    uint8_t c = 0;
    // A bump: the rate spikes for two samples. Sampled every 16 ms, received in bunches (three
    // within 1 ms after a 40 ms wait, then one 8 ms later), as the emulated board received them.
    const int16_t rates[] = {0, 20000, -15000, 3000, 0, 0};
    const uint64_t rx_us[] = {1000000u, 1040000u, 1040300u, 1040600u, 1048600u, 1064600u};
    for (unsigned i = 0; i < 6u; i++) {
        hal_can_frame_t f = gyro_frame(&c, rates[i]);
        assert_int_equal(gyro_rx_rate(&g, &f, rx_us[i]), FW_OK);
    }
    // Trapezoids over 16 ms each: (0 + 200) / 2 + (200 - 150) / 2 + (-150 + 30) / 2 + 30 / 2 deg/s.
    const float want = (100.0f + 25.0f - 60.0f + 15.0f) * 0.016f;
    assert_float_equal(gyro_heading_deg(&g), want, 1e-3f);
}

static void test_lost_frames_count_their_periods(void **state)
{
    (void)state;
    gyro_t g;
    gyro_init(&g);
    uint8_t c = 0;
    hal_can_frame_t f = gyro_frame(&c, 9000);
    assert_int_equal(gyro_rx_rate(&g, &f, 0u), FW_OK);
    c = (uint8_t)(c + 2u);  // two frames lost: three periods
    f = gyro_frame(&c, 9000);
    assert_int_equal(gyro_rx_rate(&g, &f, 20000u), FW_OK);  // received early, as after a stall
    assert_float_equal(gyro_heading_deg(&g), 90.0f * 0.048f, 1e-3f);
    assert_int_equal(g.rx.lost, 2);
    // More samples lost than FW_CFG_GYRO_MAX_DT_US spans (7 x 16 ms): the counter's jump is
    // refused (GYRO_MAX_STEP), the next sample resynchronises, and that is a gap, not bridged.
    c = (uint8_t)(c + 6u);
    f = gyro_frame(&c, 9000);
    assert_int_equal(gyro_rx_rate(&g, &f, 140000u), FW_ERR_INVAL);
    assert_int_equal(g.rx.implausible, 1);
    f = gyro_frame(&c, 9000);
    assert_int_equal(gyro_rx_rate(&g, &f, 156000u), FW_OK);
    assert_int_equal(g.gaps, 1);
    assert_float_equal(gyro_heading_deg(&g), 90.0f * 0.048f, 1e-3f);
}

// A stalled host delivers the next sample 190 ms late (the board's worst lateness under load):
// the counter says none was lost, so the one period between them is integrated. A silence of 16
// periods or more is one the 4-bit counter cannot count: a gap.
static void test_a_late_delivery_is_no_gap(void **state)
{
    (void)state;
    gyro_t g;
    gyro_init(&g);
    uint8_t c = 0;
    hal_can_frame_t f = gyro_frame(&c, 19000);
    assert_int_equal(gyro_rx_rate(&g, &f, 0u), FW_OK);
    f = gyro_frame(&c, 19000);
    assert_int_equal(gyro_rx_rate(&g, &f, 190000u), FW_OK);
    assert_int_equal(g.gaps, 0);
    assert_float_equal(gyro_heading_deg(&g), 190.0f * 0.016f, 1e-3f);
    f = gyro_frame(&c, 19000);
    assert_int_equal(gyro_rx_rate(&g, &f, 190000u + 16u * 16000u), FW_OK);
    assert_int_equal(g.gaps, 1);
    assert_float_equal(gyro_heading_deg(&g), 190.0f * 0.016f, 1e-3f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bunched_frames_integrate_over_the_sample_period),
        cmocka_unit_test(test_lost_frames_count_their_periods),
        cmocka_unit_test(test_a_late_delivery_is_no_gap),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
