// SPDX-License-Identifier: MIT
// dynaqpc scheduler. The contract is in sched/sched.h; this file says why it is built this way.
//
// I keep one main loop and no preemption: tasks run to completion, so the agent's tables need no
// locks; interrupt handlers touch only the event ring, under hal_irq_save(). Every pass is
// bounded (each task at most once, events snapshotted at the start, idle steps capped), so the
// same code cannot hang a lock-step simulation in which time moves only when someone says so.
#include "sched/sched.h"

#include <string.h>

#include "fw/fw_base.h"
#include "fw/fw_util.h"
#include "hal/hal_cpu.h"
#include "hal/hal_time.h"

#define EVENT_MASK ((uint32_t)FW_CFG_SCHED_EVENT_CAPACITY - 1u)

static uint32_t add_sat_u32(uint32_t a, uint64_t b)
{
    uint64_t sum = (uint64_t)a + b;
    return sum > UINT32_MAX ? UINT32_MAX : (uint32_t)sum;
}

int sched_init(sched_t *s, const sched_config_t *cfg)
{
    if (s == NULL || cfg == NULL) {
        return FW_ERR_INVAL;
    }
    memset(s, 0, sizeof *s);
    s->cfg = *cfg;
    s->epoch_us = hal_time_us();
    s->idle_since_us = s->epoch_us;
    s->stats.idle_steps_min_period = UINT32_MAX;
    return FW_OK;
}

int sched_add_task(sched_t *s, const sched_task_config_t *task)
{
    if (s == NULL || task == NULL || task->fn == NULL || task->period_us == 0u ||
        task->phase_us >= task->period_us) {
        return FW_ERR_INVAL;
    }
    if (s->task_count >= (uint32_t)FW_CFG_SCHED_MAX_TASKS) {
        return FW_ERR_NOMEM;
    }
    sched_task_t *t = &s->tasks[s->task_count];
    memset(t, 0, sizeof *t);
    t->cfg = *task;
    // Releases stay on the epoch's grid even for a task added while the loop runs: its first
    // release is the first grid point not in the past, and the ones before it were never owed.
    // Before the first pass, the boot's own time since sched_init() does not count.
    uint64_t first = s->epoch_us + task->phase_us;
    uint64_t now = hal_time_us();
    if (s->stats.passes > 0u && first < now) {
        uint64_t behind = (now - first + task->period_us - 1u) / task->period_us;
        first += behind * task->period_us;
    }
    t->next_release_us = first;
    return (int)s->task_count++;
}

int sched_on_event(sched_t *s, uint8_t type, sched_event_fn fn, void *ctx)
{
    if (s == NULL || type >= (uint32_t)FW_CFG_SCHED_EVENT_TYPES) {
        return FW_ERR_INVAL;
    }
    s->handlers[type].fn = fn;
    s->handlers[type].ctx = fn != NULL ? ctx : NULL;
    return FW_OK;
}

int sched_set_period_task(sched_t *s, sched_task_id_t id)
{
    if (s == NULL || id >= s->task_count) {
        return FW_ERR_INVAL;
    }
    s->period_task = id;
    s->period_started = false;
    s->stats.idle_steps_last_period = 0u;
    s->stats.idle_steps_min_period = UINT32_MAX;
    s->stats.idle_steps_max_period = 0u;
    s->stats.periods_measured = 0u;
    return FW_OK;
}

int sched_post(sched_t *s, const sched_event_t *event)
{
    if (s == NULL || event == NULL || event->type >= (uint32_t)FW_CFG_SCHED_EVENT_TYPES) {
        return FW_ERR_INVAL;
    }
    int rc = FW_OK;
    hal_irq_state_t irq = hal_irq_save();
    uint32_t count = s->ev_tail - s->ev_head;
    if (count >= (uint32_t)FW_CFG_SCHED_EVENT_CAPACITY) {
        s->stats.events_dropped++;
        rc = FW_ERR_FULL;
    } else {
        s->events[s->ev_tail & EVENT_MASK] = *event;
        s->ev_tail++;
        s->stats.events_posted++;
        if (count + 1u > s->stats.events_high_water) {
            s->stats.events_high_water = count + 1u;
        }
    }
    hal_irq_restore(irq);
    return rc;
}

uint32_t sched_pending_events(const sched_t *s)
{
    FW_ASSERT(s != NULL);
    hal_irq_state_t irq = hal_irq_save();
    uint32_t count = s->ev_tail - s->ev_head;
    hal_irq_restore(irq);
    return count;
}

uint64_t sched_next_wakeup(const sched_t *s)
{
    FW_ASSERT(s != NULL);
    uint64_t next = UINT64_MAX;
    for (uint32_t i = 0; i < s->task_count; i++) {
        if (s->tasks[i].next_release_us < next) {
            next = s->tasks[i].next_release_us;
        }
    }
    return next;
}

