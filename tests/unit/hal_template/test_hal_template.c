// SPDX-License-Identifier: MIT
// Tests of the port template (hal/ports/template): it links as a whole port, and every call with
// an error return says FW_ERR_NOSYS, the rest report nothing done.
#include "test_common.h"

#include <string.h>

#include "hal/hal_can.h"
#include "hal/hal_cpu.h"
#include "hal/hal_flash.h"
#include "hal/hal_time.h"
#include "hal/hal_uart.h"

static void noop_rx_(void *ctx)
{
    (void)ctx;
}

static void every_error_return_is_nosys(void **state)
{
    (void)state;
    assert_int_equal(hal_time_init(), FW_ERR_NOSYS);
    assert_int_equal(hal_cpu_watchdog_start(100), FW_ERR_NOSYS);
    const uint32_t ids[1] = {0x100};
    assert_int_equal(hal_can_init(500000, ids, 1, NULL, NULL), FW_ERR_NOSYS);
    hal_can_frame_t f;
    memset(&f, 0, sizeof f);
    assert_int_equal(hal_can_send(&f), FW_ERR_NOSYS);
    assert_int_equal(hal_uart_init(115200, noop_rx_, NULL), FW_ERR_NOSYS);
    hal_flash_geometry_t g;
    memset(&g, 0xA5, sizeof g);
    assert_int_equal(hal_flash_get_geometry(&g), FW_ERR_NOSYS);
    assert_int_equal(g.sector_count, 0u);
    uint8_t buf[4];
    assert_int_equal(hal_flash_read(0, buf, sizeof buf), FW_ERR_NOSYS);
    assert_int_equal(hal_flash_erase(0), FW_ERR_NOSYS);
    assert_int_equal(hal_flash_write(0, buf, sizeof buf), FW_ERR_NOSYS);
}

static void the_rest_report_nothing_done(void **state)
{
    (void)state;
    assert_true(hal_time_us() == 0u);
    hal_irq_restore(hal_irq_save());
    hal_cpu_wait_until(1000);
    hal_cpu_account(10);
    hal_cpu_watchdog_kick();
    assert_int_equal(hal_cpu_reset_cause(), HAL_RESET_OTHER);
    uint8_t buf[4] = {1, 2, 3, 4};
    assert_int_equal(hal_uart_read(buf, sizeof buf), 0u);
    assert_int_equal(hal_uart_write(buf, sizeof buf), 0u);
    assert_null(hal_flash_map(0, 4));
    hal_can_stats_t cs;
    memset(&cs, 0xA5, sizeof cs);
    hal_can_get_stats(&cs);
    assert_int_equal(cs.tx_frames + cs.rx_frames + cs.tx_dropped, 0u);
    hal_uart_stats_t us;
    memset(&us, 0xA5, sizeof us);
    hal_uart_get_stats(&us);
    assert_int_equal(us.rx_bytes + us.rx_overruns, 0u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_error_return_is_nosys),
        cmocka_unit_test(the_rest_report_nothing_done),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
