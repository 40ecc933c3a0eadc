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

/// hal_cpu_wait_until() called with "interrupts masked": the calling thread lets go of the irq
/// mutex (all its nesting, returned) so that receiver threads can deliver while it sleeps, and
/// takes it back after. Safe because the wait's wake latch (hal_host_cpu_wake) remembers any
/// delivery since the caller's last check, as WFI remembers a pending interrupt.
uint32_t host_irq_release(void);
void host_irq_reacquire(uint32_t depth);

#endif // HOST_INTERNAL_H
