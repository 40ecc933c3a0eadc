// SPDX-License-Identifier: MIT
// dynaqpc: unit tests of the cooperative scheduler, run on the host port in lock-step: the test
// plays the simulator (it owns virtual time, steps the firmware, delivers CAN frames).
#include "test_common.h"

#include <pthread.h>
#include <string.h>

#include "fw/fw_base.h"
#include "hal/hal_can.h"
#include "hal/hal_cpu.h"
#include "hal/hal_time.h"
#include "hal_host/hal_host.h"
#include "sched/sched.h"

#define CPU_HZ 168000000u
#define US_TO_CYCLES(us) ((uint32_t)((us) * (CPU_HZ / 1000000u)))

static sched_t s_;

static int setup(void **state)
{
    (void)state;
    hal_host_reset();
    assert_int_equal(hal_time_init(), FW_OK);
    return 0;
}

// The simulator's loop: step the firmware, then move time to the wake-up it asked for (never
// past t_end). Returns the number of passes; fails the test if time stops moving for long.
static uint32_t run_until(sched_t *s, uint64_t t_end)
{
    uint32_t passes = 0;
    uint32_t stuck = 0;
    for (;;) {
        uint64_t before = hal_time_us();
        sched_step(s);
        passes++;
        uint64_t now = hal_time_us();
        if (now >= t_end) {
            return passes;
        }
        uint64_t wake = hal_host_wait_deadline();
        if (wake > now) {
            assert_int_equal(hal_host_time_set_us(wake < t_end ? wake : t_end), FW_OK);
        }
        stuck = hal_time_us() == before ? stuck + 1u : 0u;
        assert_true(stuck < 10000u);
    }
}

// ---- Tasks run at period and phase --------------------------------------------------------------

#define MAX_STARTS 512
typedef struct recorder {
    uint64_t starts[MAX_STARTS];
    uint32_t n;
    uint64_t advance_on_run;   // run number that advances time itself
    uint64_t advance_us;
    char tag;
} recorder_t;

static char order_[64];
static uint32_t order_n_;

static void record_task(void *ctx)
{
    recorder_t *r = ctx;
    if (r->n < MAX_STARTS) {
        r->starts[r->n] = hal_time_us();
    }
    r->n++;
    if (order_n_ < sizeof order_ - 1u) {
        order_[order_n_++] = r->tag;
    }
    if (r->advance_us != 0u && r->n == r->advance_on_run) {
        assert_int_equal(hal_host_time_advance_us(r->advance_us), FW_OK);
    }
}

static void test_period_and_phase_exact(void **state)
{
    (void)state;
    static recorder_t a, b;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    sched_config_t cfg = {0};
    assert_int_equal(sched_init(&s_, &cfg), FW_OK);
    sched_task_config_t ta = {"a", record_task, &a, 10000u, 0u, 0u, US_TO_CYCLES(300)};
    sched_task_config_t tb = {"b", record_task, &b, 25000u, 3000u, 0u, US_TO_CYCLES(1000)};
    assert_int_equal(sched_add_task(&s_, &ta), 0);
    assert_int_equal(sched_add_task(&s_, &tb), 1);

    (void)run_until(&s_, 2000000u);
    assert_int_equal(a.n, 201); // releases 0, 10 ms, ..., 2 s
    assert_int_equal(b.n, 80);  // 3 ms, 28 ms, ..., 1978 ms
    for (uint32_t k = 0; k < a.n; k++) {
        // a's release at 3 ms + 25 k ms never coincides with b's... except where b runs first:
        // b's releases are at 3 ms mod 25 ms, a's at 0 mod 10 ms: they never collide.
        assert_int_equal(a.starts[k], (uint64_t)k * 10000u);
    }
    for (uint32_t k = 0; k < b.n; k++) {
        assert_int_equal(b.starts[k], 3000u + (uint64_t)k * 25000u);
    }
    sched_stats_t st;
    sched_get_stats(&s_, &st);
    assert_int_equal(st.task_count, 2);
    assert_int_equal(st.task[0].runs, 201);
    assert_int_equal(st.task[1].runs, 80);
    assert_int_equal(st.task[0].misses, 0);
    assert_int_equal(st.task[1].misses, 0);
    assert_int_equal(st.task[0].worst_lateness_us, 0);
    assert_int_equal(st.task[0].worst_run_us, 300);
    assert_int_equal(st.task[1].worst_run_us, 1000);
    assert_int_equal(sched_next_wakeup(&s_), 2003000u); // b's next release
}

