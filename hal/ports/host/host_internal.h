// SPDX-License-Identifier: MIT
// dynaqpc host port: what the port's files offer each other (not a public header). The files
// use each other in one direction only: host_time.c (the clock) <- host_cpu.c (masking, the
// wait, its wake latch) <- host_can.c, host_uart.c; host_flash.c alone; host_reset.c, the hub
// of hal_host_reset(), uses them all.
#ifndef HOST_INTERNAL_H
#define HOST_INTERNAL_H

#include <pthread.h>
#include <stdbool.h>
#include <stdint.h>

/// Each part's share of hal_host_reset() (host_reset.c).
void host_time_reset(void);
void host_cpu_reset(void);
void host_can_reset(void);
void host_uart_reset(void);
void host_flash_reset(void);

/// The clock's side of hal_cpu_wait_until(deadline_us) (host_time.c, for host_cpu.c). Lock-step:
/// records the wait for the simulator (hal_host_wait_deadline) and returns false: the wait
/// returns at once. Real time: true, with the CLOCK_MONOTONIC instant to sleep until (at most a
/// wall-clock second ahead), when the deadline is still ahead; false when it has passed.
bool host_time_idle_begin(uint64_t deadline_us, uint64_t *until_ns);
/// A wake arrived: the recorded lock-step wait is over.
void host_time_idle_end(void);

/// A counter, setting or flag read under the mutex that guards it: the port's getters for the
/// simulator and the tests (stalls, kicks, erases, programmed bytes, a live line...), each one
/// call.
static inline uint32_t host_locked_u32(pthread_mutex_t *lock, const uint32_t *value)
{
    pthread_mutex_lock(lock);
    const uint32_t v = *value;
    pthread_mutex_unlock(lock);
    return v;
}

static inline uint64_t host_locked_u64(pthread_mutex_t *lock, const uint64_t *value)
{
    pthread_mutex_lock(lock);
    const uint64_t v = *value;
    pthread_mutex_unlock(lock);
    return v;
}

static inline bool host_locked_bool(pthread_mutex_t *lock, const bool *value)
{
    pthread_mutex_lock(lock);
    const bool v = *value;
    pthread_mutex_unlock(lock);
    return v;
}

/// A flag set under the mutex that guards it (the UART reader's line gone, a test's hold).
static inline void host_locked_set_bool(pthread_mutex_t *lock, bool *flag, bool value)
{
    pthread_mutex_lock(lock);
    *flag = value;
    pthread_mutex_unlock(lock);
}

#endif  // HOST_INTERNAL_H
