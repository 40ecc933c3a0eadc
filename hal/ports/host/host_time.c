// SPDX-License-Identifier: MIT
// dynaqpc host port: the clock (lock-step or real-time), where an idle wait would end, and cycle
// accounting. The bottom of the port: it uses no other file of it.
//
// Lock-step time is a plain counter that only the simulator (and hal_cpu_account()) moves, so a
// run depends on nothing the OS does; the firmware's idle wait is recorded here for the simulator
// (hal_host_wait_deadline) and ends when time moves or a wake arrives. Real-time mode maps
// CLOCK_MONOTONIC through a speed factor; host_time_idle_begin() turns a wait's deadline into the
// monotonic instant the CPU's wait (host_cpu.c, with its wake latch) sleeps until.
#include <pthread.h>
#include <time.h>

#include "fw/fw_base.h"
#include "hal/hal_cpu.h"
#include "hal/hal_time.h"
#include "hal_host/hal_host.h"
#include "host_internal.h"

static pthread_mutex_t lock_ = PTHREAD_MUTEX_INITIALIZER;

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

static void lock(void)
{
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

// Caller holds the lock. Both ways the simulator moves lock-step time: forward only (an
// advance that would wrap is a move backwards, refused), and a move ends the recorded wait.
static int move_to_locked(uint64_t t_us)
{
    if (mode_ != HAL_HOST_CLOCK_LOCKSTEP || t_us < virt_us_) {
        return FW_ERR_INVAL;
    }
    virt_us_ = t_us;
    waiting_ = false;
    return FW_OK;
}

int hal_host_time_set_us(uint64_t t_us)
{
    lock();
    const int rc = move_to_locked(t_us);
    unlock();
    return rc;
}

int hal_host_time_advance_us(uint64_t dt_us)
{
    lock();
    const int rc = move_to_locked(virt_us_ + dt_us);
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

bool host_time_idle_begin(uint64_t deadline_us, uint64_t *until_ns)
{
    lock();
    bool sleep = false;
    if (mode_ == HAL_HOST_CLOCK_LOCKSTEP) {
        waiting_ = true;
        wait_deadline_us_ = deadline_us;
    } else {
        const uint64_t now = now_us_locked();
        if (deadline_us > now) {
            // At most one wall-clock second per wait: spurious returns are allowed, and this
            // keeps the arithmetic far from overflow for a deadline of UINT64_MAX.
            double wait_ns = (double)(deadline_us - now) * 1000.0 / speed_;
            if (wait_ns > 1e9) {
                wait_ns = 1e9;
            }
            *until_ns = mono_ns() + (uint64_t)wait_ns + 1u;
            sleep = true;
        }
    }
    unlock();
    return sleep;
}

void host_time_idle_end(void)
{
    lock();
    waiting_ = false;
    unlock();
}
