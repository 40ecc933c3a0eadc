// SPDX-License-Identifier: MIT
// dynaqpc scheduler: periodic run-to-completion tasks, an interrupt-fed event queue, and idle
// work (the agent's planning updates) fitted into the time left before the next deadline.
//
// One main loop, no preemption, no heap. Interrupt handlers only post events; the main loop
// dispatches them, runs the tasks that are due, then calls the idle hook one bounded step at a
// time while the next deadline is far enough away, then sleeps until the next wake-up:
//
//     sched_init(&s, &cfg);  sched_add_task(&s, &control);  ...
//     for (;;) { sched_step(&s); }
//
// Portable: it calls only hal_time.h and hal_cpu.h. hal_can.h is included for one type, the
// CAN frame an event can carry (sched_event_t.can); the scheduler makes no CAN call.
#ifndef SCHED_SCHED_H
#define SCHED_SCHED_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_can.h"
#include "sched/sched_config.h"

#ifdef __cplusplus
extern "C" {
#endif

/// A task's handle: its index in the table, 0 .. FW_CFG_SCHED_MAX_TASKS - 1, in the order added.
typedef uint8_t sched_task_id_t;

/// A task body. Runs to completion in the main loop (thread context). `ctx` is the task's.
typedef void (*sched_task_fn)(void *ctx);

/// A periodic task. Release k happens at epoch + phase_us + k * period_us, where epoch is the
/// time of sched_init().
typedef struct sched_task_config {
    const char *name;       ///< for telemetry; may be NULL
    sched_task_fn fn;       ///< required
    void *ctx;              ///< passed to fn
    uint32_t period_us;     ///< > 0
    uint32_t phase_us;      ///< first release after the epoch; < period_us
    /// Lateness allowed: a run that starts more than this after its release is a miss. 0 allows
    /// none (exact in lock-step only). sched_tolerance_us(period_us) is the project's rule:
    /// FW_CFG_SCHED_TOLERANCE_PERMILLE of the period (10 %), see sched_config.h for why.
    uint32_t tolerance_us;
    /// CPU cycles one run takes, passed to hal_cpu_account() after each run (0 = unknown: not
    /// accounted). Lets the host's lock-step mode charge the run's time to virtual time.
    uint32_t cost_cycles;
} sched_task_config_t;

/// One event as an interrupt handler posts it: a type and a payload.
typedef struct sched_event {
    uint8_t type;            ///< 0 .. FW_CFG_SCHED_EVENT_TYPES - 1; picks the handler
    union {
        hal_can_frame_t can; ///< a received CAN frame
        uint32_t word;       ///< a small value (a flag, a count, a byte)
        uint8_t bytes[sizeof(hal_can_frame_t)];
    } u;
} sched_event_t;

/// Handles one dispatched event, in the main loop (thread context). The event is a copy that
/// lives only for the call.
typedef void (*sched_event_fn)(const sched_event_t *event, void *ctx);

/// ONE bounded unit of idle work (one planning update). Returns true if it did work (and there
/// may be more), false if there was nothing to do. Thread context.
typedef bool (*sched_idle_fn)(void *ctx);

/// What sched_init() needs besides the tasks.
typedef struct sched_config {
    sched_idle_fn idle;          ///< may be NULL: no idle work, the loop just sleeps
    void *idle_ctx;
    /// Worst-case duration of one idle step. Idle work runs only while
    /// now + idle_step_budget_us + guard_us <= next deadline, so a task waits at most one step
    /// (if the budget is honest) and, in lock-step, is never late.
    uint32_t idle_step_budget_us;
    uint32_t guard_us;           ///< extra margin before a deadline (wake-up latency, jitter)
    /// CPU cycles of one idle step, passed to hal_cpu_account() after each step that did work
    /// (0 = not accounted). On the host in lock-step this is what makes idle steps take time.
    uint32_t idle_step_cycles;
} sched_config_t;

/// Per-task counters.
///
/// Deadline misses, precisely. Release k of a task is due at r_k. It counts as ONE miss if any
/// of these holds, and otherwise as none:
///   - skipped: the scheduler reaches the task only at or after r_{k+1} (an earlier release
///     overran, or another task or a late wake-up delayed it). A skipped release is never run
///     later: only the latest release that has passed is run, the older ones are skipped;
///   - late: it starts more than tolerance_us after r_k;
///   - overrun: it is still running at r_{k+1} (its run ends after r_{k+1}).
typedef struct sched_task_stats {
    uint32_t runs;               ///< releases run
    uint32_t misses;             ///< releases missed (each release counted at most once)
    uint32_t skipped;            ///< of the misses, releases never run
    uint32_t overruns;           ///< of the misses, runs still going at the next release
    uint32_t late;               ///< of the misses, runs started more than tolerance_us late
                                 ///< (a run both late and overrunning is one miss)
    uint32_t worst_lateness_us;  ///< largest start - release over the runs
    uint32_t worst_run_us;       ///< longest run (start to end, including accounted cycles)
} sched_task_stats_t;

/// The scheduler's counters. Idle steps are the calls of the idle hook that returned true.
typedef struct sched_stats {
    sched_task_stats_t task[FW_CFG_SCHED_MAX_TASKS]; ///< by sched_task_id_t
    uint32_t task_count;
    uint64_t idle_steps;             ///< total idle steps
    /// Idle steps between the two latest starts of the period task (sched_set_period_task(),
    /// default task 0): the planning updates the last complete period got. 0 until that task
    /// has run twice. min/max are over every complete period so far.
    uint32_t idle_steps_last_period;
    uint32_t idle_steps_min_period;
    uint32_t idle_steps_max_period;
    uint32_t periods_measured;       ///< complete periods behind the three figures above
    uint64_t idle_work_us;           ///< time spent in idle steps
    /// Time outside tasks and handlers: idle work + waiting, up to now (or, asked from a task or
    /// handler, up to the start of the current pass).
    uint64_t idle_us;
    uint32_t events_posted;          ///< accepted by sched_post()
    uint32_t events_dropped;         ///< refused by sched_post() because the queue was full
    uint32_t events_dispatched;      ///< taken out of the queue (handled or unhandled)
    uint32_t events_unhandled;       ///< of those, with no handler registered for their type
    uint32_t events_high_water;      ///< most events ever queued at once
    uint32_t passes;                 ///< sched_step() calls
} sched_stats_t;

/// A scheduler. Opaque in use; public so that the caller owns its storage (declare it static).
/// How late a task's runs started: a histogram of start - release over its runs.
typedef struct sched_lateness {
    /// Runs by lateness: [0] started at the release, [k] (1 .. B-2) 2^(k-1) .. 2^k - 1 us late,
    /// [B-1] at least 2^(B-2) us late (B = FW_CFG_SCHED_LATENESS_BUCKETS).
    /// sched_lateness_bucket_max_us(k) is bucket k's upper limit.
    uint32_t bucket[FW_CFG_SCHED_LATENESS_BUCKETS];
    uint32_t runs;          ///< runs counted (the sum of the buckets)
    uint32_t worst_us;      ///< the largest lateness (worst_lateness_us)
    const char *name;       ///< the task's name, period and tolerance, to read the figures by
    uint32_t period_us;
    uint32_t tolerance_us;
} sched_lateness_t;

typedef struct sched_task {
    sched_task_config_t cfg;
    uint64_t next_release_us; // the oldest release not yet run or skipped
    sched_task_stats_t stats;
    uint32_t lateness[FW_CFG_SCHED_LATENESS_BUCKETS];
} sched_task_t;

typedef struct sched_handler {
    sched_event_fn fn;
    void *ctx;
} sched_handler_t;

// (Members ordered so the struct has little padding: the 192 KiB paper-sim image has none to spare.)
typedef struct sched {
    uint64_t epoch_us;
    uint64_t idle_steps_at_period_start;
    uint64_t idle_since_us;    // end of the last busy stretch (tasks, handlers)
    sched_stats_t stats;
    sched_task_t tasks[FW_CFG_SCHED_MAX_TASKS];
    sched_config_t cfg;
    uint32_t task_count;
    sched_handler_t handlers[FW_CFG_SCHED_EVENT_TYPES];
    // The event ring: written by interrupt handlers, read by the main loop, both under
    // hal_irq_save(). head and tail run freely and are masked on use.
    volatile uint32_t ev_head; // next to take
    volatile uint32_t ev_tail; // next free
    sched_event_t events[FW_CFG_SCHED_EVENT_CAPACITY];
    sched_task_id_t period_task;
    bool period_started;
    bool busy;                 // dispatching events or running tasks
} sched_t;

/// Prepares an empty scheduler (no tasks, no handlers) whose epoch is hal_time_us() now.
/// Call after hal_time_init(). Returns FW_OK, or FW_ERR_INVAL (NULL arguments).
/// Context: thread, at boot, before interrupts that post are enabled.
FW_CHECK_RETURN int sched_init(sched_t *s, const sched_config_t *cfg);

/// Adds a periodic task. Returns its id (>= 0), FW_ERR_INVAL (no fn, period 0, phase >= period),
/// or FW_ERR_NOMEM (FW_CFG_SCHED_MAX_TASKS already added). A task added before the first
/// sched_step() is first released at epoch + phase_us; one added later, at its first release
/// (on the same grid) that is not in the past.
/// Context: thread, at boot.
FW_CHECK_RETURN int sched_add_task(sched_t *s, const sched_task_config_t *task);

/// Registers `fn` (NULL: unregisters) for events of `type`, replacing any previous handler.
/// Returns FW_OK or FW_ERR_INVAL (type >= FW_CFG_SCHED_EVENT_TYPES).
/// Context: thread, at boot.
int sched_on_event(sched_t *s, uint8_t type, sched_event_fn fn, void *ctx);

/// Chooses the task whose periods idle_steps_*_period are counted over (default: task 0) and
/// restarts that measurement. Returns FW_OK or FW_ERR_INVAL (no such task). Context: thread.
int sched_set_period_task(sched_t *s, sched_task_id_t id);

/// Copies `event` into the queue, in O(1), inside hal_irq_save()/hal_irq_restore().
/// Returns FW_OK, FW_ERR_INVAL (NULL, or type >= FW_CFG_SCHED_EVENT_TYPES), or FW_ERR_FULL (the
/// queue holds FW_CFG_SCHED_EVENT_CAPACITY events: this one is dropped and counted in
/// events_dropped). Events are dispatched in the order they were accepted.
/// Context: any, including interrupt handlers. Never blocks.
int sched_post(sched_t *s, const sched_event_t *event);

/// One pass of the main loop:
///  1. dispatches the events queued when the pass starts, oldest first (one handler call each;
///     events posted meanwhile wait for the next pass);
///  2. runs each task that is due (release <= now), earliest release first (ties: lower id),
///     each at most once per pass; after each run, hal_cpu_account(cost_cycles);
///  3. if no task is still due and no event is pending, calls the idle hook while
///     now + idle_step_budget_us + guard_us <= the next release and the hook returns true
///     (at most FW_CFG_SCHED_IDLE_STEPS_PER_PASS times; it stops early when an event arrives);
///     after each step that did work, hal_cpu_account(idle_step_cycles);
///  4. calls hal_cpu_wait_until(sched_next_wakeup()) — unless a task is due, an event is
///     pending, or the step limit cut idle work short: then it returns without waiting.
/// Bounded: it never loops on time. Context: thread (the main loop) only.
void sched_step(sched_t *s);

/// The earliest pending release over all tasks (UINT64_MAX with no task). Context: thread.
uint64_t sched_next_wakeup(const sched_t *s);

/// A consistent snapshot of the counters. Context: thread.
void sched_get_stats(const sched_t *s, sched_stats_t *out);

/// Events queued now. Context: any.
uint32_t sched_pending_events(const sched_t *s);

/// The project's deadline tolerance for a task of period `period_us`:
/// period_us * FW_CFG_SCHED_TOLERANCE_PERMILLE / 1000, rounded down. Context: any.
uint32_t sched_tolerance_us(uint32_t period_us);

/// Copies task `id`'s lateness histogram into `out`. Returns FW_OK or FW_ERR_INVAL (NULL, no
/// such task). Context: thread.
int sched_get_lateness(const sched_t *s, sched_task_id_t id, sched_lateness_t *out);

/// The largest lateness bucket `b` of a sched_lateness_t holds: 0 for bucket 0, 2^b - 1 us for
/// the buckets in between, UINT32_MAX for the last one (and beyond). Context: any.
uint32_t sched_lateness_bucket_max_us(uint32_t b);

/// An upper bound on the lateness of the `permille` / 1000 share of runs that started earliest
/// (500: the median, 990: the 99th percentile; above 1000 counts as 1000): the upper limit of
/// the bucket in which that share is reached, but never more than worst_us (so 1000 gives
/// worst_us). Log2 buckets: the bound is within a factor of 2. 0 when there were no runs.
/// Context: any.
uint32_t sched_lateness_percentile_us(const sched_lateness_t *l, uint32_t permille);

#ifdef __cplusplus
}
#endif

#endif // SCHED_SCHED_H
