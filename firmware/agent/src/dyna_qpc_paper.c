// SPDX-License-Identifier: MIT
// dynaqpc: Dyna-QPC with the paper's model (`--model paper`): Fig. 3's prioritized sweeping over
// CMAC-Model and CMAC-R (paper_model.h), as the paper's Figs. 9 and 10 put them together.
//
// Why a set of operations of its own rather than branches through dyna_qpc.c: ours plans through
// a model with several outcomes per pair, a predecessor search whose answers the planner carries
// from one update to the next, and queues the pairs a new state makes predictable; none of that
// is the paper's. Here a planning update is Fig. 3 (g) and nothing more: pop the most urgent pair,
// back it up through CMAC-Model, queue what CMAC-R names as leading into its state. What both
// share is the agent (the Q store, acting, the real step's update: agent.c), the queue
// (pqueue.h), the settings, and the trust gate. Its line in algorithms.h (AGENT_MODELS_OF) makes
// agent_init() give a Dyna-QPC agent these operations when agent_params_t.model is
// AGENT_MODEL_PAPER: a model is registered as an algorithm is.
#include <stddef.h>

#include "algorithm.h"
#include "fw/fw_base.h"

FW_STATIC_ASSERT(QSTORE_MAX_REGIONS + PAPER_MODEL_REGIONS <= AGENT_MAX_REGIONS,
                 dyna_qpc_paper_lists_at_most_AGENT_MAX_REGIONS);
FW_STATIC_ASSERT(FW_CFG_MAX_ACTIONS <= 128 && SPACE_MAX_STATE_BITS <= 24, paper_queue_keys_fit);

static int init_(agent_t *ag, const agent_storage_t *st)
{
    const agent_dyna_qpc_storage_t *mine = &st->dyna_qpc;
    agent_dyna_qpc_t *me = &ag->alg.dyna_qpc;
    if (mine->pq_heap == NULL) {
        return FW_ERR_INVAL;
    }
    const int err = paper_model_init(&me->paper, ag->space, ag->params.model_tile_shift,
                                     ag->params.tilings, ag->params.model_rate,
                                     ag->params.min_count, &mine->paper);
    if (err) {
        return err;
    }
    return pq_init(&me->pq, mine->pq_heap, mine->pq_index_keys, mine->pq_index_pos,
                   mine->pq_capacity);
}

static void clear_(agent_t *ag)
{
    paper_model_clear(&ag->alg.dyna_qpc.paper);
    pq_clear(&ag->alg.dyna_qpc.pq);
}

// Fig. 3 (d) to (f): the model learns the step, which is queued by its priority.
static void observe_(agent_t *ag, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                     bool terminal, float priority)
{
    agent_dyna_qpc_t *me = &ag->alg.dyna_qpc;
    (void)paper_model_learn(&me->paper, s, a, r, s_next, terminal);
    if (priority > ag->params.theta) {
        (void)pq_push(&me->pq, agent_pair_(ag, s, a), priority);
    }
}

// Fig. 3 (g), one pass: the most urgent pair is backed up through CMAC-Model, then each pair
// CMAC-R names as leading into its state is queued by how much the change matters to it.
static bool plan_one_(agent_t *ag)
{
    agent_dyna_qpc_t *me = &ag->alg.dyna_qpc;
    uint32_t key;
    float priority;
    if (!pq_pop(&me->pq, &key, &priority)) {
        return false;
    }
    const uint32_t n_actions = ag->space->n_actions;
    const agent_state_t s = key / n_actions;
    const uint8_t a = (uint8_t)(key % n_actions);
    model_step_t step;
    qstore_row_t row = QSTORE_NO_ROW;
    if (!paper_model_predict(&me->paper, s, a, &step) ||
        (row = qstore_row_for_plan(&ag->q, s)) == QSTORE_NO_ROW) {
        ag->stats.planning_skipped++;  // untrusted, or no Q row and no room for one
        return true;
    }
    agent_sweep_update_(ag, row, key, a,
                        agent_target_(ag, step.reward, step.next, step.terminal != 0u));
    model_pred_t pred[PAPER_MAX_PREDECESSORS];
    const uint32_t n = paper_model_predecessors(&me->paper, s, pred);
    const float value_here = ag->params.gamma * qstore_row_max(&ag->q, row);
    for (uint32_t i = 0; i < n; i++) {
        agent_sweep_queue_(ag, pred[i].state, pred[i].action, pred[i].reward + value_here);
    }
    return true;
}

