// SPDX-License-Identifier: MIT
// dynaqpc: Q-learning (Fig. 1), table-based Dyna-Q (Fig. 5) and Dyna-QPC (Figs. 3, 7, 10).
#include "agent/agent.h"

#include <stddef.h>

#include "agent/model_state.h"
#include "fw/fw_base.h"

agent_params_t agent_default_params(void)
{
    agent_params_t p;
    p.alpha = 0.1f;
    p.plan_alpha = 1.0f;
    p.gamma = 0.95f;
    p.epsilon = 0.1f;
    p.theta = 1e-4f;
    p.model_rate = 0.999f;
    p.tilings = 16;
    p.min_count = 1;
    return p;
}

static bool params_valid_(const agent_params_t *p)
{
    return p->alpha > 0.0f && p->alpha <= 1.0f &&      //
           p->plan_alpha > 0.0f && p->plan_alpha <= 1.0f && //
           p->gamma >= 0.0f && p->gamma <= 1.0f &&     //
           p->epsilon >= 0.0f && p->epsilon <= 1.0f && //
           p->theta >= 0.0f &&                         //
           p->model_rate > 0.0f && p->model_rate <= 1.0f && FW_IS_POW2(p->tilings) &&
           p->tilings <= FW_CFG_MAX_TILINGS && p->min_count >= 1u;
}

int agent_init(agent_t *ag, const agent_config_t *cfg)
{
    if (ag == NULL || cfg == NULL || cfg->storage == NULL || space_validate(cfg->space) != FW_OK ||
        !params_valid_(&cfg->params) || cfg->kind > AGENT_DYNA_QPC) {
        return FW_ERR_INVAL;
    }
    const agent_storage_t *st = cfg->storage;
    const agent_space_t *sp = cfg->space;
    ag->kind = cfg->kind;
    ag->space = sp;
    ag->params = cfg->params;
    int err = qstore_init(&ag->q, st->q, st->q_keys, st->q_states, sp->n_actions,
                          space_state_bits(sp));
    if (err) {
        return err;
    }
    if (cfg->kind == AGENT_DYNA_QPC) {
        err = model_init(&ag->model, sp, cfg->params.tilings, cfg->params.model_rate,
                         cfg->params.min_count, &st->forward, &st->reloc);
        if (err) {
            return err;
        }
        if (st->pq_heap == NULL) {
            return FW_ERR_INVAL;
        }
        err = pq_init(&ag->pq, st->pq_heap, st->pq_index_keys, st->pq_index_pos, st->pq_capacity);
    } else if (cfg->kind == AGENT_DYNA_Q) {
        err = dynaq_init(&ag->table, st->table, st->table_index_keys, st->table_index_rec,
                         st->table_states, sp->n_actions);
    }
    if (err) {
        return err;
    }
    prng_seed(&ag->rng, cfg->seed);
    ag->stats = (agent_stats_t){0};
    return FW_OK;
}

void agent_reset(agent_t *ag, uint32_t seed)
{
    qstore_clear(&ag->q);
    if (ag->kind == AGENT_DYNA_QPC) {
        model_clear(&ag->model);
        pq_clear(&ag->pq);
    } else if (ag->kind == AGENT_DYNA_Q) {
        dynaq_clear(&ag->table);
    }
    prng_seed(&ag->rng, seed);
    ag->stats = (agent_stats_t){0};
}

uint8_t agent_act(agent_t *ag, agent_state_t s)
{
    if (prng_unit(&ag->rng) < ag->params.epsilon) {
        return (uint8_t)prng_below(&ag->rng, ag->space->n_actions);
    }
    return agent_act_greedy(ag, s);
}

uint8_t agent_act_greedy(agent_t *ag, agent_state_t s)
{
    // Ties broken uniformly: while every value is still 0 the robot must not always pick
    // action 0 (a replayed policy would drive into a wall forever from a state it never saw).
    const uint32_t n = ag->space->n_actions;
    const float *row = qstore_row(&ag->q, s);
    uint32_t best = 0;
    uint32_t ties = 1;
    for (uint32_t a = 1; a < n; a++) {
        if (row[a] > row[best]) {
            best = a;
            ties = 1;
        } else if (row[a] == row[best]) {
            ties++;
            if (prng_below(&ag->rng, ties) == 0u) {
                best = a;
            }
        }
    }
    return (uint8_t)best;
}

uint8_t agent_greedy(const agent_t *ag, agent_state_t s)
{
    const float *row = qstore_row(&ag->q, s);
    uint32_t best = 0;
    for (uint32_t a = 1; a < ag->space->n_actions; a++) {
        if (row[a] > row[best]) {
            best = a;
        }
    }
    return (uint8_t)best;
}

float agent_q(const agent_t *ag, agent_state_t s, uint8_t a)
{
    return qstore_row(&ag->q, s)[a];
}