static void test_simultaneous_releases_run_in_order(void **state)
{
    (void)state;
    static recorder_t a, b;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    a.tag = 'a';
    b.tag = 'b';
    order_n_ = 0;
    memset(order_, 0, sizeof order_);
    sched_config_t cfg = {0};
    assert_int_equal(sched_init(&s_, &cfg), FW_OK);
    // Both released at 0 and 20 ms; a (id 0) wins ties, and b, which a delays by 2 ms, is late
    // but within its tolerance.
    sched_task_config_t ta = {"a", record_task, &a, 20000u, 0u, 0u, US_TO_CYCLES(2000)};
    sched_task_config_t tb = {"b", record_task, &b, 10000u, 0u, 2000u, US_TO_CYCLES(100)};
    assert_int_equal(sched_add_task(&s_, &ta), 0);
    assert_int_equal(sched_add_task(&s_, &tb), 1);
    (void)run_until(&s_, 30000u);
    assert_string_equal(order_, "abbabb");
    assert_int_equal(b.starts[0], 2000u);
    assert_int_equal(b.starts[1], 10000u);
    sched_stats_t st;
    sched_get_stats(&s_, &st);
    assert_int_equal(st.task[1].misses, 0);
    assert_int_equal(st.task[1].worst_lateness_us, 2000);
}

// ---- Idle work that never ends misses no deadline -----------------------------------------------

static uint64_t idle_calls_;

static bool idle_forever(void *ctx)
{
    (void)ctx;
    idle_calls_++;
    return true;
}

static void idle_forever_case(uint32_t step_us, uint32_t guard_us)
{
    static recorder_t control, telemetry;
    memset(&control, 0, sizeof control);
    memset(&telemetry, 0, sizeof telemetry);
    hal_host_reset();
    assert_int_equal(hal_time_init(), FW_OK);
    idle_calls_ = 0;
    sched_config_t cfg = {idle_forever, NULL, step_us, guard_us, US_TO_CYCLES(step_us)};
    assert_int_equal(sched_init(&s_, &cfg), FW_OK);
    // The paper's 0.192 s control period; a 48 ms telemetry task between its releases.
    sched_task_config_t tc = {"control", record_task, &control, 192000u, 0u, 0u,
                              US_TO_CYCLES(1000)};
    sched_task_config_t tt = {"telemetry", record_task, &telemetry, 48000u, 24000u, 0u,
                              US_TO_CYCLES(100)};
    assert_int_equal(sched_add_task(&s_, &tc), 0);
    assert_int_equal(sched_add_task(&s_, &tt), 1);

    const uint32_t periods = 50;
    (void)run_until(&s_, (uint64_t)periods * 192000u + 1u); // + 1: the last release runs
    sched_stats_t st;
    sched_get_stats(&s_, &st);
    assert_int_equal(st.task[0].runs, periods + 1u);
    assert_int_equal(st.task[1].runs, periods * 4u);
    for (uint32_t i = 0; i < 2; i++) {
        assert_int_equal(st.task[i].misses, 0);
        assert_int_equal(st.task[i].worst_lateness_us, 0);
    }
    for (uint32_t k = 0; k <= periods; k++) {
        assert_int_equal(control.starts[k], (uint64_t)k * 192000u);
    }
    assert_int_equal(st.idle_steps, idle_calls_);
    assert_true(st.idle_steps > 0u);
    assert_int_equal(st.periods_measured, periods);
    assert_int_equal(st.idle_steps_min_period, st.idle_steps_max_period);
    assert_int_equal(st.idle_steps_last_period, st.idle_steps_min_period);
    // Every idle step took exactly its accounted time.
    assert_int_equal(st.idle_work_us, st.idle_steps * step_us);
    // Time is tasks + idle: nothing unaccounted.
    uint64_t busy = (uint64_t)st.task[0].runs * 1000u + (uint64_t)st.task[1].runs * 100u;
    assert_int_equal(st.idle_us + busy, hal_time_us());
}

static void test_idle_forever_misses_nothing(void **state)
{
    (void)state;
    idle_forever_case(100u, 0u);
    sched_stats_t st;
    sched_get_stats(&s_, &st);
    // One period: 192 ms - 1 ms control - 4 x 0.1 ms telemetry, all on a 100 us grid.
    assert_int_equal(st.idle_steps_last_period, (192000u - 1000u - 400u) / 100u);

    // Steps that do not divide the gaps, a guard, and a step longer than some gaps.
    idle_forever_case(130u, 0u);
    idle_forever_case(77u, 50u);
    idle_forever_case(30000u, 0u);
    sched_get_stats(&s_, &st);
    // 30 ms steps: of the gaps (23, 47.9, 47.9, 47.9, 23.9 ms) only the 47.9 ms ones fit one.
    assert_int_equal(st.idle_steps_last_period, 3u);
}

// ---- Overruns -----------------------------------------------------------------------------------

