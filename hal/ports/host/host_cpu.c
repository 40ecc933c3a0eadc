// SPDX-License-Identifier: MIT
// dynaqpc host port: the CPU contract (hal_cpu.h): interrupt masking (a recursive mutex), the
// idle wait with its wake latch, the watchdog and the reset cause. Uses the clock (host_time.c);
// the peripherals (host_can.c, host_uart.c) use it to mask and to wake it.
//
// "Masking interrupts" on a PC means: while the main loop holds the lock, no receiver thread
// can run a handler, and while a handler runs, the main loop cannot enter a critical section.
// Recursive, because a handler (which runs with the lock held) calls sched_post(), which saves
// and restores again, exactly as nested masking works on the MCU.
//
// The wait is a condition variable on the monotonic clock, so that a receiver thread can cut it
// short, and a wake that arrives before the wait is remembered (wake_pending_) rather than lost,
// as WFI remembers a pending interrupt.
#include <errno.h>
#include <pthread.h>
#include <time.h>

#include "fw/fw_base.h"
#include "hal/hal_cpu.h"
#include "hal/hal_time.h"
#include "hal_host/hal_host.h"
#include "host_internal.h"

static pthread_mutex_t irq_mutex_;
static pthread_once_t irq_once_ = PTHREAD_ONCE_INIT;
static uint32_t irq_depth_; // protected by irq_mutex_ itself
static __thread uint32_t my_depth_; // this thread's nesting: it holds irq_mutex_ when > 0

static pthread_mutex_t wd_lock_ = PTHREAD_MUTEX_INITIALIZER;
static uint32_t wd_timeout_ms_;
static uint32_t wd_kicks_;
static uint64_t wd_last_kick_us_;
static hal_reset_cause_t reset_cause_ = HAL_RESET_POWER_ON;

static void irq_init_once(void)
{
    pthread_mutexattr_t attr;
    pthread_mutexattr_init(&attr);
    pthread_mutexattr_settype(&attr, PTHREAD_MUTEX_RECURSIVE);
    pthread_mutex_init(&irq_mutex_, &attr);
    pthread_mutexattr_destroy(&attr);
}

hal_irq_state_t hal_irq_save(void)
{
    pthread_once(&irq_once_, irq_init_once);
    pthread_mutex_lock(&irq_mutex_);
    my_depth_++;
    return irq_depth_++;
}

void hal_irq_restore(hal_irq_state_t state)
{
    (void)state;
    irq_depth_--;
    my_depth_--;
    pthread_mutex_unlock(&irq_mutex_);
}

// hal_cpu_wait_until() called with "interrupts masked": the calling thread lets go of the irq
// mutex (all its nesting, returned) so that receiver threads can deliver while it sleeps, and
// takes it back after. Safe because the wake latch remembers any delivery since the caller's
// last check.
static uint32_t irq_release_(void)
{
    const uint32_t depth = my_depth_;
    for (uint32_t i = 0; i < depth; i++) {
        hal_irq_restore(0);
    }
    return depth;
}

static void irq_reacquire_(uint32_t depth)
{
    for (uint32_t i = 0; i < depth; i++) {
        (void)hal_irq_save();
    }
}

// ---- The idle wait and its wake latch ------------------------------------------------------------
static pthread_mutex_t wait_lock_ = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t wake_cond_;
static pthread_once_t wait_once_ = PTHREAD_ONCE_INIT;
static bool wake_pending_; // protected by wait_lock_
static bool last_wait_masked_;

static void wait_init_once(void)
{
    pthread_condattr_t attr;
    pthread_condattr_init(&attr);
    pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
    pthread_cond_init(&wake_cond_, &attr);
    pthread_condattr_destroy(&attr);
}

static void wait_lock(void)
{
    pthread_once(&wait_once_, wait_init_once);
    pthread_mutex_lock(&wait_lock_);
}

void hal_host_cpu_wake(void)
{
    wait_lock();
    host_time_idle_end();
    wake_pending_ = true;
    pthread_cond_broadcast(&wake_cond_);
    pthread_mutex_unlock(&wait_lock_);
}

bool hal_host_last_wait_masked(void)
{
    return last_wait_masked_;
}

void hal_cpu_wait_until(uint64_t deadline_us)
{
    const uint32_t masked = irq_release_();
    wait_lock();
    last_wait_masked_ = masked > 0u;
    // Lock-step: the wait is recorded for the simulator and returns at once. Real time: sleep
    // until the deadline unless a wake is pending or comes.
    uint64_t until = 0;
    if (host_time_idle_begin(deadline_us, &until)) {
        struct timespec ts;
        ts.tv_sec = (time_t)(until / 1000000000u);
        ts.tv_nsec = (long)(until % 1000000000u);
        while (!wake_pending_) {
            if (pthread_cond_timedwait(&wake_cond_, &wait_lock_, &ts) == ETIMEDOUT) {
                break;
            }
        }
    }
    wake_pending_ = false;
    pthread_mutex_unlock(&wait_lock_);
    irq_reacquire_(masked);
}

// ---- Watchdog and reset cause ------------------------------------------------------------------------
int hal_cpu_watchdog_start(uint32_t timeout_ms)
{
    if (timeout_ms == 0u) {
        return FW_ERR_INVAL;
    }
    uint64_t now = hal_time_us();
    pthread_mutex_lock(&wd_lock_);
    wd_timeout_ms_ = timeout_ms;
    wd_kicks_ = 0;
    wd_last_kick_us_ = now;
    pthread_mutex_unlock(&wd_lock_);
    return FW_OK;
}

void hal_cpu_watchdog_kick(void)
{
    uint64_t now = hal_time_us();
    pthread_mutex_lock(&wd_lock_);
    if (wd_timeout_ms_ != 0u) {
        wd_kicks_++;
        wd_last_kick_us_ = now;
    }
    pthread_mutex_unlock(&wd_lock_);
}

bool hal_host_watchdog_expired(void)
{
    uint64_t now = hal_time_us();
    pthread_mutex_lock(&wd_lock_);
    bool expired =
        wd_timeout_ms_ != 0u && now - wd_last_kick_us_ > (uint64_t)wd_timeout_ms_ * 1000u;
    pthread_mutex_unlock(&wd_lock_);
    return expired;
}

uint32_t hal_host_watchdog_kicks(void)
{
    return host_locked_u32(&wd_lock_, &wd_kicks_);
}

uint32_t hal_host_watchdog_timeout_ms(void)
{
    return host_locked_u32(&wd_lock_, &wd_timeout_ms_);
}

hal_reset_cause_t hal_cpu_reset_cause(void)
{
    pthread_mutex_lock(&wd_lock_);
    hal_reset_cause_t c = reset_cause_;
    pthread_mutex_unlock(&wd_lock_);
    return c;
}

void hal_host_set_reset_cause(hal_reset_cause_t cause)
{
    pthread_mutex_lock(&wd_lock_);
    reset_cause_ = cause;
    pthread_mutex_unlock(&wd_lock_);
}

void host_cpu_reset(void)
{
    pthread_mutex_lock(&wd_lock_);
    wd_timeout_ms_ = 0;
    wd_kicks_ = 0;
    wd_last_kick_us_ = 0;
    reset_cause_ = HAL_RESET_POWER_ON;
    pthread_mutex_unlock(&wd_lock_);
    wait_lock();
    wake_pending_ = false;
    last_wait_masked_ = false;
    pthread_mutex_unlock(&wait_lock_);
}
