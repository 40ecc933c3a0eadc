// SPDX-License-Identifier: MIT
// dynaqpc host port: hal_host_reset(), the hub that puts every part back to its power-on state.
// It uses each part; no part uses it.
#include "hal_host/hal_host.h"
#include "host_internal.h"

void hal_host_reset(void)
{
    host_uart_reset();  // first: it stops the reader thread
    host_can_reset();
    host_cpu_reset();
    host_flash_reset();
    host_time_reset();
}