static void test_overrun_by_cost_is_missed_and_not_made_up(void **state)
{
    (void)state;
    static recorder_t a;
    memset(&a, 0, sizeof a);
    sched_config_t cfg = {0};
    assert_int_equal(sched_init(&s_, &cfg), FW_OK);
    // Each run takes 25 ms of a 10 ms period.
    sched_task_config_t ta = {"a", record_task, &a, 10000u, 0u, 1000u, US_TO_CYCLES(25000)};
    assert_int_equal(sched_add_task(&s_, &ta), 0);
    (void)run_until(&s_, 100001u);
    // Runs start at 0, 25, 50, 75, 100 ms, each for the latest release passed (0, 20, 50, 70,
    // 100 ms); the releases in between (10, 30, 40, 60, 80, 90 ms) are skipped, never run.
    assert_int_equal(a.n, 5);
    for (uint32_t k = 0; k < a.n; k++) {
        assert_int_equal(a.starts[k], (uint64_t)k * 25000u);
    }
    sched_stats_t st;
    sched_get_stats(&s_, &st);
    assert_int_equal(st.task[0].runs, 5);
    // Releases up to the last start (100 ms): 11. All of them are missed: each run overruns,
    // and 6 were never run.
    assert_int_equal(st.task[0].skipped, 6);
    assert_int_equal(st.task[0].runs + st.task[0].skipped, 11);
    assert_int_equal(st.task[0].misses, 11);
    assert_int_equal(st.task[0].overruns, 5);
    assert_int_equal(st.task[0].late, 2); // 5 ms late (releases 20, 70 ms); 1 ms allowed
    assert_int_equal(st.task[0].worst_lateness_us, 5000);
    assert_int_equal(st.task[0].worst_run_us, 25000);
}

static void test_overrun_by_time_jump(void **state)
{
    (void)state;
    static recorder_t a, b;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    a.tag = 'a';
    b.tag = 'b';
    order_n_ = 0;
    memset(order_, 0, sizeof order_);
    // a's third run (release 20 ms) takes 25 ms: it ends at 45 ms.
    a.advance_on_run = 3;
    a.advance_us = 25000u;
    sched_config_t cfg = {0};
    assert_int_equal(sched_init(&s_, &cfg), FW_OK);
    sched_task_config_t ta = {"a", record_task, &a, 10000u, 0u, 0u, 0u};
    sched_task_config_t tb = {"b", record_task, &b, 5000u, 2500u, 0u, 0u};
    assert_int_equal(sched_add_task(&s_, &ta), 0);
    assert_int_equal(sched_add_task(&s_, &tb), 1);
    (void)run_until(&s_, 70000u);

    sched_stats_t st;
    sched_get_stats(&s_, &st);
    // a: release 20 overran, 30 skipped, 40 ran late at 45 ms; then 50, 60, 70 on time.
    assert_int_equal(a.n, 7);
    const uint64_t a_expect[] = {0, 10000, 20000, 45000, 50000, 60000, 70000};
    for (uint32_t k = 0; k < 7; k++) {
        assert_int_equal(a.starts[k], a_expect[k]);
    }
    assert_int_equal(st.task[0].overruns, 1);
    assert_int_equal(st.task[0].skipped, 1);
    assert_int_equal(st.task[0].misses, 3);
    assert_int_equal(st.task[0].worst_lateness_us, 5000);
    // b: releases 22.5, 27.5, 32.5, 37.5 skipped, 42.5 ran at 45 ms (before a: earlier release).
    assert_int_equal(st.task[1].skipped, 4);
    assert_int_equal(st.task[1].misses, 5);
    assert_int_equal(st.task[1].runs, 14 - 4);
    assert_int_equal(b.starts[4], 45000u);
    assert_int_equal(b.starts[5], 47500u);
    // Order around the jump: a(0) b(2.5) b(7.5) a(10) b(12.5) b(17.5) a(20) b(42.5@45) a(40@45).
    assert_memory_equal(order_, "abbabbaba", 9);
}

// ---- Deadline tolerance and the lateness histogram -----------------------------------------------

// A task that takes a scripted time per run (virtual time: it advances the clock itself), to
// delay a task released at the same moment by exactly that much.
typedef struct blocker {
    const uint64_t *run_us;
    uint32_t n_runs;
    uint32_t n;
} blocker_t;

static void blocker_task(void *ctx)
{
    blocker_t *b = ctx;
    if (b->n < b->n_runs && b->run_us[b->n] != 0u) {
        assert_int_equal(hal_host_time_advance_us(b->run_us[b->n]), FW_OK);
    }
    b->n++;
}

// Starts a scheduler with the blocker (id 0, tolerance blocker_tol_us) and a recorded control task
// (id 1, tolerance tol_us), both released every period_us: control run k starts runs[k] late.
static void start_blocked_control_(blocker_t *blk, recorder_t *ctl, const uint64_t *runs, uint32_t n,
                                   uint32_t period_us, uint32_t blocker_tol_us, uint32_t tol_us)
{
    memset(blk, 0, sizeof *blk);
    memset(ctl, 0, sizeof *ctl);
    blk->run_us = runs;
    blk->n_runs = n;
    sched_config_t cfg = {0};
    assert_int_equal(sched_init(&s_, &cfg), FW_OK);
    sched_task_config_t tb = {"blocker", blocker_task, blk, period_us, 0u, blocker_tol_us, 0u};
    sched_task_config_t tc = {"control", record_task, ctl, period_us, 0u, tol_us, 0u};
    assert_int_equal(sched_add_task(&s_, &tb), 0);
    assert_int_equal(sched_add_task(&s_, &tc), 1);
}