static uint32_t plan_(agent_t *ag, uint32_t n)
{
    uint32_t done = 0;
    while (done < n && plan_one_(ag)) {
        done++;
    }
    return done;
}

static uint32_t regions_(const agent_t *ag, agent_region_t *out)
{
    return paper_model_regions(&ag->alg.dyna_qpc.paper, out);
}

static int check_(const agent_t *ag, const void *const *image, uint32_t state_bits)
{
    (void)state_bits;
    return paper_model_check(&ag->alg.dyna_qpc.paper, image);
}

static void restored_(agent_t *ag)
{
    paper_model_restored(&ag->alg.dyna_qpc.paper);
    pq_clear(&ag->alg.dyna_qpc.pq);  // work in progress, not knowledge: never saved
}

static int walk_counters_(const agent_t *ag, agent_visit_t visit, void *data)
{
    const paper_model_t *m = &ag->alg.dyna_qpc.paper;
    AGENT_VISIT_(agent_visit_counter_(visit, data, "cmac_fwd", m->forward.stats.cells_used, m->forward.capacity));
    AGENT_VISIT_(agent_visit_counter_(visit, data, "cmac_evicted", m->forward.stats.evicted, 0u));
    AGENT_VISIT_(agent_visit_counter_(visit, data, "cmac_dropped", m->forward.stats.dropped, 0u));
    AGENT_VISIT_(agent_visit_counter_(visit, data, "cmac_r", m->inverse.stats.cells_used, m->inverse.capacity));
    AGENT_VISIT_(agent_visit_counter_(visit, data, "cmac_r_evicted", m->inverse.stats.evicted, 0u));
    AGENT_VISIT_(agent_visit_counter_(visit, data, "cmac_r_dropped", m->inverse.stats.dropped, 0u));
    AGENT_VISIT_(agent_visit_counter_(visit, data, "model_untrusted", m->untrusted, 0u));
    AGENT_VISIT_(agent_visit_counter_(visit, data, "model_rejected", m->rejected, 0u));
    return agent_dyna_qpc_queue_counters_(ag, visit, data);
}

// The paper's model keeps no map of what was perceived: a state with a Q row was visited (a real
// step writes it); CMAC-Model's training counts and predictions say the rest.
static int walk_states_(agent_t *ag, agent_visit_t visit, void *data)
{
    paper_model_t *m = &ag->alg.dyna_qpc.paper;
    for (agent_state_t s = 0; (s >> ag->state_bits) == 0u; s++) {
        agent_state_facts_t f = {s, false, qstore_has_row(&ag->q, s), false, {0}};
        bool trained = false;
        uint32_t comp[FW_CFG_MAX_COMPONENTS];
        space_unpack(ag->space, s, comp);
        for (uint32_t a = 0; a < ag->space->n_actions; a++) {
            cmac_tiles_t t;
            cmac_tiles_of(&m->forward, comp, a, &t);
            int32_t out[CMAC_MAX_OUTPUTS];
            f.n[a] = cmac_predict(&m->forward, &t, out);
            trained = trained || f.n[a] != 0u;
            model_step_t step;
            f.modelled = paper_model_predict(m, s, (uint8_t)a, &step) || f.modelled;
        }
        if (f.visited || f.modelled || trained) {
            AGENT_VISIT_(agent_visit_state_(visit, data, &f));
        }
    }
    return 0;
}

static int walk_(agent_t *ag, uint32_t what, agent_visit_t visit, void *data)
{
    const paper_model_t *m = &ag->alg.dyna_qpc.paper;
    if (what & AGENT_FACT_COUNTER) {
        AGENT_VISIT_(walk_counters_(ag, visit, data));
    }
    if (what & AGENT_FACT_TABLE) {  // CMAC-Model and CMAC-R: no map, no situations
        AGENT_VISIT_(agent_visit_table_(visit, data, "cmac", "cells", m->forward.stats.cells_used, m->forward.capacity));
        AGENT_VISIT_(agent_visit_table_(visit, data, "cmac_r", "cells", m->inverse.stats.cells_used, m->inverse.capacity));
    }
    return (what & AGENT_FACT_STATE) ? walk_states_(ag, visit, data) : 0;
}

const agent_algorithm_t agent_dyna_qpc_paper_algorithm = {
    AGENT_OWN_OPERATIONS_,
    .backlog = agent_dyna_qpc_backlog_,
    .plan_cycles = 4213u,  // Dyna-QPC's (agent_kind_info() gives the kind's figure)
};