// Takes the oldest event out under the lock; the handler then runs with interrupts enabled.
static bool pop_event(sched_t *s, sched_event_t *out)
{
    bool got = false;
    hal_irq_state_t irq = hal_irq_save();
    if (s->ev_tail != s->ev_head) {
        *out = s->events[s->ev_head & EVENT_MASK];
        s->ev_head++;
        s->stats.events_dispatched++;
        got = true;
    }
    hal_irq_restore(irq);
    return got;
}

static void dispatch_events(sched_t *s)
{
    // Only what was queued when the pass began: a handler that posts (or an interrupt storm)
    // cannot keep the tasks from running.
    uint32_t n = sched_pending_events(s);
    for (uint32_t i = 0; i < n; i++) {
        sched_event_t ev;
        if (!pop_event(s, &ev)) {
            break;
        }
        const sched_handler_t *h = &s->handlers[ev.type];
        if (h->fn != NULL) {
            h->fn(&ev, h->ctx);
        } else {
            hal_irq_state_t irq = hal_irq_save();
            s->stats.events_unhandled++;
            hal_irq_restore(irq);
        }
    }
}

static void note_period_start(sched_t *s)
{
    sched_stats_t *st = &s->stats;
    if (s->period_started) {
        uint32_t steps = fw_sat_u32(st->idle_steps - s->idle_steps_at_period_start);
        st->idle_steps_last_period = steps;
        if (steps < st->idle_steps_min_period) {
            st->idle_steps_min_period = steps;
        }
        if (steps > st->idle_steps_max_period) {
            st->idle_steps_max_period = steps;
        }
        st->periods_measured++;
    }
    s->idle_steps_at_period_start = st->idle_steps;
    s->period_started = true;
}

// Log2 buckets: a fixed, small table covers microseconds to seconds, and the bucket of a value
// is its bit length, so recording a run costs a few shifts and no division.
static uint32_t lateness_bucket(uint64_t lateness_us)
{
    uint32_t bits = 0;
    while (lateness_us != 0u) {
        bits++;
        lateness_us >>= 1;
    }
    const uint32_t last = (uint32_t)FW_CFG_SCHED_LATENESS_BUCKETS - 1u;
    return bits < last ? bits : last;
}

static void run_task(sched_t *s, uint32_t id, uint64_t now)
{
    sched_task_t *t = &s->tasks[id];
    sched_task_stats_t *ts = &t->stats;
    uint64_t period = t->cfg.period_us;

    // Releases that passed while the task could not run are skipped, never made up for: running
    // a control step twice in a row would act on one observation twice.
    uint64_t skipped = (now - t->next_release_us) / period;
    uint64_t release = t->next_release_us + skipped * period;
    ts->skipped = add_sat_u32(ts->skipped, skipped);
    ts->misses = add_sat_u32(ts->misses, skipped);

    uint64_t lateness = now - release;
    bool missed = lateness > t->cfg.tolerance_us;
    if (missed) {
        ts->late++;
    }
    if (lateness > ts->worst_lateness_us) {
        ts->worst_lateness_us = fw_sat_u32(lateness);
    }
    t->lateness[lateness_bucket(lateness)]++;
    if (id == s->period_task) {
        note_period_start(s);
    }

    t->cfg.fn(t->cfg.ctx);
    if (t->cfg.cost_cycles != 0u) {
        hal_cpu_account(t->cfg.cost_cycles);
    }

    uint64_t end = hal_time_us();
    uint64_t next = release + period;
    if (end > next) {
        ts->overruns++;
        missed = true;
    }
    if (missed) {
        ts->misses = add_sat_u32(ts->misses, 1u);
    }
    if (end - now > ts->worst_run_us) {
        ts->worst_run_us = fw_sat_u32(end - now);
    }
    ts->runs++;
    t->next_release_us = next;
}

// Runs each due task once, earliest release first. Returns true if a task is still due.
static bool run_due_tasks(sched_t *s)
{
    bool ran[FW_CFG_SCHED_MAX_TASKS] = {false};
    for (;;) {
        uint64_t now = hal_time_us();
        uint32_t pick = UINT32_MAX;
        bool still_due = false;
        for (uint32_t i = 0; i < s->task_count; i++) {
            if (s->tasks[i].next_release_us > now) {
                continue;
            }
            if (ran[i]) {
                still_due = true;
                continue;
            }
            if (pick == UINT32_MAX ||
                s->tasks[i].next_release_us < s->tasks[pick].next_release_us) {
                pick = i;
            }
        }
        if (pick == UINT32_MAX) {
            return still_due;
        }
        ran[pick] = true;
        run_task(s, pick, now);
    }
}

static bool step_fits(const sched_t *s, uint64_t now, uint64_t next)
{
    if (next == UINT64_MAX) {
        return true;
    }
    uint64_t need = (uint64_t)s->cfg.idle_step_budget_us + s->cfg.guard_us;
    return next >= now && next - now >= need;
}