static void test_lateness_against_tolerance(void **state)
{
    (void)state;
    // Both released every 20 ms; the blocker (id 0) wins the tie, so the control task starts as
    // late as the blocker's run lasts: 0, 500, 1000 (exactly the tolerance), 1001, 5000, 0 us.
    static const uint64_t runs[] = {0u, 500u, 1000u, 1001u, 5000u, 0u};
    static blocker_t blk;
    static recorder_t ctl;
    start_blocked_control_(&blk, &ctl, runs, 6u, 20000u, 20000u, 1000u);
    (void)run_until(&s_, 5u * 20000u + 1u);

    assert_int_equal(ctl.n, 6);
    for (uint32_t k = 0; k < 6; k++) {
        assert_int_equal(ctl.starts[k], (uint64_t)k * 20000u + runs[k]);
    }
    sched_stats_t st;
    sched_get_stats(&s_, &st);
    // Within the tolerance (0, 500, 1000 us late) is on time; beyond it (1001, 5000) a miss.
    assert_int_equal(st.task[1].runs, 6);
    assert_int_equal(st.task[1].misses, 2);
    assert_int_equal(st.task[1].late, 2);
    assert_int_equal(st.task[1].skipped, 0);
    assert_int_equal(st.task[1].overruns, 0);
    assert_int_equal(st.task[1].worst_lateness_us, 5000);
    // The blocker itself always started on time.
    assert_int_equal(st.task[0].misses, 0);
    assert_int_equal(st.task[0].late, 0);

    sched_lateness_t l;
    assert_int_equal(sched_get_lateness(&s_, 1, &l), FW_OK);
    assert_int_equal(l.runs, 6);
    assert_int_equal(l.worst_us, 5000);
    assert_string_equal(l.name, "control");
    assert_int_equal(l.period_us, 20000);
    assert_int_equal(l.tolerance_us, 1000);
    // 0, 0 -> bucket 0; 500 -> [256, 511] = 9; 1000, 1001 -> [512, 1023] = 10; 5000 -> 13.
    for (uint32_t b = 0; b < FW_CFG_SCHED_LATENESS_BUCKETS; b++) {
        uint32_t expect = b == 0u ? 2u : b == 9u ? 1u : b == 10u ? 2u : b == 13u ? 1u : 0u;
        assert_int_equal(l.bucket[b], expect);
    }
    // Percentiles are bucket limits: half the runs started <= 511 us late (the third of six),
    // five of six <= 1023 us, all of them at the worst, 5000 us (not the bucket's 8191).
    assert_int_equal(sched_lateness_percentile_us(&l, 0u), 0u);
    assert_int_equal(sched_lateness_percentile_us(&l, 333u), 0u);
    assert_int_equal(sched_lateness_percentile_us(&l, 500u), 511u);
    assert_int_equal(sched_lateness_percentile_us(&l, 833u), 1023u);
    assert_int_equal(sched_lateness_percentile_us(&l, 900u), 5000u);
    assert_int_equal(sched_lateness_percentile_us(&l, 1000u), 5000u);
    assert_int_equal(sched_lateness_percentile_us(&l, 5000u), 5000u);

    assert_int_equal(sched_get_lateness(&s_, 2, &l), FW_ERR_INVAL);
    assert_int_equal(sched_get_lateness(NULL, 0, &l), FW_ERR_INVAL);
    assert_int_equal(sched_get_lateness(&s_, 0, NULL), FW_ERR_INVAL);
}

static void test_zero_tolerance_counts_any_lateness(void **state)
{
    (void)state;
    // The same delays with tolerance 0: every late start is a miss.
    static const uint64_t runs[] = {0u, 1u, 0u, 3u};
    static blocker_t blk;
    static recorder_t ctl;
    start_blocked_control_(&blk, &ctl, runs, 4u, 10000u, 0u, 0u);
    (void)run_until(&s_, 3u * 10000u + 1u);
    sched_stats_t st;
    sched_get_stats(&s_, &st);
    assert_int_equal(st.task[1].runs, 4);
    assert_int_equal(st.task[1].misses, 2);
    assert_int_equal(st.task[1].late, 2);
    sched_lateness_t l;
    assert_int_equal(sched_get_lateness(&s_, 1, &l), FW_OK);
    assert_int_equal(l.bucket[0], 2);
    assert_int_equal(l.bucket[1], 1); // 1 us
    assert_int_equal(l.bucket[2], 1); // 2 .. 3 us
    assert_int_equal(sched_lateness_percentile_us(&l, 500u), 0u);
    assert_int_equal(sched_lateness_percentile_us(&l, 750u), 1u);
    assert_int_equal(sched_lateness_percentile_us(&l, 990u), 3u);
}

