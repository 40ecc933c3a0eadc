// SPDX-License-Identifier: MIT
// dynaqpc host port: the clock (lock-step or real-time), idle waiting and cycle accounting.
//
// Lock-step time is a plain counter that only the simulator (and hal_cpu_account()) moves, so a
// run depends on nothing the OS does. Real-time mode maps CLOCK_MONOTONIC through a speed factor;
// the wait is a condition variable on the monotonic clock so that a receiver thread can cut it
// short, and a wake that arrives before the wait is remembered (wake_pending) rather than lost.
#include <errno.h>
#include <pthread.h>
#include <time.h>

#include "fw/fw_base.h"
#include "hal/hal_cpu.h"
#include "hal/hal_time.h"
#include "hal_host/hal_host.h"
#include "host_internal.h"

static pthread_mutex_t lock_ = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t wake_cond_;
static pthread_once_t once_ = PTHREAD_ONCE_INIT;

static hal_host_clock_mode_t mode_ = HAL_HOST_CLOCK_LOCKSTEP;
// Lock-step
static uint64_t virt_us_;
static uint64_t cycle_rem_;       // cycles * 1e6 not yet turned into whole microseconds
static uint32_t hz_ = FW_CFG_HOST_CPU_HZ;
static uint64_t accounted_cycles_;
static bool waiting_;
static uint64_t wait_deadline_us_;
// Real-time
static uint64_t origin_ns_;       // CLOCK_MONOTONIC at the (re)base
static uint64_t base_us_;         // firmware time at the (re)base
static uint64_t last_us_;         // never return less than this
static double speed_ = 1.0;
static bool wake_pending_;

static void init_once(void)
{
    pthread_condattr_t attr;
    pthread_condattr_init(&attr);
    pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
    pthread_cond_init(&wake_cond_, &attr);
    pthread_condattr_destroy(&attr);
}

static void lock(void)
{
    pthread_once(&once_, init_once);
    pthread_mutex_lock(&lock_);
}

static void unlock(void)
{
    pthread_mutex_unlock(&lock_);
}

static uint64_t mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

// Caller holds the lock.
static uint64_t now_us_locked(void)
{
    if (mode_ == HAL_HOST_CLOCK_LOCKSTEP) {
        return virt_us_;
    }
    uint64_t t = base_us_ + (uint64_t)((double)(mono_ns() - origin_ns_) * speed_ / 1000.0);
    if (t < last_us_) {
        t = last_us_;
    }
    last_us_ = t;
    return t;
}

static void restart_locked(void)
{
    virt_us_ = 0;
    cycle_rem_ = 0;
    waiting_ = false;
    wait_deadline_us_ = 0;
    origin_ns_ = mono_ns();
    base_us_ = 0;
    last_us_ = 0;
    wake_pending_ = false;
}

void host_time_reset(void)
{
    lock();
    mode_ = HAL_HOST_CLOCK_LOCKSTEP;
    hz_ = FW_CFG_HOST_CPU_HZ;
    speed_ = 1.0;
    accounted_cycles_ = 0;
    restart_locked();
    unlock();
}

int hal_time_init(void)
{
    lock();
    restart_locked();
    unlock();
    return FW_OK;
}

uint64_t hal_time_us(void)
{
    lock();
    uint64_t t = now_us_locked();
    unlock();
    return t;
}

void hal_host_time_set_mode(hal_host_clock_mode_t mode)
{
    lock();
    mode_ = mode == HAL_HOST_CLOCK_REALTIME ? HAL_HOST_CLOCK_REALTIME : HAL_HOST_CLOCK_LOCKSTEP;
    restart_locked();
    unlock();
}

hal_host_clock_mode_t hal_host_time_mode(void)
{
    lock();
    hal_host_clock_mode_t m = mode_;
    unlock();
    return m;
}