static float target_(const agent_t *ag, float r, agent_state_t s_next, bool terminal)
{
    return terminal ? r : r + ag->params.gamma * qstore_max(&ag->q, s_next);
}

// The target of a predicted step: with several outcomes (a place seen with several percepts),
// the mean of their values, each equally likely.
static float step_target_(const agent_t *ag, const model_step_t *step)
{
    if (step->terminal || step->others == 0u) {
        return target_(ag, step->reward, step->next, step->terminal);
    }
    agent_state_t next[MODEL_MAX_PERCEPTS];
    const uint32_t n = model_step_outcomes(&ag->model, step, next);
    float sum = 0.0f;
    for (uint32_t i = 0; i < n; i++) {
        sum += qstore_max(&ag->q, next[i]);
    }
    return step->reward + ag->params.gamma * (sum / (float)n);
}

static float abs_(float x)
{
    return x < 0.0f ? -x : x;
}

// Q(s, a) += alpha * (target - Q(s, a)). A real step's write may forget another state to make
// room; a planning write may not (qstore_row_for_plan) and returns false when s has no row.
static bool q_update_(agent_t *ag, agent_state_t s, uint8_t a, float target, float alpha,
                      bool planning)
{
    float *row = planning ? qstore_row_for_plan(&ag->q, s) : qstore_row_for_update(&ag->q, s);
    if (row == NULL) {
        return false;
    }
    row[a] += alpha * (target - row[a]);
    return true;
}

static uint32_t pq_key_(const agent_t *ag, agent_state_t s, uint8_t a)
{
    return s * ag->space->n_actions + a;
}

// A queued pair whose CMAC-Model tiles did not all find room carries this bit in its queue key,
// and popping it is a skip that needs no model lookup (a miss in a full window probes all
// FW_CFG_MAX_PROBE slots). With eviction this is rare: only a window held entirely by the same
// training refuses a tile. Should a later real step store the pair's tiles, that step queues it
// again without the bit.
#define UNPLANNABLE_BIT 0x80000000u
// States have at most 24 bits, so s * n_actions + a stays below the bit.
FW_STATIC_ASSERT(FW_CFG_MAX_ACTIONS <= 128 && SPACE_MAX_STATE_BITS <= 24,
                 queue_keys_leave_the_top_bit_free);

static void queue_if_urgent_(agent_t *ag, agent_state_t s, uint8_t a, float target)
{
    const float p = abs_(target - agent_q(ag, s, a));
    if (p > ag->params.theta) {
        (void)pq_push(&ag->pq, pq_key_(ag, s, a), p);
    }
}

// The target of a predecessor of `here`: its step, leading there (and to its other outcomes).
static float pred_target_(const agent_t *ag, const model_pred_t *pred, agent_state_t here)
{
    const model_step_t step = {here, pred->reward, 0u, pred->others};
    return step_target_(ag, &step);
}

// A state seen for the first time makes new predictions possible: its own untried pairs, and
// untried pairs elsewhere that the relocatable model now sees leading into it. Their successors'
// values may never change again, so nothing else would queue them: they are queued here.
static void queue_new_state_(agent_t *ag, agent_state_t s)
{
    model_query_t q;
    model_step_t step;
    model_pred_t pred[MODEL_MAX_PREDECESSORS];
    model_query_init(&ag->model, s, &q);
    for (uint32_t a = 0; a < ag->space->n_actions; a++) {
        if (model_query_predict(&ag->model, &q, (uint8_t)a, &step)) {
            queue_if_urgent_(ag, s, (uint8_t)a, step_target_(ag, &step));
        }
    }
    const uint32_t n = model_query_predecessors(&ag->model, &q, pred, NULL);
    for (uint32_t i = 0; i < n; i++) {
        queue_if_urgent_(ag, pred[i].state, pred[i].action, pred_target_(ag, &pred[i], s));
    }
}

void agent_observe(agent_t *ag, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                   bool terminal)
{
    const float target = target_(ag, r, s_next, terminal);
    const float priority = abs_(target - agent_q(ag, s, a));
    ag->stats.real_steps++;
    if (q_update_(ag, s, a, target, ag->params.alpha, false)) {
        ag->stats.real_updates++;
    }
    if (ag->kind == AGENT_DYNA_QPC) {
        // New to the map (which learning is about to show it); a space without one has no
        // new states.
        const bool new_state = ag->model.percepts != NULL && !model_has_seen(&ag->model, s_next);
        const bool plannable = model_learn(&ag->model, s, a, r, s_next, terminal);
        if (priority > ag->params.theta) {
            (void)pq_push(&ag->pq, pq_key_(ag, s, a) | (plannable ? 0u : UNPLANNABLE_BIT),
                          priority);
        }
        if (new_state && !terminal) {
            queue_new_state_(ag, s_next);
        }
    } else if (ag->kind == AGENT_DYNA_Q) {
        dynaq_remember(&ag->table, s, a, r, s_next, terminal);
    }
}