static void test_lateness_buckets_and_tolerance_rule(void **state)
{
    (void)state;
    assert_int_equal(sched_lateness_bucket_max_us(0u), 0u);
    assert_int_equal(sched_lateness_bucket_max_us(1u), 1u);
    assert_int_equal(sched_lateness_bucket_max_us(2u), 3u);
    assert_int_equal(sched_lateness_bucket_max_us(10u), 1023u);
    assert_int_equal(sched_lateness_bucket_max_us(FW_CFG_SCHED_LATENESS_BUCKETS - 2u),
                     (1u << (FW_CFG_SCHED_LATENESS_BUCKETS - 2u)) - 1u);
    assert_int_equal(sched_lateness_bucket_max_us(FW_CFG_SCHED_LATENESS_BUCKETS - 1u), UINT32_MAX);
    assert_int_equal(sched_lateness_bucket_max_us(1000u), UINT32_MAX);
    assert_int_equal(sched_lateness_percentile_us(NULL, 500u), 0u);
    sched_lateness_t none;
    memset(&none, 0, sizeof none);
    assert_int_equal(sched_lateness_percentile_us(&none, 990u), 0u);

    // The rule: a documented share of the period; 10 % by default (the paper's 0.192 s period:
    // 19.2 ms); no overflow at the largest period.
    assert_int_equal(sched_tolerance_us(1000u), FW_CFG_SCHED_TOLERANCE_PERMILLE);
    assert_int_equal(sched_tolerance_us(UINT32_MAX),
                     (uint32_t)((uint64_t)UINT32_MAX * FW_CFG_SCHED_TOLERANCE_PERMILLE / 1000u));
#if FW_CFG_SCHED_TOLERANCE_PERMILLE == 100
    assert_int_equal(sched_tolerance_us(192000u), 19200u);
#endif

    // A run later than the whole histogram lands in the last bucket; its percentile is the worst.
    static const uint64_t runs[] = {(uint64_t)1u << (FW_CFG_SCHED_LATENESS_BUCKETS + 1u)};
    static blocker_t blk;
    static recorder_t ctl;
    const uint32_t period = (uint32_t)runs[0] * 2u;
    start_blocked_control_(&blk, &ctl, runs, 1u, period, 0u, sched_tolerance_us(period));
    (void)run_until(&s_, runs[0] + 1u);
    sched_lateness_t l;
    assert_int_equal(sched_get_lateness(&s_, 1, &l), FW_OK);
    assert_int_equal(l.runs, 1);
    assert_int_equal(l.bucket[FW_CFG_SCHED_LATENESS_BUCKETS - 1u], 1);
    assert_int_equal(sched_lateness_percentile_us(&l, 500u), (uint32_t)runs[0]);
    sched_stats_t st;
    sched_get_stats(&s_, &st);
#if FW_CFG_SCHED_TOLERANCE_PERMILLE < 500
    assert_int_equal(st.task[1].misses, 1); // half a period late: beyond the tolerance
#endif
}

static void test_task_added_late_keeps_grid(void **state)
{
    (void)state;
    static recorder_t a;
    memset(&a, 0, sizeof a);
    sched_config_t cfg = {0};
    assert_int_equal(sched_init(&s_, &cfg), FW_OK);
    sched_step(&s_); // the loop is running
    assert_int_equal(hal_host_time_set_us(25000u), FW_OK);
    sched_task_config_t ta = {"a", record_task, &a, 10000u, 2000u, 0u, 0u};
    assert_int_equal(sched_add_task(&s_, &ta), 0);
    assert_int_equal(sched_next_wakeup(&s_), 32000u);
    (void)run_until(&s_, 52000u);
    assert_int_equal(a.n, 3);
    assert_int_equal(a.starts[0], 32000u);
    sched_stats_t st;
    sched_get_stats(&s_, &st);
    assert_int_equal(st.task[0].misses, 0);
}

// ---- Idle hook that runs out of work ------------------------------------------------------------

static uint32_t work_left_;

static void refill_task(void *ctx)
{
    (void)ctx;
    work_left_ = 7;
}

static bool idle_some(void *ctx)
{
    (void)ctx;
    if (work_left_ == 0u) {
        return false;
    }
    work_left_--;
    return true;
}

static void test_idle_stops_and_waits_for_deadline(void **state)
{
    (void)state;
    sched_config_t cfg = {idle_some, NULL, 200u, 10u, US_TO_CYCLES(200)};
    assert_int_equal(sched_init(&s_, &cfg), FW_OK);
    sched_task_config_t tc = {"control", refill_task, NULL, 192000u, 0u, 0u, US_TO_CYCLES(500)};
    assert_int_equal(sched_add_task(&s_, &tc), 0);

    sched_step(&s_);
    // Task 0.5 ms, then 7 steps of 0.2 ms, then the hook said "no work": wait for 192 ms.
    assert_int_equal(hal_time_us(), 500u + 7u * 200u);
    assert_int_equal(hal_host_wait_deadline(), 192000u);
    sched_stats_t st;
    sched_get_stats(&s_, &st);
    assert_int_equal(st.idle_steps, 7);
    assert_int_equal(st.periods_measured, 0);
    assert_int_equal(st.idle_steps_last_period, 0);

    (void)run_until(&s_, 192000u * 10u);
    sched_get_stats(&s_, &st);
    assert_int_equal(st.idle_steps, 7u * 11u); // the pass at the end does its idle work too
    assert_int_equal(st.periods_measured, 10);
    assert_int_equal(st.idle_steps_last_period, 7);
    assert_int_equal(st.idle_steps_min_period, 7);
    assert_int_equal(st.idle_steps_max_period, 7);
    assert_int_equal(st.task[0].misses, 0);
    // Idle time covers the steps and the waits.
    assert_int_equal(st.idle_work_us, 7u * 11u * 200u);
    assert_int_equal(st.idle_us, hal_time_us() - 11u * 500u);
}

