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

// A recorded state's facts: visited, its tried actions (n 1 each); and the states they led to.
static int walk_record_(const agent_t *ag, const dynaq_record_t *r, agent_visit_t visit, void *data)
{
    if ((r->state >> ag->state_bits) != 0u) {
        return 0;
    }
    agent_state_facts_t f = {r->state, false, true, false, {0}};
    for (uint32_t a = 0; a < ag->space->n_actions; a++) {
        if (dynaq_bit(r->tried, a)) {
            f.n[a] = 1u;
            f.modelled = true;
        }
    }
    AGENT_VISIT_(agent_visit_state_(visit, data, &f));
    for (uint32_t a = 0; a < ag->space->n_actions; a++) {
        if (dynaq_bit(r->tried, a) && (r->next[a] >> ag->state_bits) == 0u) {
            const agent_state_facts_t next = {r->next[a], false, true, false, {0}};
            AGENT_VISIT_(agent_visit_state_(visit, data, &next));
        }
    }
    return 0;
}

int agent_dyna_q_table_walk_(const agent_t *ag, const dynaq_table_t *table, uint32_t what,
                             agent_visit_t visit, void *data)
{
    if (what & AGENT_FACT_COUNTER) {
        AGENT_VISIT_(agent_visit_counter_(visit, data, "table", table->count, table->capacity));
        AGENT_VISIT_(agent_visit_counter_(visit, data, "table_evicted", table->evicted, 0u));
    }
    if (what & AGENT_FACT_TABLE) {
        AGENT_VISIT_(agent_visit_table_(visit, data, "table", "records", table->count, table->capacity));
    }
    for (uint32_t i = 0; (what & AGENT_FACT_STATE) && i < table->count; i++) {
        AGENT_VISIT_(walk_record_(ag, &table->records[i], visit, data));
    }
    return 0;
}

static int walk_(agent_t *ag, uint32_t what, agent_visit_t visit, void *data)
{
    return agent_dyna_q_table_walk_(ag, &ag->alg.dyna_q.table, what, visit, data);
}

bool agent_dyna_q_predict_(const agent_t *ag, agent_state_t s, uint8_t a, agent_outcome_t *out)
{
    const dynaq_record_t *rec = dynaq_find(&ag->alg.dyna_q.table, s);
    if (rec == NULL || !dynaq_bit(rec->tried, a)) {
        return false;
    }
    *out = (agent_outcome_t){rec->next[a], rec->reward[a], dynaq_bit(rec->terminal, a)};
    return true;
}

const agent_algorithm_t agent_dyna_q_algorithm = {
    AGENT_OWN_OPERATIONS_,
    .predict = agent_dyna_q_predict_,
    .backlog = agent_backlog_none_,
    .plan_cycles = 389u,  // cortex-m4.bench.insn_paper_lab_dyna_q (361 before main merged 23fef33)
};
