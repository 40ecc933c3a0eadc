// SPDX-License-Identifier: MIT
// dynaqpc qemu-agent: the agent learning on the Cortex-M4 under QEMU, with its planning
// instrumented; the same program built for the host prints the same digest (host = MCU).
//
// The robot-shaped gridworld of gridrobot.h (8 x 8 cells, 16 headings, a range
// sensor: the paper-lab state layout) is the agent's scenario. Dyna-QPC learns it for a fixed
// number of episodes with QEMU_PLAN_STEPS planning updates after each real step, then the greedy
// policy is tried from fixed starts. It prints what it learned (the CRC-32 of every learned table,
// as learned_store saves them: `digest=`) on its console and exits 0 when
// learning shortened the episodes to a third and the greedy policy reaches the goal from at
// least 15 of 20 fixed starts, 1 otherwise. (Measured: paper-lab 84 -> 14 steps, 19 of 20.)
//
// Every agent_plan() call is bracketed by bench_mark_begin()/bench_mark_end(), and
// bench_mark_report() follows the learning run: the QEMU plugin tools/qemu/insn_count.c counts
// the instructions executed between the marks, which with planning_updates gives the
// instructions per planning update on this CPU (cmake/bench_insn.cmake does the division).
#include <stdbool.h>
#include <stdint.h>

#include "agent/agent.h"
#include "console.h"
#include "gridrobot.h"
#include "robot/agent_profiles.h"
#include "robot/learned_digest.h"

#if defined(QEMU_PROFILE_PAPER_SIM)
#define PROFILE_NAME "paper-sim"
#define PROFILE_AGENT agent_paper_sim
#define PROFILE_STORAGE agent_storage_paper_sim
#else
#define PROFILE_NAME "paper-lab"
#define PROFILE_AGENT agent_paper_lab
#define PROFILE_STORAGE agent_storage_paper_lab
#endif

#ifndef QEMU_EPISODES
#define QEMU_EPISODES 500u
#endif
#ifndef QEMU_PLAN_STEPS
#define QEMU_PLAN_STEPS 5u
#endif
// The algorithm that learns (agent/algorithms.h). The digest images run Dyna-QPC; the
// instruction bench also runs each other planning algorithm, to measure its own cost per update
// (the lock-step simulator charges each agent its own in idle time: host_sim/src/lockstep.h).
#ifndef QEMU_AGENT_KIND
#define QEMU_AGENT_KIND AGENT_DYNA_QPC
#endif
// 1: learning the grid robot is not this image's verdict (a cost benchmark of an algorithm that
// need not learn it in QEMU_EPISODES): it exits 0 whatever the greedy policy does.
#ifndef QEMU_BENCH_ONLY
#define QEMU_BENCH_ONLY 0
#endif
#define MAX_STEPS_PER_EPISODE 1000u
#define EVAL_STARTS 20u
#define EVAL_MAX_STEPS 100u
#define EVAL_MIN_REACHED 15u

// The plugin toggles its count on the first instruction of these functions: they must stay
// separate functions that really get called.
__attribute__((noinline)) void bench_mark_begin(void);
__attribute__((noinline)) void bench_mark_end(void);
__attribute__((noinline)) void bench_mark_report(void);
void bench_mark_begin(void)
{
    __asm__ volatile("" ::: "memory");
}
void bench_mark_end(void)
{
    __asm__ volatile("" ::: "memory");
}
void bench_mark_report(void)
{
    __asm__ volatile("" ::: "memory");
}

static uint32_t run_episode_(agent_t *ag, prng_t *world, bool learn)
{
    gridrobot_t g;
    gridrobot_reset(&g, world);
    const uint32_t cap = learn ? MAX_STEPS_PER_EPISODE : EVAL_MAX_STEPS;
    for (uint32_t step = 1; step <= cap; step++) {
        const agent_state_t s = gridrobot_state(&g);
        const uint8_t a = learn ? agent_act(ag, s) : agent_greedy(ag, s);
        float reward = 0.0f;
        const bool done = gridrobot_step(&g, a, &reward);
        if (learn) {
            agent_observe(ag, s, a, reward, gridrobot_state(&g), done);
            bench_mark_begin();
            (void)agent_plan(ag, QEMU_PLAN_STEPS);
            bench_mark_end();
        }
        if (done) {
            return step;
        }
    }
    return cap + 1u;  // did not reach the goal
}