static void test_idle_pass_is_bounded_when_time_stands_still(void **state)
{
    (void)state;
    // idle_step_cycles 0: in lock-step the steps take no time, so only the per-pass limit ends
    // the pass; it then returns without asking to wait.
    sched_config_t cfg = {idle_forever, NULL, 100u, 0u, 0u};
    idle_calls_ = 0;
    assert_int_equal(sched_init(&s_, &cfg), FW_OK);
    sched_step(&s_);
    assert_int_equal(idle_calls_, FW_CFG_SCHED_IDLE_STEPS_PER_PASS);
    assert_int_equal(hal_time_us(), 0u);
    assert_int_equal(hal_host_wait_deadline(), 0u);
    // With no task, a hook with no work makes the loop wait for ever (until an interrupt).
    sched_config_t cfg2 = {idle_some, NULL, 100u, 0u, 0u};
    work_left_ = 0;
    assert_int_equal(sched_init(&s_, &cfg2), FW_OK);
    sched_step(&s_);
    assert_int_equal(hal_host_wait_deadline(), UINT64_MAX);
}

// ---- Events -------------------------------------------------------------------------------------

#define EV_WORD 3u
#define EV_CAN 5u

static uint32_t seen_words_[FW_CFG_SCHED_EVENT_CAPACITY * 4];
static uint32_t seen_n_;

static void on_word(const sched_event_t *ev, void *ctx)
{
    assert_ptr_equal(ctx, &seen_n_);
    assert_int_equal(ev->type, EV_WORD);
    if (seen_n_ < sizeof seen_words_ / sizeof seen_words_[0]) {
        seen_words_[seen_n_] = ev->u.word;
    }
    seen_n_++;
}

static uint32_t post_fill(uint32_t first)
{
    uint32_t accepted = 0;
    for (uint32_t i = 0; i < FW_CFG_SCHED_EVENT_CAPACITY; i++) {
        sched_event_t ev = {.type = EV_WORD};
        ev.u.word = first + i;
        assert_int_equal(sched_post(&s_, &ev), FW_OK);
        accepted++;
    }
    sched_event_t extra = {.type = EV_WORD};
    extra.u.word = 0xDEADu;
    assert_int_equal(sched_post(&s_, &extra), FW_ERR_FULL);
    return accepted;
}

static void posting_task(void *ctx)
{
    (void)ctx;
    (void)post_fill(1000u);
}

static bool posting_idle(void *ctx)
{
    bool *done = ctx;
    if (*done) {
        return false;
    }
    *done = true;
    (void)post_fill(2000u);
    return true;
}

static void test_events_fill_to_capacity_in_order(void **state)
{
    (void)state;
    static bool idle_done;
    idle_done = false;
    seen_n_ = 0;
    sched_config_t cfg = {posting_idle, &idle_done, 100u, 0u, US_TO_CYCLES(100)};
    assert_int_equal(sched_init(&s_, &cfg), FW_OK);
    assert_int_equal(sched_on_event(&s_, EV_WORD, on_word, &seen_n_), FW_OK);
    sched_task_config_t tp = {"poster", posting_task, NULL, 50000u, 0u, 0u, 0u};
    assert_int_equal(sched_add_task(&s_, &tp), 0);

    // Pass 1: the task fills the queue (one refused); idle is skipped because events wait.
    sched_step(&s_);
    assert_int_equal(sched_pending_events(&s_), FW_CFG_SCHED_EVENT_CAPACITY);
    assert_int_equal(idle_done, false);
    // Pass 2: all dispatched, in order; then idle fills it again.
    sched_step(&s_);
    assert_int_equal(seen_n_, FW_CFG_SCHED_EVENT_CAPACITY);
    assert_true(idle_done);
    assert_int_equal(sched_pending_events(&s_), FW_CFG_SCHED_EVENT_CAPACITY);
    sched_step(&s_);
    assert_int_equal(seen_n_, 2u * FW_CFG_SCHED_EVENT_CAPACITY);
    for (uint32_t i = 0; i < FW_CFG_SCHED_EVENT_CAPACITY; i++) {
        assert_int_equal(seen_words_[i], 1000u + i);
        assert_int_equal(seen_words_[FW_CFG_SCHED_EVENT_CAPACITY + i], 2000u + i);
    }
    sched_stats_t st;
    sched_get_stats(&s_, &st);
    assert_int_equal(st.events_posted, 2u * FW_CFG_SCHED_EVENT_CAPACITY);
    assert_int_equal(st.events_dropped, 2);
    assert_int_equal(st.events_dispatched, 2u * FW_CFG_SCHED_EVENT_CAPACITY);
    assert_int_equal(st.events_unhandled, 0);
    assert_int_equal(st.events_high_water, FW_CFG_SCHED_EVENT_CAPACITY);
}

