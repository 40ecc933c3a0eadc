// SPDX-License-Identifier: MIT
// dynaqpc: Dyna-Q with the majority rule, the fair baseline for Dyna-QPC: table-based
// Dyna-Q (dyna_q.c, the paper's Fig. 5) whose table keeps, per (s, a), the outcome most
// observations agreed on instead of the last one, by the rule Dyna-QPC's models use for tried
// pairs (model.h; cmac_contradict() in cmac.c): an observation that agrees with the kept outcome
// adds one to its count, one that disagrees takes one off, and replaces it only once as many
// observations disagreed as agreed (the count was 1). As in CMAC-Model's cells, the replacing
// outcome starts at a count of 2, and a count saturates at 255. Agreeing means the same next
// state and the same end of episode, and a reward within 0.5 (CMAC-Model's test), whose latest
// value is kept. Planning replays the table uniformly at random, as Dyna-Q.
#include <stddef.h>

#include "algorithm.h"
#include "fw/fw_base.h"

FW_STATIC_ASSERT(QSTORE_MAX_REGIONS + DYNAQ_REGIONS + 1u <= AGENT_MAX_REGIONS,
                 dyna_q_majority_lists_at_most_AGENT_MAX_REGIONS);

static int init_(agent_t *ag, const agent_storage_t *st)
{
    const agent_dyna_q_majority_storage_t *mine = &st->dyna_q_majority;
    agent_dyna_q_majority_t *me = &ag->alg.dyna_q_majority;
    if (mine->counts == NULL) {
        return FW_ERR_INVAL;
    }
    me->counts = mine->counts;
    me->kept = 0;
    me->replaced = 0;
    return dynaq_init(&me->table, mine->records, mine->index_keys, mine->index_rec, mine->states,
                      ag->space->n_actions);
}

static void clear_(agent_t *ag)
{
    agent_dyna_q_majority_t *me = &ag->alg.dyna_q_majority;
    dynaq_clear(&me->table);
    me->kept = 0;
    me->replaced = 0;
}

static uint8_t *count_of_(agent_dyna_q_majority_t *me, const dynaq_record_t *rec, uint8_t a)
{
    return &me->counts[(uint32_t)(rec - me->table.records) * FW_CFG_MAX_ACTIONS + a];
}

static void observe_(agent_t *ag, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                     bool terminal, float priority)
{
    (void)priority;
    agent_dyna_q_majority_t *me = &ag->alg.dyna_q_majority;
    const dynaq_record_t *rec = dynaq_find(&me->table, s);
    if (rec != NULL && dynaq_bit(rec->tried, a)) {
        uint8_t *count = count_of_(me, rec, a);
        const agent_outcome_t kept = {rec->next[a], rec->reward[a], dynaq_bit(rec->terminal, a)};
        const bool agrees = !agent_outcome_differs_(&kept, r, s_next, terminal);
        if (agrees) {
            if (*count < UINT8_MAX) {
                (*count)++;
            }
            (void)dynaq_remember(&me->table, s, a, r, s_next, terminal);  // the latest reward
            return;
        }
        if (*count > 1u) {  // it keeps the majority
            (*count)--;
            me->kept++;
            return;
        }
        (void)dynaq_remember(&me->table, s, a, r, s_next, terminal);
        *count = 2u;
        me->replaced++;
        return;
    }
    const uint32_t rec_no = dynaq_remember(&me->table, s, a, r, s_next, terminal);
    if (rec_no != DYNAQ_NO_RECORD) {
        me->counts[rec_no * FW_CFG_MAX_ACTIONS + a] = 1u;
    }
}

// Fig. 5 (f), as Dyna-Q: a random observed state, a random action tried there, its kept outcome.
static uint32_t plan_(agent_t *ag, uint32_t n)
{
    return agent_dyna_q_replay_(ag, &ag->alg.dyna_q_majority.table, n);
}

// The table's regions, then the counts.
static uint32_t regions_(const agent_t *ag, agent_region_t *out)
{
    const agent_dyna_q_majority_t *me = &ag->alg.dyna_q_majority;
    const uint32_t n = dynaq_regions(&me->table, out);
    return agent_region_add(out, n, me->counts, me->table.capacity * FW_CFG_MAX_ACTIONS);
}

// Any count is safe (one of 0 or 1 lets the next disagreement replace the outcome).
static int check_(const agent_t *ag, const void *const *image, uint32_t state_bits)
{
    return dynaq_check(&ag->alg.dyna_q_majority.table, image, state_bits);
}

static void restored_(agent_t *ag)
{
    agent_dyna_q_majority_t *me = &ag->alg.dyna_q_majority;
    dynaq_restored(&me->table);
    me->kept = 0;
    me->replaced = 0;
}

// What Dyna-Q's table knows, then its own counters.
static int walk_(agent_t *ag, uint32_t what, agent_visit_t visit, void *data)
{
    const agent_dyna_q_majority_t *me = &ag->alg.dyna_q_majority;
    AGENT_VISIT_(agent_dyna_q_table_walk_(ag, &me->table, what, visit, data));
    if (what & AGENT_FACT_COUNTER) {
        AGENT_VISIT_(agent_visit_counter_(visit, data, "table_kept", me->kept, 0u));
        AGENT_VISIT_(agent_visit_counter_(visit, data, "table_replaced", me->replaced, 0u));
    }
    return 0;
}

// As Dyna-Q's: its table is where Dyna-Q's is (the first member of each one's state).
FW_STATIC_ASSERT(offsetof(agent_dyna_q_majority_t, table) == offsetof(agent_dyna_q_t, table),
                 dyna_q_majority_keeps_its_table_where_dyna_q_does);

const agent_algorithm_t agent_dyna_q_majority_algorithm = {
    AGENT_OWN_OPERATIONS_,
    .predict = agent_dyna_q_predict_,
    .backlog = agent_backlog_none_,
    .plan_cycles = 388u,  // cortex-m4.bench.insn_paper_lab_dyna_q_majority (359 before 23fef33)
};