static float row_max_(const float *row, uint32_t n)
{
    float best = row[0];
    for (uint32_t a = 1; a < n; a++) {
        if (row[a] > best) {
            best = row[a];
        }
    }
    return best;
}

// What planning updates pass on to the next ones in the same agent_plan() call: the last state
// whose predecessors were found, those predecessors, and the queries (components and tiles) of
// all of them. Nothing trains the model between two updates of one call (a real step does, and
// each call starts with none of this), so what the model said then it would say again:
// - confirming a predecessor was asking CMAC-Model about it, and the answer was "it leads to
//   `here` with the predecessor's reward, not terminal". Prioritized sweeping works backwards,
//   so an update often pops one of them (about a third of the updates on the grid robot);
// - an update that pops another action of `here` (about one in ten) has the same predecessors.
typedef struct plan_carry {
    bool valid;           // `here` and the predecessors belong together
    model_query_t *here;  // the last state whose predecessors were found
    uint32_t n;
    model_pred_t pred[MODEL_MAX_PREDECESSORS];
    model_query_t *query[MODEL_MAX_PREDECESSORS];  // pred[i]'s
    model_counts_t counted;  // what finding them added to the model's counters
    model_query_t store[MODEL_MAX_PREDECESSORS + 1];  // where `here` and `query` point, all apart
} plan_carry_t;

// The carry of the planning call in progress (about 1.8 KB: MODEL_MAX_PREDECESSORS queries). It
// lives in .bss rather than on the stack, so the size report counts it and the MCU's planning
// stack stays small; planning calls never nest, and each starts by emptying it.
static plan_carry_t carry_;

static void plan_carry_init_(plan_carry_t *c)
{
    c->valid = false;
    c->here = &c->store[0];
    for (uint32_t i = 0; i < MODEL_MAX_PREDECESSORS; i++) {
        c->query[i] = &c->store[i + 1u];
    }
}

// Fig. 3 (g): the most urgent pair is updated through the model, then every predecessor the
// model knows is queued by how much this change matters to it. `c` holds what the previous
// updates of this agent_plan() call found, and receives what this one finds.
static bool plan_qpc_(agent_t *ag, plan_carry_t *c)
{
    uint32_t key;
    float priority;
    if (!pq_pop(&ag->pq, &key, &priority)) {
        return false;
    }
    if (key & UNPLANNABLE_BIT) {
        model_count_untrusted(&ag->model);  // what model_predict() would have counted
        ag->stats.planning_skipped++;
        return true;
    }
    const uint32_t n_actions = ag->space->n_actions;
    const agent_state_t s = key / n_actions;
    const uint8_t a = (uint8_t)(key % n_actions);
    const bool same = c->valid && c->here->state == s;
    uint32_t known = 0;
    while (c->valid && known < c->n &&
           pq_key_(ag, c->pred[known].state, c->pred[known].action) != key) {
        known++;
    }
    model_step_t step;
    if (c->valid && known < c->n) {
        step.next = c->here->state;
        step.reward = c->pred[known].reward;
        step.terminal = 0;
        step.others = c->pred[known].others;
        if (!same) {  // the predecessor's query becomes `here`, its old place is free
            model_query_t *const q = c->query[known];
            c->query[known] = c->here;
            c->here = q;
            c->valid = false;
        }
    } else {
        if (!same) {
            c->valid = false;
            model_query_init(&ag->model, s, c->here);
        }
        if (!model_query_predict(&ag->model, c->here, a, &step)) {
            ag->stats.planning_skipped++;
            return true;
        }
    }
    const float target = step_target_(ag, &step);
    // Q(s, a) += alpha (target - Q(s, a)); planning never forgets a state to make room for s,
    // which then has no row and reads 0.
    float *row = qstore_row_for_plan(&ag->q, s);
    if (row == NULL) {
        // No row and no room for one: nothing changes, so neither the pair nor its predecessors
        // go back in the queue (requeueing it spun the planner on paper-sim: 10 M refusals in
        // 15 episodes, 2 updates per real step made of a budget of 1,000).
        ag->stats.planning_skipped++;
        return true;
    }
    row[a] += ag->params.plan_alpha * (target - row[a]);
    const float q_sa = row[a];
    ag->stats.planning_updates++;
    // With alpha < 1 one update leaves (1 - alpha) of the error behind; the pair goes back in
    // the queue with what is left, so planning keeps working on it while it is the most urgent.
    const float left = abs_(target - q_sa);
    if (left > ag->params.theta) {
        (void)pq_push(&ag->pq, key, left);
    }

    if (c->valid) {  // s is the carry's state: its predecessors are the ones found then
        model_count_again(&ag->model, c->counted);
    } else {
        const model_counts_t before = model_counts(&ag->model);
        c->n = model_query_predecessors(&ag->model, c->here, c->pred, c->query);
        c->counted = model_counts_since(&ag->model, before);
        c->valid = true;
    }
    if (c->n == 0u) {
        return true;
    }
    const float value_here = ag->params.gamma * row_max_(row, n_actions);
    for (uint32_t i = 0; i < c->n; i++) {
        const model_pred_t *pred = &c->pred[i];
        const float target_pred =
            pred->others == 0u ? pred->reward + value_here : pred_target_(ag, pred, s);
        const float p = abs_(target_pred - qstore_row(&ag->q, pred->state)[pred->action]);
        if (p > ag->params.theta) {
            (void)pq_push(&ag->pq, pq_key_(ag, pred->state, pred->action), p);
        }
    }
    return true;
}

