// SPDX-License-Identifier: MIT
// dynaqpc HAL: the CPU — interrupt masking, idle waiting, the watchdog, reset.
#ifndef HAL_CPU_H
#define HAL_CPU_H

#include <stdbool.h>
#include <stdint.h>

#include "fw/fw_base.h"  // FW_OK and the FW_ERR_* codes the functions return

#ifdef __cplusplus
extern "C" {
#endif

/// Saved interrupt-enable state, for nesting critical sections.
typedef uint32_t hal_irq_state_t;

/// Masks interrupts and returns the previous state. Keep the masked section short (no loops
/// over tables): interrupt latency is the bus's receive budget.
/// Context: any. Never blocks.
hal_irq_state_t hal_irq_save(void);

/// Restores the state returned by the matching hal_irq_save(). Context: any.
void hal_irq_restore(hal_irq_state_t state);

/// Waits, in the CPU's low-power idle state, until hal_time_us() >= deadline_us or an
/// interrupt has become pending (whichever is first), then returns. Returns at once if the
/// deadline has passed. Spurious early returns are allowed: callers re-check time and their events.
///
/// The sleep handoff: call it with interrupts masked (hal_irq_save) from the caller's last check
/// that it has nothing to do, and restore the mask after it returns. An interrupt that arrives
/// between that check and the wait then still ends the wait at once (on the Cortex-M, WFI wakes
/// on an interrupt PRIMASK holds pending; its handler runs when the caller unmasks), instead of
/// being left pending until the next timer tick. Called unmasked, such an interrupt may wait for
/// the next tick (1 ms on the STM32F4). The port must not take the interrupt itself while masked.
/// Context: thread (the scheduler's main loop) only.
/// In the host port's lock-step mode it returns at once and records the deadline: the
/// simulator, which owns time, advances the clock to the wake-up before the next call.
void hal_cpu_wait_until(uint64_t deadline_us);

/// Tells the port that the caller just did about `cycles` CPU cycles of work. Real ports ignore
/// it (time passes by itself). The host port's lock-step mode advances virtual time by
/// cycles / its modelled clock (168 MHz by default), so the simulator can model the MCU's time
/// budget honestly. The scheduler calls it after each idle step and each task run with their
/// configured costs. Context: thread. Never blocks.
void hal_cpu_account(uint32_t cycles);

/// Starts the watchdog with the given timeout. After this, hal_cpu_watchdog_kick() must be
/// called at least once per timeout or the MCU resets. A port without one returns FW_ERR_NOSYS.
/// Context: thread, at boot.
int hal_cpu_watchdog_start(uint32_t timeout_ms);

/// Reloads the watchdog. Context: thread. Never blocks.
void hal_cpu_watchdog_kick(void);

/// Why the CPU last started: lets the firmware count watchdog resets and report them.
typedef enum hal_reset_cause {
    HAL_RESET_POWER_ON = 0,
    HAL_RESET_PIN = 1,
    HAL_RESET_WATCHDOG = 2,
    HAL_RESET_SOFTWARE = 3,
    HAL_RESET_OTHER = 4,
} hal_reset_cause_t;

hal_reset_cause_t hal_cpu_reset_cause(void);

#ifdef __cplusplus
}
#endif

#endif // HAL_CPU_H