static void test_event_errors_and_unhandled(void **state)
{
    (void)state;
    sched_config_t cfg = {0};
    assert_int_equal(sched_init(&s_, &cfg), FW_OK);
    sched_event_t bad = {.type = FW_CFG_SCHED_EVENT_TYPES};
    assert_int_equal(sched_post(&s_, &bad), FW_ERR_INVAL);
    assert_int_equal(sched_post(&s_, NULL), FW_ERR_INVAL);
    assert_int_equal(sched_on_event(&s_, FW_CFG_SCHED_EVENT_TYPES, on_word, NULL), FW_ERR_INVAL);
    sched_event_t ev = {.type = 1};
    assert_int_equal(sched_post(&s_, &ev), FW_OK);
    sched_step(&s_);
    sched_stats_t st;
    sched_get_stats(&s_, &st);
    assert_int_equal(st.events_posted, 1);
    assert_int_equal(st.events_dispatched, 1);
    assert_int_equal(st.events_unhandled, 1);
    // Task table errors.
    sched_task_config_t t = {"x", refill_task, NULL, 0u, 0u, 0u, 0u};
    assert_int_equal(sched_add_task(&s_, &t), FW_ERR_INVAL);
    t.period_us = 10u;
    t.phase_us = 10u;
    assert_int_equal(sched_add_task(&s_, &t), FW_ERR_INVAL);
    t.phase_us = 0u;
    t.fn = NULL;
    assert_int_equal(sched_add_task(&s_, &t), FW_ERR_INVAL);
    t.fn = refill_task;
    for (int i = 0; i < FW_CFG_SCHED_MAX_TASKS; i++) {
        assert_int_equal(sched_add_task(&s_, &t), i);
    }
    assert_int_equal(sched_add_task(&s_, &t), FW_ERR_NOMEM);
    assert_int_equal(sched_set_period_task(&s_, FW_CFG_SCHED_MAX_TASKS), FW_ERR_INVAL);
    assert_int_equal(sched_init(NULL, &cfg), FW_ERR_INVAL);
}

// CAN frames through the host port's "interrupt": the rx handler posts them.
static uint32_t can_seen_;
static uint32_t can_last_seq_;
static bool can_in_order_ = true;

static void can_rx_to_sched(const hal_can_frame_t *frame, void *ctx)
{
    sched_event_t ev = {.type = EV_CAN};
    ev.u.can = *frame;
    (void)sched_post(ctx, &ev);
}

static void on_can(const sched_event_t *ev, void *ctx)
{
    (void)ctx;
    uint32_t seq = (uint32_t)ev->u.can.data[0] | (uint32_t)ev->u.can.data[1] << 8 |
                   (uint32_t)ev->u.can.data[2] << 16 | (uint32_t)ev->u.can.data[3] << 24;
    if (can_seen_ > 0u && seq <= can_last_seq_) {
        can_in_order_ = false;
    }
    can_last_seq_ = seq;
    can_seen_++;
}

static hal_can_frame_t seq_frame(uint32_t seq)
{
    hal_can_frame_t f = {.id = 0x123u, .dlc = 4u, .flags = 0u};
    f.data[0] = (uint8_t)seq;
    f.data[1] = (uint8_t)(seq >> 8);
    f.data[2] = (uint8_t)(seq >> 16);
    f.data[3] = (uint8_t)(seq >> 24);
    return f;
}

static void test_can_isr_posts_never_lost(void **state)
{
    (void)state;
    can_seen_ = 0;
    can_in_order_ = true;
    sched_config_t cfg = {0};
    assert_int_equal(sched_init(&s_, &cfg), FW_OK);
    assert_int_equal(sched_on_event(&s_, EV_CAN, on_can, NULL), FW_OK);
    assert_int_equal(hal_can_init(500000u, NULL, 0u, can_rx_to_sched, &s_), FW_OK);
    for (uint32_t i = 0; i <= FW_CFG_SCHED_EVENT_CAPACITY; i++) {
        hal_can_frame_t f = seq_frame(i);
        assert_int_equal(hal_host_can_deliver(&f), FW_OK);
    }
    sched_step(&s_);
    assert_int_equal(can_seen_, FW_CFG_SCHED_EVENT_CAPACITY);
    assert_true(can_in_order_);
    assert_int_equal(can_last_seq_, FW_CFG_SCHED_EVENT_CAPACITY - 1u);
    sched_stats_t st;
    sched_get_stats(&s_, &st);
    assert_int_equal(st.events_dropped, 1);
}

// A receiver thread posts while the main loop runs: every frame is either dispatched or
// counted as dropped, and the dispatched ones come in order.
static uint32_t isr_failures_;

static void *isr_thread(void *arg)
{
    uint32_t n = *(const uint32_t *)arg;
    for (uint32_t i = 0; i < n; i++) {
        hal_can_frame_t f = seq_frame(i);
        if (hal_host_can_deliver(&f) != FW_OK) {
            isr_failures_++; // cmocka's asserts belong to the main thread
        }
    }
    return NULL;
}

