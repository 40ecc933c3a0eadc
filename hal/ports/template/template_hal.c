// SPDX-License-Identifier: MIT
// dynaqpc HAL port template: every hal_* function, doing nothing, returning FW_ERR_NOSYS where
// the contract has an error return. Copy this folder to start a port (docs/porting.md):
//
//     cp -r hal/ports/template hal/ports/<mcu>
//
// then rename dynaqpc_hal_template in its CMakeLists.txt, and replace each body below with the
// peripheral's code, one contract at a time (the header named above each group says what it
// must do, in which context, and what it returns). The firmware links and boots against this
// file as it is: hal_time_init() and hal_can_init() fail with FW_ERR_NOSYS, so it stops there.
// Split it into one source per peripheral as the port grows (hal/ports/stm32f4/src/ does).
//
// Rules every port keeps: no allocator, no include of a firmware module (agent/, robot/,
// sched/, drivers/): a port sees only hal/*.h and the base layer (fw/*.h).
#include <stddef.h>
#include <string.h>

#include "hal/hal_can.h"
#include "hal/hal_cpu.h"
#include "hal/hal_flash.h"
#include "hal/hal_time.h"
#include "hal/hal_uart.h"
#include "template_config.h"

// ---- hal_time.h: one 64-bit microsecond clock since boot -------------------------------------

int hal_time_init(void)
{
    return FW_ERR_NOSYS;  // start a timer (SysTick) at 0
}

uint64_t hal_time_us(void)
{
    return 0;  // never goes backwards; callable from interrupts
}

// ---- hal_cpu.h: interrupts, idle, watchdog, reset cause --------------------------------------

hal_irq_state_t hal_irq_save(void)
{
    return 0;  // mask interrupts, return the previous mask (PRIMASK)
}

void hal_irq_restore(hal_irq_state_t state)
{
    (void)state;
}

void hal_cpu_wait_until(uint64_t deadline_us)
{
    (void)deadline_us;  // sleep (WFI) until the deadline or an interrupt; early returns allowed
}

void hal_cpu_account(uint32_t cycles)
{
    (void)cycles;  // real ports ignore it: time passes by itself
}

int hal_cpu_watchdog_start(uint32_t timeout_ms)
{
    (void)timeout_ms;
    return FW_ERR_NOSYS;  // the contract's answer for a port without a watchdog
}

void hal_cpu_watchdog_kick(void)
{
}

hal_reset_cause_t hal_cpu_reset_cause(void)
{
    return HAL_RESET_OTHER;  // read the reset controller's flags
}

// ---- hal_can.h: classic CAN, 8-byte frames, receive in an interrupt --------------------------

int hal_can_init(uint32_t bitrate, const uint32_t *accept_ids, uint32_t n_ids, hal_can_rx_fn on_rx,
                 void *ctx)
{
    (void)bitrate;
    (void)accept_ids;
    (void)n_ids;
    (void)on_rx;
    (void)ctx;
    return FW_ERR_NOSYS;
}

int hal_can_send(const hal_can_frame_t *frame)
{
    (void)frame;
    return FW_ERR_NOSYS;
}

void hal_can_get_stats(hal_can_stats_t *out)
{
    memset(out, 0, sizeof *out);
}

// ---- hal_uart.h: the Cricket listener's serial line ------------------------------------------

int hal_uart_init(uint32_t baud, hal_uart_rx_fn on_rx, void *ctx)
{
    (void)baud;
    (void)on_rx;
    (void)ctx;
    return FW_ERR_NOSYS;
}

size_t hal_uart_read(uint8_t *buf, size_t cap)
{
    (void)buf;
    (void)cap;
    return 0;  // nothing received
}

size_t hal_uart_write(const uint8_t *data, size_t len)
{
    (void)data;
    (void)len;
    return 0;  // nothing queued
}

void hal_uart_get_stats(hal_uart_stats_t *out)
{
    memset(out, 0, sizeof *out);
}

// ---- hal_flash.h: the region that keeps what was learned -------------------------------------

int hal_flash_get_geometry(hal_flash_geometry_t *out)
{
    memset(out, 0, sizeof *out);
    return FW_ERR_NOSYS;  // no region: the firmware runs, and learns, without saving
}

int hal_flash_read(uint32_t offset, void *buf, size_t len)
{
    (void)offset;
    (void)buf;
    (void)len;
    return FW_ERR_NOSYS;
}

const void *hal_flash_map(uint32_t offset, size_t len)
{
    (void)offset;
    (void)len;
    return NULL;
}

int hal_flash_erase(uint32_t sector)
{
    (void)sector;
    return FW_ERR_NOSYS;
}

int hal_flash_write(uint32_t offset, const void *data, size_t len)
{
    (void)offset;
    (void)data;
    (void)len;
    return FW_ERR_NOSYS;
}
