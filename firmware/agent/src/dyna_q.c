// SPDX-License-Identifier: MIT
// dynaqpc: table-based Dyna-Q (the paper's Fig. 5): every real step is remembered in a table of
// observed transitions (the last outcome of each pair, as Sutton & Barto's Dyna-Q), and
// planning replays them uniformly at random.
#include <stddef.h>

#include "algorithm.h"
#include "fw/fw_base.h"

FW_STATIC_ASSERT(QSTORE_MAX_REGIONS + DYNAQ_REGIONS <= AGENT_MAX_REGIONS,
                 dyna_q_lists_at_most_AGENT_MAX_REGIONS);

static int init_(agent_t *ag, const agent_storage_t *st)
{
    const agent_dyna_q_storage_t *mine = &st->dyna_q;
    return dynaq_init(&ag->alg.dyna_q.table, mine->records, mine->index_keys, mine->index_rec,
                      mine->states, ag->space->n_actions);
}

static void clear_(agent_t *ag)
{
    dynaq_clear(&ag->alg.dyna_q.table);
}

static void observe_(agent_t *ag, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                     bool terminal, float priority)
{
    (void)priority;
    dynaq_remember(&ag->alg.dyna_q.table, s, a, r, s_next, terminal);
}

// Fig. 5 (f): a random observed state, a random action tried there, its recorded outcome.
static bool replay_one_(agent_t *ag, const dynaq_table_t *table)
{
    agent_state_t s;
    agent_state_t s_next;
    uint8_t a;
    float r;
    bool terminal;
    if (!dynaq_sample(table, &ag->rng, &s, &a, &r, &s_next, &terminal)) {
        return false;
    }
    // Dyna-Q+ (explore.h): the bonus of a pair untried for long joins its recorded reward.
    const float target = agent_target_(ag, r, s_next, terminal) + agent_plan_bonus_(ag, s, a);
    if (agent_q_update_(ag, s, a, target, ag->params.plan_alpha, true)) {
        ag->stats.planning_updates++;
    }
    return true;
}

uint32_t agent_dyna_q_replay_(agent_t *ag, const dynaq_table_t *table, uint32_t n)
{
    uint32_t done = 0;
    while (done < n && replay_one_(ag, table)) {
        done++;
    }
    return done;
}

static uint32_t plan_(agent_t *ag, uint32_t n)
{
    return agent_dyna_q_replay_(ag, &ag->alg.dyna_q.table, n);
}

static uint32_t regions_(const agent_t *ag, agent_region_t *out)
{
    return dynaq_regions(&ag->alg.dyna_q.table, out);
}

static int check_(const agent_t *ag, const void *const *image, uint32_t state_bits)
{
    return dynaq_check(&ag->alg.dyna_q.table, image, state_bits);
}

static void restored_(agent_t *ag)
{
    dynaq_restored(&ag->alg.dyna_q.table);
}

uint32_t agent_dyna_q_table_counters_(const dynaq_table_t *table, agent_counter_t *out)
{
    out[0] = (agent_counter_t){"table", table->count, table->capacity};
    out[1] = (agent_counter_t){"table_evicted", table->evicted, 0u};
    return 2u;
}

static uint32_t counters_(const agent_t *ag, agent_counter_t *out)
{
    return agent_dyna_q_table_counters_(&ag->alg.dyna_q.table, out);
}

const agent_algorithm_t agent_dyna_q_algorithm = {
    .init = init_,
    .clear = clear_,
    .observe = observe_,
    .plan = plan_,
    .regions = regions_,
    .check = check_,
    .restored = restored_,
    .counters = counters_,
    .backlog = agent_backlog_none_,
    .plan_cycles = 389u,  // cortex-m4.bench.insn_paper_lab_dyna_q (361 before main merged 23fef33)
};