// Fig. 5 (f): a random observed state, a random action tried there, its recorded outcome.
static bool plan_dynaq_(agent_t *ag)
{
    agent_state_t s;
    agent_state_t s_next;
    uint8_t a;
    float r;
    bool terminal;
    if (!dynaq_sample(&ag->table, &ag->rng, &s, &a, &r, &s_next, &terminal)) {
        return false;
    }
    if (q_update_(ag, s, a, target_(ag, r, s_next, terminal), ag->params.plan_alpha, true)) {
        ag->stats.planning_updates++;
    }
    return true;
}

bool agent_plan_step(agent_t *ag)
{
    switch (ag->kind) {
    case AGENT_DYNA_QPC:
        plan_carry_init_(&carry_);
        return plan_qpc_(ag, &carry_);
    case AGENT_DYNA_Q:
        return plan_dynaq_(ag);
    case AGENT_Q_LEARNING:
    default:
        return false;
    }
}

uint32_t agent_plan(agent_t *ag, uint32_t n)
{
    uint32_t done = 0;
    if (ag->kind == AGENT_DYNA_QPC) {  // the planner's loop, without a dispatch per step
        plan_carry_init_(&carry_);
        while (done < n && pq_size(&ag->pq) > 0u) {
            (void)plan_qpc_(ag, &carry_);
            done++;
        }
        return done;
    }
    while (done < n && agent_plan_step(ag)) {
        done++;
    }
    return done;
}

// ---- Saving and restoring what was learned ----------------------------------------------------

// Each module lists its own regions, checks its own part of a saved image and recounts its own
// fill; the agent only strings them together, in this order: the Q store, then the model
// (Dyna-QPC) or the transition table (Dyna-Q).

uint32_t agent_learned_regions(const agent_t *ag, agent_region_t out[AGENT_MAX_REGIONS])
{
    uint32_t n = qstore_regions(&ag->q, out);
    if (ag->kind == AGENT_DYNA_QPC) {
        n += model_regions(&ag->model, out + n);
    } else if (ag->kind == AGENT_DYNA_Q) {
        n += dynaq_regions(&ag->table, out + n);
    }
    return n;
}

FW_STATIC_ASSERT(QSTORE_MAX_REGIONS + MODEL_MAX_REGIONS <= AGENT_MAX_REGIONS &&
                     QSTORE_MAX_REGIONS + DYNAQ_REGIONS <= AGENT_MAX_REGIONS,
                 every_agent_lists_at_most_AGENT_MAX_REGIONS);

void agent_learned_restored(agent_t *ag)
{
    qstore_restored(&ag->q);
    if (ag->kind == AGENT_DYNA_QPC) {
        model_restored(&ag->model);
        pq_clear(&ag->pq);  // work in progress, not knowledge: never saved
    } else if (ag->kind == AGENT_DYNA_Q) {
        dynaq_restored(&ag->table);
    }
}

int agent_learned_check(const agent_t *ag, const void *const image[AGENT_MAX_REGIONS])
{
    // The regions in agent_learned_regions()' order: each module checks its own, starting where
    // the one before it ends.
    agent_region_t scratch[AGENT_MAX_REGIONS];
    const uint32_t state_bits = space_state_bits(ag->space);
    if (qstore_check(&ag->q, image, state_bits) != FW_OK) {
        return FW_ERR_CORRUPT;
    }
    const void *const *const rest = image + qstore_regions(&ag->q, scratch);
    if (ag->kind == AGENT_DYNA_QPC) {
        return model_check(&ag->model, rest) == FW_OK ? FW_OK : FW_ERR_CORRUPT;
    }
    if (ag->kind == AGENT_DYNA_Q) {
        return dynaq_check(&ag->table, rest, state_bits) == FW_OK ? FW_OK : FW_ERR_CORRUPT;
    }
    return FW_OK;
}
