// SPDX-License-Identifier: MIT
// Tests of the whole application on the host port in lock-step: the firmware's wiring of
// interrupts, events and tasks under faults (a full event queue, a full UART ring).
#include "test_common.h"

#include <string.h>

#include "robot/agent_profiles.h"
#include "drivers/candev.h"
#include "hal/hal_time.h"
#include "hal/hal_uart.h"
#include "hal_host/hal_host.h"
#include "robot/robot_app.h"
#include "sched/sched.h"

static int setup_(void **state)
{
    (void)state;
    hal_host_reset();
    robot_app_options_t opt = {0};
    opt.cfg = &robot_config_paper_lab;  // Cricket pose: the UART is on
    opt.agent = &agent_paper_lab;
    opt.storage = &agent_storage_paper_lab;
    opt.seed = 1;
    opt.plan_budget_us = ROBOT_PLAN_BUDGET_US;
    assert_int_equal(robot_app_init(&opt), FW_OK);
    return 0;
}

// Runs the firmware until it asks to sleep, then lets virtual time reach `t_us`.
static void run_until_(uint64_t t_us)
{
    for (;;) {
        robot_app_step();
        hal_can_frame_t f;
        while (hal_host_can_take_tx(&f)) {
        }
        const uint64_t wake = hal_host_wait_deadline();
        if (wake > hal_time_us()) {
            if (wake >= t_us) {
                if (t_us > hal_time_us()) {
                    assert_int_equal(hal_host_time_set_us(t_us), FW_OK);
                }
                robot_app_step();
                return;
            }
            assert_int_equal(hal_host_time_set_us(wake), FW_OK);
        }
    }
}

// More frames than the event queue holds, with nobody draining it: the queue is full.
static void fill_event_queue_(void)
{
    hal_can_frame_t f = {0};
    f.id = candev_rx_ids[0];
    f.dlc = 8;
    for (uint32_t i = 0; i < FW_CFG_SCHED_EVENT_CAPACITY + 8u; i++) {
        (void)hal_host_can_deliver(&f);
    }
    sched_stats_t ss;
    sched_get_stats(robot_app_sched(), &ss);
    assert_true(ss.events_dropped > 0u);
}

static uint32_t rx_bytes_(void)
{
    hal_uart_stats_t us;
    hal_uart_get_stats(&us);
    return us.rx_bytes;
}

// The line keeps sending while the event queue is full and the ring fills up (a stalled
// firmware): once the firmware runs again, the line is drained again. (The bug: the wake-up
// was posted only when a byte was stored, so a full ring never woke the firmware again.)
static void test_uart_resumes_after_full_queue_and_full_ring(void **state)
{
    (void)state;
    uint8_t line[FW_CFG_HOST_UART_RX_CAPACITY];
    memset(line, 'x', sizeof line);
    fill_event_queue_();
    assert_int_equal(hal_host_uart_feed(line, sizeof line), sizeof line);  // the wake-up fails
    assert_int_equal(hal_host_uart_feed(line, 16), 0);                      // full: overruns
    robot_app_stats_t st;
    robot_app_get_stats(&st);
    assert_true(st.uart_posts_failed > 0u);
    // The firmware runs again; bytes go on arriving, a few at a time.
    uint64_t t = hal_time_us();
    uint32_t fed = 0;
    for (uint32_t i = 0; i < 200u; i++) {
        t += 1000u;
        run_until_(t);
        fed += 16u;
        (void)hal_host_uart_feed(line, 16);
    }
    run_until_(t + 200000u);
    // Nearly everything fed after the stall was stored: the ring was drained all along.
    assert_true(rx_bytes_() >= FW_CFG_HOST_UART_RX_CAPACITY + fed - FW_CFG_HOST_UART_RX_CAPACITY);
    assert_int_equal(hal_host_uart_feed(line, sizeof line), sizeof line);  // and it is empty now
}

// The wake-up fails and the line then falls silent: the bytes already in the ring are still
// read, by the control task, within a control period.
static void test_uart_drained_when_the_line_falls_silent(void **state)
{
    (void)state;
    uint8_t bytes[10];
    memset(bytes, 'y', sizeof bytes);
    fill_event_queue_();
    assert_int_equal(hal_host_uart_feed(bytes, sizeof bytes), sizeof bytes);
    run_until_(hal_time_us() + robot_config_paper_lab.period_us + 1000u);
    uint8_t ring[FW_CFG_HOST_UART_RX_CAPACITY];
    memset(ring, 'z', sizeof ring);
    assert_int_equal(hal_host_uart_feed(ring, sizeof ring), sizeof ring);  // the ring was empty
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_uart_resumes_after_full_queue_and_full_ring, setup_),
        cmocka_unit_test_setup(test_uart_drained_when_the_line_falls_silent, setup_),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
