// SPDX-License-Identifier: MIT
// dynaqpc host port: what the port's files share with each other (not a public header).
#ifndef HOST_INTERNAL_H
#define HOST_INTERNAL_H

#include <stdbool.h>

/// Each part's share of hal_host_reset().
void host_time_reset(void);
void host_cpu_reset(void);
void host_can_reset(void);
void host_uart_reset(void);
void host_flash_reset(void);

#endif // HOST_INTERNAL_H