int hal_host_time_set_us(uint64_t t_us)
{
    int rc = FW_ERR_INVAL;
    lock();
    if (mode_ == HAL_HOST_CLOCK_LOCKSTEP && t_us >= virt_us_) {
        virt_us_ = t_us;
        waiting_ = false;
        rc = FW_OK;
    }
    unlock();
    return rc;
}

int hal_host_time_advance_us(uint64_t dt_us)
{
    int rc = FW_ERR_INVAL;
    lock();
    if (mode_ == HAL_HOST_CLOCK_LOCKSTEP && virt_us_ + dt_us >= virt_us_) {
        virt_us_ += dt_us;
        waiting_ = false;
        rc = FW_OK;
    }
    unlock();
    return rc;
}

int hal_host_time_set_speed(double speed)
{
    if (!(speed > 0.0 && speed <= 1e6)) {
        return FW_ERR_INVAL;
    }
    lock();
    if (mode_ == HAL_HOST_CLOCK_REALTIME) {
        // Rebase so that the new factor applies from now on and time stays continuous.
        base_us_ = now_us_locked();
        origin_ns_ = mono_ns();
    }
    speed_ = speed;
    unlock();
    return FW_OK;
}

int hal_host_cpu_set_hz(uint32_t hz)
{
    if (hz == 0u) {
        return FW_ERR_INVAL;
    }
    lock();
    hz_ = hz;
    cycle_rem_ = 0;
    unlock();
    return FW_OK;
}

uint64_t hal_host_cpu_accounted_cycles(void)
{
    lock();
    uint64_t c = accounted_cycles_;
    unlock();
    return c;
}

void hal_cpu_account(uint32_t cycles)
{
    lock();
    accounted_cycles_ += cycles;
    if (mode_ == HAL_HOST_CLOCK_LOCKSTEP) {
        // Keep the remainder, so that many small steps add up to exactly what one big one would.
        cycle_rem_ += (uint64_t)cycles * 1000000u;
        virt_us_ += cycle_rem_ / hz_;
        cycle_rem_ %= hz_;
    }
    unlock();
}

uint64_t hal_host_wait_deadline(void)
{
    lock();
    uint64_t t = waiting_ && wait_deadline_us_ > virt_us_ ? wait_deadline_us_ : virt_us_;
    unlock();
    return t;
}

void hal_host_cpu_wake(void)
{
    lock();
    waiting_ = false;
    wake_pending_ = true;
    pthread_cond_broadcast(&wake_cond_);
    unlock();
}

static bool last_wait_masked_;

bool hal_host_last_wait_masked(void)
{
    return last_wait_masked_;
}

void hal_cpu_wait_until(uint64_t deadline_us)
{
    const uint32_t masked = host_irq_release();
    lock();
    last_wait_masked_ = masked > 0u;
    if (mode_ == HAL_HOST_CLOCK_LOCKSTEP) {
        waiting_ = true;
        wait_deadline_us_ = deadline_us;
        wake_pending_ = false;
        unlock();
        host_irq_reacquire(masked);
        return;
    }
    uint64_t now = now_us_locked();
    if (!wake_pending_ && deadline_us > now) {
        // At most one wall-clock second per wait: spurious returns are allowed, and this keeps
        // the arithmetic far from overflow for a deadline of UINT64_MAX.
        double wait_ns = (double)(deadline_us - now) * 1000.0 / speed_;
        if (wait_ns > 1e9) {
            wait_ns = 1e9;
        }
        uint64_t until = mono_ns() + (uint64_t)wait_ns + 1u;
        struct timespec ts;
        ts.tv_sec = (time_t)(until / 1000000000u);
        ts.tv_nsec = (long)(until % 1000000000u);
        while (!wake_pending_) {
            if (pthread_cond_timedwait(&wake_cond_, &lock_, &ts) == ETIMEDOUT) {
                break;
            }
        }
    }
    wake_pending_ = false;
    unlock();
    host_irq_reacquire(masked);
}