void sched_step(sched_t *s)
{
    FW_ASSERT(s != NULL);
    uint64_t start = hal_time_us();
    s->stats.idle_us += start - s->idle_since_us;
    s->stats.passes++;

    s->busy = true;
    dispatch_events(s);
    bool task_due = run_due_tasks(s);
    s->idle_since_us = hal_time_us();
    s->busy = false;
    if (task_due) {
        return; // an overrun left a release due: the next pass runs it first
    }

    bool cut_short = false;
    if (s->cfg.idle != NULL) {
        uint32_t steps = 0;
        for (;;) {
            if (steps >= (uint32_t)FW_CFG_SCHED_IDLE_STEPS_PER_PASS) {
                cut_short = true;
                break;
            }
            uint64_t before = hal_time_us();
            if (!step_fits(s, before, sched_next_wakeup(s))) {
                break;
            }
            if (sched_pending_events(s) != 0u) {
                cut_short = true;
                break;
            }
            if (!s->cfg.idle(s->cfg.idle_ctx)) {
                break;
            }
            if (s->cfg.idle_step_cycles != 0u) {
                hal_cpu_account(s->cfg.idle_step_cycles);
            }
            s->stats.idle_steps++;
            s->stats.idle_work_us += hal_time_us() - before;
            steps++;
        }
    }

    // Masked from the last look at the queue to the sleep (hal_cpu.h): an event an interrupt
    // posts in between still ends the sleep at once.
    uint64_t wake = sched_next_wakeup(s);
    const hal_irq_state_t irq = hal_irq_save();
    if (!cut_short && sched_pending_events(s) == 0u && wake > hal_time_us()) {
        hal_cpu_wait_until(wake);
    }
    hal_irq_restore(irq);
}

void sched_get_stats(const sched_t *s, sched_stats_t *out)
{
    FW_ASSERT(s != NULL && out != NULL);
    // One block copy under the lock (a few hundred bytes, no loop over the task table), so the
    // event counters interrupt handlers write are consistent with each other.
    hal_irq_state_t irq = hal_irq_save();
    *out = s->stats;
    hal_irq_restore(irq);
    for (uint32_t i = 0; i < s->task_count; i++) {
        out->task[i] = s->tasks[i].stats;
    }
    out->task_count = s->task_count;
    if (!s->busy) {
        // Called between passes (by a simulator, say): the idle stretch in progress counts too.
        out->idle_us += hal_time_us() - s->idle_since_us;
    }
    if (out->periods_measured == 0u) {
        out->idle_steps_min_period = 0u;
    }
}

uint32_t sched_tolerance_us(uint32_t period_us)
{
    return (uint32_t)((uint64_t)period_us * (uint64_t)FW_CFG_SCHED_TOLERANCE_PERMILLE / 1000u);
}

int sched_get_lateness(const sched_t *s, sched_task_id_t id, sched_lateness_t *out)
{
    if (s == NULL || out == NULL || id >= s->task_count) {
        return FW_ERR_INVAL;
    }
    const sched_task_t *t = &s->tasks[id];
    memset(out, 0, sizeof *out);
    for (uint32_t b = 0; b < (uint32_t)FW_CFG_SCHED_LATENESS_BUCKETS; b++) {
        out->bucket[b] = t->lateness[b];
        out->runs = add_sat_u32(out->runs, t->lateness[b]);
    }
    out->worst_us = t->stats.worst_lateness_us;
    out->name = t->cfg.name;
    out->period_us = t->cfg.period_us;
    out->tolerance_us = t->cfg.tolerance_us;
    return FW_OK;
}

uint32_t sched_lateness_bucket_max_us(uint32_t b)
{
    if (b >= (uint32_t)FW_CFG_SCHED_LATENESS_BUCKETS - 1u) {
        return UINT32_MAX;
    }
    return (uint32_t)(((uint64_t)1u << b) - 1u);
}

uint32_t sched_lateness_percentile_us(const sched_lateness_t *l, uint32_t permille)
{
    if (l == NULL || l->runs == 0u) {
        return 0u;
    }
    if (permille > 1000u) {
        permille = 1000u;
    }
    // The rank of the run that reaches the share, counted from 1 (at least the first run).
    uint64_t rank = ((uint64_t)l->runs * permille + 999u) / 1000u;
    if (rank == 0u) {
        rank = 1u;
    }
    uint64_t seen = 0;
    for (uint32_t b = 0; b < (uint32_t)FW_CFG_SCHED_LATENESS_BUCKETS; b++) {
        seen += l->bucket[b];
        if (seen >= rank) {
            uint32_t limit = sched_lateness_bucket_max_us(b);
            return limit < l->worst_us ? limit : l->worst_us;
        }
    }
    return l->worst_us;
}
