// SPDX-License-Identifier: MIT
// dynaqpc host port: how long a receiver thread was away, told apart from how long it waited for
// a CPU.
//
// The pty reader (host_uart.c) and the firmware's CAN receive thread (host_sim/fw/fw_main.cpp)
// stand in for receive interrupts. Away from their line for longer than their stall threshold,
// the process was stopped (SIGSTOP, a debugger): what the line or the socket holds then arrived
// while no interrupt could run, and is lost as on the MCU. They used to measure that as the
// wall-clock gap between two looks at the line. On a loaded host, though, a thread whose poll
// timed out may wait on the run queue for tens of milliseconds before it runs (measured: the
// reader of unit.hal_host judged a 48-byte line written while it ran a "stall" and kept one byte
// of it, 4 runs in 120 next to five busy loops). An MCU's receive interrupt never waits for a
// CPU, so that loss was the host's, not the firmware's.
//
// Linux counts, per thread, the time it ran and the time it was runnable but waiting on a run
// queue (/proc/thread-self/schedstat: cpu ns, run-queue wait ns, timeslices). What remains of the
// wall-clock interval between two looks is the time the thread was asleep (its poll's timeout,
// its pacing, a lock's wait) or stopped: its absence. A stopped thread is in neither state, so a
// SIGSTOP shows in full wherever it lands; a load that keeps the thread off the CPU does not. A
// wait for a lock counts: the firmware's irq mutex held long is interrupts masked too long, which
// delays the MCU's interrupt as well. (Counting only the thread's own sleeps would leave out lock
// waits, but a receiver busy with a stream at 1,000 frames a second spends most of its time out
// of them, and missed a SIGSTOP there: e2e.cricket_stall's event queue overflowed.) Without
// schedstat (another kernel, /proc not mounted) the absence is the whole interval, as before.
#include <fcntl.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include "hal_host/hal_host.h"

static int64_t wall_us(void)
{
    struct timespec ts;
    (void)clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

// The calling thread's run time plus run-queue wait, in microseconds; false where the kernel
// does not say.
static bool sched_busy_us(int64_t *out)
{
    const int fd = open("/proc/thread-self/schedstat", O_RDONLY);
    if (fd < 0) {
        return false;
    }
    char buf[96];
    const ssize_t n = read(fd, buf, sizeof buf - 1u);
    (void)close(fd);
    if (n <= 0) {
        return false;
    }
    buf[n] = '\0';
    char *end = NULL;
    const unsigned long long ran_ns = strtoull(buf, &end, 10);
    if (end == buf) {
        return false;
    }
    char *end2 = NULL;
    const unsigned long long waited_ns = strtoull(end, &end2, 10);
    if (end2 == end) {
        return false;
    }
    *out = (int64_t)((ran_ns + waited_ns) / 1000u);
    return true;
}

// A look: the wall clock and the thread's busy time at one instant. A thread preempted between
// the two reads would pair a clock from before its wait with a busy time after it (or the other
// way round) and misjudge the lap by that wait, so the clock is read between two busy times and
// kept when they agree within SAMPLE_AGREE_US (no wait came between; run time accrues too, in
// microseconds). Bounded: after SAMPLE_TRIES the last sample is kept.
#define SAMPLE_AGREE_US 1000
#define SAMPLE_TRIES 4
void hal_host_absence_start(hal_host_absence_t *a)
{
    if (a == NULL) {
        return;
    }
    for (int i = 0; i < SAMPLE_TRIES; i++) {
        int64_t before = 0, after = 0;
        a->known = sched_busy_us(&before);
        a->wall_us = wall_us();
        a->known = a->known && sched_busy_us(&after);
        a->busy_us = a->known ? before : 0;
        if (!a->known || after - before < SAMPLE_AGREE_US) {
            break;
        }
    }
}

int64_t hal_host_absence_lap_us(hal_host_absence_t *a)
{
    if (a == NULL) {
        return 0;
    }
    const int64_t wall0 = a->wall_us;
    const int64_t busy0 = a->busy_us;
    const bool known0 = a->known;
    hal_host_absence_start(a);
    int64_t away = a->wall_us - wall0;
    if (known0 && a->known) {
        away -= a->busy_us - busy0;
    }
    // schedstat is in ns and the clock read apart from it: a few microseconds either way.
    return away > 0 ? away : 0;
}

bool hal_host_absence_known(void)
{
    int64_t busy;
    return sched_busy_us(&busy);
}