static void test_concurrent_isr_thread(void **state)
{
    (void)state;
    can_seen_ = 0;
    can_in_order_ = true;
    sched_config_t cfg = {0};
    assert_int_equal(sched_init(&s_, &cfg), FW_OK);
    assert_int_equal(sched_on_event(&s_, EV_CAN, on_can, NULL), FW_OK);
    assert_int_equal(hal_can_init(500000u, NULL, 0u, can_rx_to_sched, &s_), FW_OK);
    static uint32_t n = 20000;
    pthread_t th;
    assert_int_equal(pthread_create(&th, NULL, isr_thread, &n), 0);
    hal_can_stats_t cs;
    do {
        sched_step(&s_);
        hal_can_get_stats(&cs);
    } while (cs.rx_frames < n);
    assert_int_equal(pthread_join(th, NULL), 0);
    assert_int_equal(isr_failures_, 0);
    sched_step(&s_);
    sched_stats_t st;
    sched_get_stats(&s_, &st);
    assert_int_equal(st.events_posted + st.events_dropped, n);
    assert_int_equal(st.events_dispatched, st.events_posted);
    assert_int_equal(can_seen_, st.events_posted);
    assert_true(can_in_order_);
}

// The sleep handoff (hal_cpu.h): the scheduler goes to sleep with interrupts masked from its last
// look at the event queue, so an event posted in between cannot wait for the next tick.
static void test_sleeps_with_interrupts_masked(void **state)
{
    (void)state;
    sched_config_t cfg = {0};
    assert_int_equal(sched_init(&s_, &cfg), FW_OK);
    (void)hal_host_time_set_us(10u);
    sched_step(&s_);  // nothing to do: it waits
    assert_true(hal_host_last_wait_masked());
    // And the mask is given back: an "interrupt" can post again.
    const hal_irq_state_t irq = hal_irq_save();
    hal_irq_restore(irq);
    assert_int_equal(irq, 0);
}

// Real-time mode: the same loop sleeps in hal_cpu_wait_until() and a receiver thread's frames
// wake it. Asserts what happened, not how fast.
static void test_realtime_loop_wakes_on_events(void **state)
{
    (void)state;
    static recorder_t a;
    memset(&a, 0, sizeof a);
    can_seen_ = 0;
    can_in_order_ = true;
    isr_failures_ = 0;
    hal_host_time_set_mode(HAL_HOST_CLOCK_REALTIME);
    assert_int_equal(hal_host_time_set_speed(100.0), FW_OK); // 10 ms of firmware time = 0.1 ms
    sched_config_t cfg = {0};
    assert_int_equal(sched_init(&s_, &cfg), FW_OK);
    assert_int_equal(sched_on_event(&s_, EV_CAN, on_can, NULL), FW_OK);
    assert_int_equal(hal_can_init(500000u, NULL, 0u, can_rx_to_sched, &s_), FW_OK);
    // A long period: the loop sleeps most of the time, so only the wake-ups get frames seen.
    sched_task_config_t ta = {"a", record_task, &a, 1000000u, 0u, 1000000u, 0u};
    assert_int_equal(sched_add_task(&s_, &ta), 0);
    static uint32_t n = 200;
    pthread_t th;
    assert_int_equal(pthread_create(&th, NULL, isr_thread, &n), 0);
    sched_stats_t st;
    uint32_t passes = 0;
    do {
        sched_step(&s_);
        sched_get_stats(&s_, &st);
        passes++;
    } while (st.events_dispatched + st.events_dropped < n && passes < 1000000u);
    assert_int_equal(pthread_join(th, NULL), 0);
    assert_int_equal(isr_failures_, 0);
    assert_int_equal(st.events_posted + st.events_dropped, n);
    assert_int_equal(can_seen_, st.events_posted);
    assert_true(can_in_order_);
    assert_true(a.n >= 1u);
    hal_host_time_set_mode(HAL_HOST_CLOCK_LOCKSTEP);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_period_and_phase_exact, setup),
        cmocka_unit_test_setup(test_simultaneous_releases_run_in_order, setup),
        cmocka_unit_test_setup(test_idle_forever_misses_nothing, setup),
        cmocka_unit_test_setup(test_overrun_by_cost_is_missed_and_not_made_up, setup),
        cmocka_unit_test_setup(test_overrun_by_time_jump, setup),
        cmocka_unit_test_setup(test_lateness_against_tolerance, setup),
        cmocka_unit_test_setup(test_zero_tolerance_counts_any_lateness, setup),
        cmocka_unit_test_setup(test_lateness_buckets_and_tolerance_rule, setup),
        cmocka_unit_test_setup(test_task_added_late_keeps_grid, setup),
        cmocka_unit_test_setup(test_idle_stops_and_waits_for_deadline, setup),
        cmocka_unit_test_setup(test_idle_pass_is_bounded_when_time_stands_still, setup),
        cmocka_unit_test_setup(test_events_fill_to_capacity_in_order, setup),
        cmocka_unit_test_setup(test_event_errors_and_unhandled, setup),
        cmocka_unit_test_setup(test_can_isr_posts_never_lost, setup),
        cmocka_unit_test_setup(test_concurrent_isr_thread, setup),
        cmocka_unit_test_setup(test_realtime_loop_wakes_on_events, setup),
        cmocka_unit_test_setup(test_sleeps_with_interrupts_masked, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
