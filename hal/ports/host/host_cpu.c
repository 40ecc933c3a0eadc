// SPDX-License-Identifier: MIT
// dynaqpc host port: interrupt masking (a recursive mutex), the watchdog, the reset cause, and
// hal_host_reset().
//
// "Masking interrupts" on a PC means: while the main loop holds the lock, no receiver thread
// can run a handler, and while a handler runs, the main loop cannot enter a critical section.
// Recursive, because a handler (which runs with the lock held) calls sched_post(), which saves
// and restores again, exactly as nested masking works on the MCU.
#include <pthread.h>

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

uint32_t host_irq_release(void)
{
    const uint32_t depth = my_depth_;
    for (uint32_t i = 0; i < depth; i++) {
        hal_irq_restore(0);
    }
    return depth;
}

void host_irq_reacquire(uint32_t depth)
{
    for (uint32_t i = 0; i < depth; i++) {
        (void)hal_irq_save();
    }
}

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
    pthread_mutex_lock(&wd_lock_);
    uint32_t k = wd_kicks_;
    pthread_mutex_unlock(&wd_lock_);
    return k;
}

uint32_t hal_host_watchdog_timeout_ms(void)
{
    pthread_mutex_lock(&wd_lock_);
    uint32_t t = wd_timeout_ms_;
    pthread_mutex_unlock(&wd_lock_);
    return t;
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
}

void hal_host_reset(void)
{
    host_uart_reset(); // first: it stops the reader thread
    host_can_reset();
    host_cpu_reset();
    host_flash_reset();
    host_time_reset();
}
