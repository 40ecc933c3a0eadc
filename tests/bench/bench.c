// SPDX-License-Identifier: MIT
// dynaqpc-bench: how fast the agent plans, on one host core. A benchmark, not a test.
//
// Workloads: the agent learns a task with N planning updates after every real step, and only the
// planning calls are timed. Figures are medians over repetitions with different seeds; under
// callgrind the same workload gives an instruction count that does not depend on machine load.
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "agent/agent.h"
#include "robot/agent_profiles.h"
#include "gridrobot.h"

typedef struct result {
    double plan_seconds;
    uint64_t planning_updates;  // Q updates made by planning
    uint64_t planning_calls;    // planning calls that did work (popped or sampled something)

    uint64_t real_steps;
} result_t;

static double now_(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

// Dyna maze of Sutton & Barto's Fig. 8.2 as a bit mask per row; start (2, 0), goal (0, 8).
static const uint16_t maze_walls_[6] = {0x080, 0x084, 0x084, 0x004, 0x020, 0x000};

static bool maze_step_(uint32_t *r, uint32_t *c, uint8_t a)
{
    int nr = (int)*r + (a == 1) - (a == 0);
    int nc = (int)*c + (a == 3) - (a == 2);
    if (nr >= 0 && nr < 6 && nc >= 0 && nc < 9 && !((maze_walls_[nr] >> nc) & 1u)) {
        *r = (uint32_t)nr;
        *c = (uint32_t)nc;
    }
    return *r == 0 && *c == 8;
}

static const agent_space_t maze_space_ = {2, {3, 4}, {0, 0}, 0, 0, 4, 0, 0};

static agent_t agent_;

static void run_(const char *workload, agent_kind_t kind, uint32_t seed, uint32_t planning,
                 result_t *out)
{
    const bool robot = strcmp(workload, "gridrobot") == 0;
    agent_config_t cfg;
    cfg.kind = kind;
    cfg.space = robot ? &gridrobot_space : &maze_space_;
    cfg.params = agent_default_params();
    cfg.storage = &agent_storage_maze;  // room to spare: the bench measures speed, not fit
    cfg.seed = seed;
    if (robot) {  // the paper's settings for its robots
        cfg.params.alpha = 0.9f;
        cfg.params.gamma = 0.9f;
        cfg.params.epsilon = 0.1f;
        cfg.params.plan_alpha = 0.999f;
    }
    if (agent_init(&agent_, &cfg) != 0) {
        fprintf(stderr, "dynaqpc-bench: agent_init failed\n");
        exit(1);
    }
    prng_t world;
    prng_seed(&world, seed ^ 0xA5A5A5A5u);
    memset(out, 0, sizeof *out);
    // The maze is learned within a few episodes, after which the queue is mostly empty: many
    // short runs give the planner enough work to time.
    const uint32_t runs = robot ? 1 : 40;
    const uint32_t episodes = robot ? 40 : 10;
    for (uint32_t e = 0; e < runs * episodes; e++) {
        if (e % episodes == 0) {
            out->planning_updates += agent_.stats.planning_updates;
            agent_reset(&agent_, seed * 7919u + e);
        }
        gridrobot_t g;
        uint32_t r = 2, c = 0;
        gridrobot_reset(&g, &world);
        bool done = false;
        for (uint32_t step = 0; step < 2000 && !done; step++) {
            const agent_state_t s = robot ? gridrobot_state(&g) : (r | c << 3);
            const uint8_t a = agent_act(&agent_, s);
            float reward = 0.0f;
            if (robot) {
                done = gridrobot_step(&g, a, &reward);
            } else {
                done = maze_step_(&r, &c, a);
                reward = done ? 1.0f : 0.0f;
            }
            agent_observe(&agent_, s, a, reward, robot ? gridrobot_state(&g) : (r | c << 3), done);
            const double t0 = now_();
            out->planning_calls += agent_plan(&agent_, planning);
            out->plan_seconds += now_() - t0;
            out->real_steps++;
        }
    }
    out->planning_updates += agent_.stats.planning_updates;
}

static int compare_(const void *a, const void *b)
{
    const double x = *(const double *)a;
    const double y = *(const double *)b;
    return (x > y) - (x < y);
}

// Instructions per planning update: callgrind counts everything agent_plan() and its callees
// execute (skipped pops and empty-queue calls included), divided by the Q updates they made.
static long long callgrind_instructions_(const char *self, const char *workload,
                                         uint64_t *calls)
{
    char cmd[1024];
    snprintf(cmd, sizeof cmd,
             "valgrind --tool=callgrind --callgrind-out-file=/dev/null --collect-atstart=no "
             "--toggle-collect=agent_plan '%s' --single %s 2>&1",
             self, workload);
    FILE *p = popen(cmd, "r");
    if (p == NULL) {
        return -1;
    }
    char line[512];
    long long collected = -1;
    unsigned long long n = 0;
    while (fgets(line, sizeof line, p) != NULL) {
        const char *c = strstr(line, "Collected : ");
        if (c != NULL) {
            collected = atoll(c + 12);
        }
        sscanf(line, "planning_updates=%llu", &n);
    }
    if (pclose(p) != 0 || n == 0) {
        return -1;
    }
    *calls = n;
    return collected;
}

int main(int argc, char **argv)
{
    const char *workloads[] = {"gridrobot", "maze"};
    if (argc == 3 && strcmp(argv[1], "--single") == 0) {  // one repetition, for callgrind
        result_t r;
        run_(argv[2], AGENT_DYNA_QPC, 1, 5, &r);
        printf("planning_updates=%llu\n", (unsigned long long)r.planning_updates);
        return 0;
    }
    const bool count = !(argc > 1 && strcmp(argv[1], "--no-callgrind") == 0);
    enum { REPS = 7 };
    for (unsigned w = 0; w < 2; w++) {
        double rate[REPS];
        result_t r = {0};
        for (uint32_t rep = 0; rep < REPS; rep++) {
            run_(workloads[w], AGENT_DYNA_QPC, 1 + rep, 5, &r);
            rate[rep] = (double)r.planning_updates / r.plan_seconds;
        }
        qsort(rate, REPS, sizeof rate[0], compare_);
        printf("workload=%s agent=dyna-qpc planning=5 real_steps=%llu planning_updates=%llu "
               "queue_dropped=%u cmac_cells=%u/%u\n",
               workloads[w], (unsigned long long)r.real_steps,
               (unsigned long long)r.planning_updates, agent_.alg.dyna_qpc.pq.stats.dropped,
               agent_.alg.dyna_qpc.model.forward.stats.cells_used, agent_.alg.dyna_qpc.model.forward.capacity);
        printf("planning_updates_per_s=%.0f (median of %d; min %.0f, max %.0f)\n", rate[REPS / 2],
               REPS, rate[0], rate[REPS - 1]);
        if (count) {
            uint64_t calls = 0;
            const long long ins = callgrind_instructions_(argv[0], workloads[w], &calls);
            if (ins > 0) {
                printf("instructions_per_update=%.0f (callgrind, host x86-64, %llu planning "
                       "updates)\n",
                       (double)ins / (double)calls, (unsigned long long)calls);
            } else {
                printf("instructions_per_update=unavailable (valgrind not found or failed)\n");
            }
        }
    }
    return 0;
}