int main(void)
{
    agent_t *ag = &PROFILE_AGENT;
    agent_config_t cfg;
    cfg.kind = QEMU_AGENT_KIND;
    cfg.space = &gridrobot_space;
    cfg.params = agent_default_params();
    cfg.params.alpha = 0.9f;  // the paper's settings for its robots (as tests/bench)
    cfg.params.gamma = 0.9f;
    cfg.params.epsilon = 0.1f;
    cfg.params.plan_alpha = 0.999f;
    cfg.storage = &PROFILE_STORAGE;
    cfg.seed = 1u;
#ifdef QEMU_MODEL_PAPER  // the paper's CMAC-Model and CMAC-R (docs/agent.md)
    cfg.params.model = AGENT_MODEL_PAPER;
#endif
    console_puts("dynaqpc-qemu-agent profile=" PROFILE_NAME " agent=");
    console_puts(agent_kind_name(QEMU_AGENT_KIND));
#ifdef QEMU_MODEL_PAPER
    console_puts(" model=paper");
#endif
    console_puts("\n");
    if (agent_init(ag, &cfg) != 0) {
        console_puts("agent_init failed\n");
        console_exit(2u);
    }
    prng_t world;
    prng_seed(&world, 0xA5A5A5A4u);
    uint32_t first10 = 0;
    uint32_t last10 = 0;
    console_puts("steps per episode:");
    for (uint32_t e = 0; e < QEMU_EPISODES; e++) {
        const uint32_t steps = run_episode_(ag, &world, true);
        console_puts(" ");
        console_put_u64(steps);
        if (e < 10u) {
            first10 += steps;
        }
        if (e >= QEMU_EPISODES - 10u) {
            last10 += steps;
        }
    }
    console_puts("\n");
    bench_mark_report();
    console_puts("profile=" PROFILE_NAME " ");
    console_kv("real_steps", agent_stats(ag)->real_steps);
    console_kv("planning_updates", agent_stats(ag)->planning_updates);
    console_kv("planning_skipped", agent_stats(ag)->planning_skipped);
    agent_counter_t counters[AGENT_MAX_COUNTERS];
    const uint32_t n_counters = agent_counters(ag, counters);
    for (uint32_t i = 0; i < n_counters; i++) {
        console_kv(counters[i].name, counters[i].value);
    }
    console_kv("first10_mean_steps", first10 / 10u);
    console_kv("last10_mean_steps", last10 / 10u);
    console_puts("\n");
    console_kv("digest", learned_digest(ag));
    console_puts("\n");

    // The greedy policy from fixed starts (a world generator of its own, so the starts do not
    // depend on how long learning took).
    prng_t starts;
    prng_seed(&starts, 12345u);
    uint32_t reached = 0;
    uint32_t steps_sum = 0;
    for (uint32_t i = 0; i < EVAL_STARTS; i++) {
        const uint32_t steps = run_episode_(ag, &starts, false);
        if (steps <= EVAL_MAX_STEPS) {
            reached++;
            steps_sum += steps;
        }
    }
    console_kv("greedy_reached", reached);
    console_kv("of", EVAL_STARTS);
    console_kv("greedy_mean_steps", reached > 0u ? steps_sum / reached : 0u);
    console_puts("\n");
    const bool learned = reached >= EVAL_MIN_REACHED && 3u * last10 <= first10;
    console_puts(learned ? "result=learned\n" : "result=NOT-LEARNED\n");
    console_exit(learned || QEMU_BENCH_ONLY ? 0u : 1u);
}
