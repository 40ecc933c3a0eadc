// SPDX-License-Identifier: MIT
// dynaqpc: Dyna-QPC (the paper's Figs. 3, 7, 10): a learned world model (model.h) predicts
// outcomes and names predecessors, and prioritized sweeping spends planning on the pairs whose
// values would change most.
#include <stddef.h>

#include "algorithm.h"
#include "fw/fw_base.h"
#include "fw_config.h"

FW_STATIC_ASSERT(QSTORE_MAX_REGIONS + MODEL_MAX_REGIONS <= AGENT_MAX_REGIONS,
                 dyna_qpc_lists_at_most_AGENT_MAX_REGIONS);

#if FW_CFG_PLAN_CACHE_ENTRIES > 0
// What the planner's model gave about a state, kept until the model next changes (fw_config.h):
// the predecessors it found, and the prediction of each action of the state that was popped.
// Between two real steps the model stands still, and idle-time planning (one update a call) pops
// and searches the same few dozen states again and again (paper-sim-real from scratch: 94 % of
// its searches are of a state searched since the last real step). An answer found again is what
// the model gave and counts what it counted (model_count_again()), so planning and the counters
// are those of the MCU, which has no room for this table. One table for the process (the host
// runs one agent at a time): its entries name their model, and every change to any model makes
// them all stale.
typedef struct plan_cache_entry {
    const world_model_t *model;
    uint32_t generation;  ///< current while it equals generation_
    agent_state_t state;
    bool searched;        ///< n, counted and pred hold the predecessor search's answer
    uint32_t predicted;   ///< bit a: action a's prediction is in moved, step[a], step_counted[a]
    uint32_t moved;       ///< bit a: model_query_predict() gave step[a] (else it refused)
    uint32_t n;
    model_counts_t counted;
    model_pred_t pred[MODEL_MAX_PREDECESSORS];
    model_step_t step[FW_CFG_MAX_ACTIONS];
    model_counts_t step_counted[FW_CFG_MAX_ACTIONS];
} plan_cache_entry_t;

FW_STATIC_ASSERT(FW_CFG_MAX_ACTIONS <= 32, plan_cache_action_masks_fit);

FW_STATIC_ASSERT(FW_IS_POW2(FW_CFG_PLAN_CACHE_ENTRIES) && FW_CFG_PLAN_CACHE_ENTRIES >= 2,
                 plan_cache_entries_are_a_power_of_two);

static plan_cache_entry_t cache_[FW_CFG_PLAN_CACHE_ENTRIES];
static uint32_t generation_ = 1u;  // 0 is no entry's: a fresh table holds nothing current

// Every entry stale: a model changed (learned, cleared, restored, made).
static void cache_forget_(void)
{
    generation_++;
    if (generation_ == 0u) {  // after 2^32 changes the oldest entries would come back: clear them
        for (uint32_t i = 0; i < FW_CFG_PLAN_CACHE_ENTRIES; i++) {
            cache_[i].generation = 0u;
        }
        generation_ = 1u;
    }
}

// The entry s maps to: the top bits of its Fibonacci hash, which depend on all of its bits.
static plan_cache_entry_t *cache_entry_(agent_state_t s)
{
    return &cache_[(uint32_t)(s * 0x9E3779B1u) / (0x80000000u / (FW_CFG_PLAN_CACHE_ENTRIES / 2u))];
}

// The entry of s for `model`, as it stands (holding nothing of s's when it held another state or
// an older model's answers).
static plan_cache_entry_t *cache_entry_for_(const world_model_t *model, agent_state_t s)
{
    plan_cache_entry_t *const e = cache_entry_(s);
    if (e->generation != generation_ || e->model != model || e->state != s) {
        e->model = model;
        e->generation = generation_;
        e->state = s;
        e->searched = false;
        e->predicted = 0u;
    }
    return e;
}
#define CACHE_FORGET_() cache_forget_()
#else
#define CACHE_FORGET_() ((void)0)
#endif

static int init_(agent_t *ag, const agent_storage_t *st)
{
    const agent_dyna_qpc_storage_t *mine = &st->dyna_qpc;
    agent_dyna_qpc_t *me = &ag->alg.dyna_qpc;
    CACHE_FORGET_();
    int err = model_init(&me->model, ag->space, ag->params.tilings, ag->params.model_rate,
                         ag->params.min_count, &mine->forward, &mine->reloc);
    if (err) {
        return err;
    }
    if (mine->pq_heap == NULL || mine->carry == NULL) {
        return FW_ERR_INVAL;
    }
    me->carry = mine->carry;
    me->model.ablate = (uint8_t)(ag->params.ablate &
                                 (AGENT_ABLATE_GENERALISE | AGENT_ABLATE_MAJORITY | AGENT_ABLATE_STAY));
    if (ag->params.stays) {
        model_set_stay_reward(&me->model, ag->params.step_reward);
    }
    return pq_init(&me->pq, mine->pq_heap, mine->pq_index_keys, mine->pq_index_pos,
                   mine->pq_capacity);
}

static void clear_(agent_t *ag)
{
    CACHE_FORGET_();
    model_clear(&ag->alg.dyna_qpc.model);
    pq_clear(&ag->alg.dyna_qpc.pq);
}

// The target of a predicted step from s: with several outcomes (a place seen with several
// percepts), the mean of their values, each equally likely; a step that may stay in s (model.h:
// a fixed step that ended in its cell) weighs in s's value by its stay share.
static float step_target_(const agent_t *ag, agent_state_t s, const model_step_t *step)
{
    const bool one_code = step->others == 0u || (ag->params.ablate & AGENT_ABLATE_EXPECTED) != 0u;
    if (step->terminal || (one_code && step->stay == 0u)) {
        return agent_target_(ag, step->reward, step->next, step->terminal);
    }
    agent_state_t next[MODEL_MAX_PERCEPTS];
    const uint32_t n = one_code ? (next[0] = step->next, 1u)
                                : model_step_outcomes(&ag->alg.dyna_qpc.model, step, next);
    float sum = 0.0f;
    for (uint32_t i = 0; i < n; i++) {
        sum += qstore_max(&ag->q, next[i]);
    }
    const float stay = (float)step->stay / 255.0f;
    const float v = (1.0f - stay) * (sum / (float)n) + stay * qstore_max(&ag->q, s);
    return step->reward + ag->params.gamma * v;
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

// `target` without the planning bonus, which this adds (Dyna-Q+; 0 in the other modes).
static void queue_if_urgent_(agent_t *ag, agent_state_t s, uint8_t a, float target)
{
    const float p = agent_abs_(target + agent_plan_bonus_(ag, s, a) - qstore_get(&ag->q, s, a));
    if (p > ag->params.theta) {
        (void)pq_push(&ag->alg.dyna_qpc.pq, agent_pair_(ag, s, a), p);
    }
}

// The target of a predecessor of `here`: its step, leading there (and to its other outcomes).
static float pred_target_(const agent_t *ag, const model_pred_t *pred, agent_state_t here)
{
    const model_step_t step = {here, pred->reward, 0u, pred->others, pred->stay};
    return step_target_(ag, pred->state, &step);
}

// A state seen for the first time makes new predictions possible: its own untried pairs, and
// untried pairs elsewhere that the relocatable model now sees leading into it. Their successors'
// values may never change again, so nothing else would queue them: they are queued here.
static void queue_new_state_(agent_t *ag, agent_state_t s)
{
    world_model_t *model = &ag->alg.dyna_qpc.model;
    model_query_t q;
    model_step_t step;
    model_pred_t pred[MODEL_MAX_PREDECESSORS];
    model_query_init(model, s, &q);
    for (uint32_t a = 0; a < ag->space->n_actions; a++) {
        if (model_query_predict(model, &q, (uint8_t)a, &step)) {
            queue_if_urgent_(ag, s, (uint8_t)a, step_target_(ag, s, &step));
        }
    }
    const uint32_t n = model_query_predecessors(model, &q, pred, NULL);
    for (uint32_t i = 0; i < n; i++) {
        queue_if_urgent_(ag, pred[i].state, pred[i].action, pred_target_(ag, &pred[i], s));
    }
}

// Pairs whose bonus a real step re-examines (Dyna-Q+ only; see refresh_bonus_()).
#define BONUS_REFRESH_PER_STEP 4u

// Dyna-Q+ with prioritized sweeping: a pair's bonus grows with every real step, but the queue
// only hears of a pair when something it leads to changes, so a pair untried for long (a door
// that was shut) would keep the value it had when last planned. Each real step re-examines a few
// tried pairs drawn at random (as Dyna-Q's uniform replay would reach them) and queues those whose
// bonus has moved their target by more than theta; sweeping then carries it to their
// predecessors. Pairs never tried get their bonus when a new state queues them.
static void refresh_bonus_(agent_t *ag)
{
    world_model_t *model = &ag->alg.dyna_qpc.model;
    for (uint32_t i = 0; i < BONUS_REFRESH_PER_STEP; i++) {
        uint32_t pair;
        if (!explore_sample(&ag->tried, &ag->rng, &pair)) {
            return;
        }
        const agent_state_t s = pair / ag->space->n_actions;
        const uint8_t a = (uint8_t)(pair % ag->space->n_actions);
        model_query_t q;
        model_step_t step;
        model_query_init(model, s, &q);
        if (model_query_predict(model, &q, a, &step)) {
            queue_if_urgent_(ag, s, a, step_target_(ag, s, &step));
        }
    }
}

static void observe_(agent_t *ag, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                     bool terminal, float priority)
{
    agent_dyna_qpc_t *me = &ag->alg.dyna_qpc;
    // New to the map (which learning is about to show it); a space without one has no new
    // states.
    const bool new_state = me->model.percepts != NULL && !model_has_seen(&me->model, s_next);
    CACHE_FORGET_();
    const bool plannable = model_learn(&me->model, s, a, r, s_next, terminal);
    if (priority > ag->params.theta) {
        (void)pq_push(&me->pq, agent_pair_(ag, s, a) | (plannable ? 0u : UNPLANNABLE_BIT), priority);
    }
    if (new_state && !terminal && (ag->params.ablate & AGENT_ABLATE_NEW_STATES) == 0u) {
        queue_new_state_(ag, s_next);
    }
    if (ag->params.explore == AGENT_EXPLORE_PLAN_BONUS) {
        refresh_bonus_(ag);
    }
}

// The carry (dyna_qpc.h) of a planning call: nothing trains the model between two updates of
// one agent_plan() call (a real step does, and each call starts with an empty carry), so what
// the model said then it would say again:
// - confirming a predecessor was asking CMAC-Model about it, and the answer was "it leads to
//   `here` with the predecessor's reward, not terminal". Prioritized sweeping works backwards,
//   so an update often pops one of them (about a third of the updates on the grid robot);
// - an update that pops another action of `here` (about one in ten) has the same predecessors.
static void plan_carry_init_(agent_plan_carry_t *c)
{
    c->valid = false;
    c->queries_missing = false;
#if FW_CFG_PLAN_CACHE_ENTRIES > 0
    c->here_missing = false;
#endif
    c->here = &c->store[0];
    for (uint32_t i = 0; i < MODEL_MAX_PREDECESSORS; i++) {
        c->query[i] = &c->store[i + 1u];
    }
}

// The predecessors of the carry's `here`, with their queries, into the carry (and what finding
// them counted); from the cache when this model's were found since it last changed, without the
// queries then (made when needed: c->queries_missing).
static void find_predecessors_(world_model_t *model, agent_plan_carry_t *c)
{
#if FW_CFG_PLAN_CACHE_ENTRIES > 0
    plan_cache_entry_t *const e = cache_entry_for_(model, c->here->state);
    if (e->searched) {
        c->n = e->n;
        for (uint32_t i = 0; i < e->n; i++) {
            c->pred[i] = e->pred[i];
        }
        c->counted = e->counted;
        c->queries_missing = true;
        model_count_again(model, e->counted);
        return;
    }
    if (c->here_missing) {  // the popped pair's prediction came from the cache: the query, made here
        model_query_init(model, c->here->state, c->here);
        c->here_missing = false;
    }
#endif
    const model_counts_t before = model_counts(model);
    c->n = model_query_predecessors(model, c->here, c->pred, c->query);
    c->counted = model_counts_since(model, before);
    c->queries_missing = false;
#if FW_CFG_PLAN_CACHE_ENTRIES > 0
    e->searched = true;
    e->n = c->n;
    e->counted = c->counted;
    for (uint32_t i = 0; i < c->n; i++) {
        e->pred[i] = c->pred[i];
    }
#endif
}

// What the popped pair (s, a) leads to: from the carry when s is a predecessor the previous
// update found (its query then becomes the carry's `here`), else predicted from a fresh query.
// False, counted as skipped, when the model cannot predict it.
static bool popped_outcome_(agent_t *ag, agent_plan_carry_t *c, uint32_t key, agent_state_t s, uint8_t a,
                            model_step_t *step)
{
    agent_dyna_qpc_t *me = &ag->alg.dyna_qpc;
    const bool same = c->valid && c->here->state == s;
    uint32_t known = 0;
    while (c->valid && known < c->n &&
           agent_pair_(ag, c->pred[known].state, c->pred[known].action) != key) {
        known++;
    }
    if (c->valid && known < c->n) {
        step->next = c->here->state;
        step->reward = c->pred[known].reward;
        step->terminal = 0;
        step->others = c->pred[known].others;
        step->stay = c->pred[known].stay;
        if (!same) {  // the predecessor's query becomes `here`, its old place is free
            model_query_t *const q = c->query[known];
#if FW_CFG_PLAN_CACHE_ENTRIES > 0
            if (c->queries_missing) {  // found in the cache: the search's query, made here
                model_query_init(&me->model, c->pred[known].state, q);
            }
#endif
            c->query[known] = c->here;
            c->here = q;
#if FW_CFG_PLAN_CACHE_ENTRIES > 0
            c->here_missing = false;
#endif
            c->valid = false;
        }
    } else {
        if (!same) {
            c->valid = false;
#if FW_CFG_PLAN_CACHE_ENTRIES > 0
            // The prediction from the cache, or made and kept there; the query only when it is
            // made (or the search needs it: find_predecessors_()).
            plan_cache_entry_t *const e = cache_entry_for_(&me->model, s);
            const uint32_t bit = 1u << a;
            if ((e->predicted & bit) == 0u) {
                model_query_init(&me->model, s, c->here);
                const model_counts_t before = model_counts(&me->model);
                if (model_query_predict(&me->model, c->here, a, &e->step[a])) {
                    e->moved |= bit;
                } else {
                    e->moved &= ~bit;
                }
                e->step_counted[a] = model_counts_since(&me->model, before);
                e->predicted |= bit;
                c->here_missing = false;
            } else {
                model_count_again(&me->model, e->step_counted[a]);
                c->here->state = s;
                c->here_missing = true;
            }
            if ((e->moved & bit) == 0u) {
                ag->stats.planning_skipped++;
                return false;
            }
            *step = e->step[a];
            return true;
#else
            model_query_init(&me->model, s, c->here);
#endif
        }
#if FW_CFG_PLAN_CACHE_ENTRIES > 0
        if (c->here_missing) {
            model_query_init(&me->model, s, c->here);
            c->here_missing = false;
        }
#endif
        if (!model_query_predict(&me->model, c->here, a, step)) {
            ag->stats.planning_skipped++;
            return false;
        }
    }
    return true;
}

#if FW_CFG_PLAN_CACHE_ENTRIES > 0
// The host's way of queueing the predecessors of `here` (state s, whose Q row is `row`): the
// same targets as pred_target_() and step_target_(), computed by the same operations in the same
// order, and the same pushes as agent_sweep_queue_(), with each state's values looked up once an
// update. About half the predecessors lead to s and to s with other percepts, or may stay where
// they are (paper-sim-real); the MCU's loop then looks s and each of those states up again for
// every predecessor, and each predecessor's state twice.
static void queue_predecessors_(agent_t *ag, const agent_plan_carry_t *c, agent_state_t s,
                                qstore_row_t row)
{
    const float max_here = qstore_row_max(&ag->q, row);
    const float value_here = ag->params.gamma * max_here;
    const bool expected = (ag->params.ablate & AGENT_ABLATE_EXPECTED) == 0u;
    float max_other[MODEL_MAX_PERCEPTS];  // qstore_max() of s with percept p, once known[p]
    uint32_t known = 0;
    for (uint32_t i = 0; i < c->n; i++) {
        const model_pred_t *pred = &c->pred[i];
        const qstore_row_t pred_row = qstore_row_of(&ag->q, pred->state);
        float target;
        if (pred->others == 0u && pred->stay == 0u) {
            target = pred->reward + value_here;
        } else if ((pred->others == 0u || !expected) && pred->stay == 0u) {
            target = pred->reward + ag->params.gamma * max_here;  // step_target_()'s agent_target_()
        } else {
            float sum = 0.0f;
            sum += max_here;
            uint32_t n = 1;
            if (expected) {
                if ((pred->others & ~known) != 0u) {
                    const model_step_t step = {s, pred->reward, 0u, pred->others, pred->stay};
                    agent_state_t next[MODEL_MAX_PERCEPTS];
                    (void)model_step_outcomes(&ag->alg.dyna_qpc.model, &step, next);
                    uint32_t k = 1;
                    for (uint32_t rest = pred->others; rest != 0u; rest &= rest - 1u, k++) {
                        const uint32_t p = (uint32_t)__builtin_ctz(rest);
                        if (((known >> p) & 1u) == 0u) {
                            max_other[p] = qstore_max(&ag->q, next[k]);
                            known |= 1u << p;
                        }
                    }
                }
                for (uint32_t rest = pred->others; rest != 0u; rest &= rest - 1u) {
                    sum += max_other[__builtin_ctz(rest)];
                    n++;
                }
            }
            const float stay = (float)pred->stay / 255.0f;
            const float v = (1.0f - stay) * (sum / (float)n) + stay * qstore_row_max(&ag->q, pred_row);
            target = pred->reward + ag->params.gamma * v;
        }
        target += agent_plan_bonus_(ag, pred->state, pred->action);
        // agent_sweep_queue_() with the value looked up in the row found above
        const float q = qstore_row_get(&ag->q, pred_row, pred->action);
        const float p = agent_abs_(target - q);
        if (p > ag->params.theta && qstore_moves(&ag->q, q, target, ag->params.plan_alpha)) {
            (void)pq_push(&ag->alg.dyna_qpc.pq, agent_pair_(ag, pred->state, pred->action), p);
        }
    }
}
#endif

// Fig. 3 (g): the most urgent pair is updated through the model, then every predecessor the
// model knows is queued by how much this change matters to it. `c` holds what the previous
// updates of this agent_plan() call found, and receives what this one finds.
static bool plan_one_(agent_t *ag, agent_plan_carry_t *c)
{
    agent_dyna_qpc_t *me = &ag->alg.dyna_qpc;
    uint32_t key;
    float priority;
    if (!pq_pop(&me->pq, &key, &priority)) {
        return false;
    }
    if (key & UNPLANNABLE_BIT) {
        model_count_untrusted(&me->model);  // what model_predict() would have counted
        ag->stats.planning_skipped++;
        return true;
    }
    const uint32_t n_actions = ag->space->n_actions;
    const agent_state_t s = key / n_actions;
    const uint8_t a = (uint8_t)(key % n_actions);
    model_step_t step;
    if (!popped_outcome_(ag, c, key, s, a, &step)) {
        return true;
    }
    const float target = step_target_(ag, s, &step) + agent_plan_bonus_(ag, s, a);
    // Q(s, a) += alpha (target - Q(s, a)); planning never forgets a state to make room for s,
    // which then has no row and reads 0.
    const qstore_row_t row = qstore_row_for_plan(&ag->q, s);
    if (row == QSTORE_NO_ROW) {
        // No row and no room for one: nothing changes, so neither the pair nor its predecessors
        // go back in the queue (requeueing it spun the planner on paper-sim: 10 M refusals in
        // 15 episodes, 2 updates per real step made of a budget of 1,000).
        ag->stats.planning_skipped++;
        return true;
    }
    agent_sweep_update_(ag, row, key, a, target);

    if (c->valid) {  // s is the carry's state: its predecessors are the ones found then
        model_count_again(&me->model, c->counted);
    } else {
        find_predecessors_(&me->model, c);
        c->valid = true;
    }
    if (c->n == 0u) {
        return true;
    }
#if FW_CFG_PLAN_CACHE_ENTRIES > 0
    queue_predecessors_(ag, c, s, row);
#else
    const float value_here = ag->params.gamma * qstore_row_max(&ag->q, row);
    for (uint32_t i = 0; i < c->n; i++) {
        const model_pred_t *pred = &c->pred[i];
        const float target_pred =
            (pred->others == 0u && pred->stay == 0u ? pred->reward + value_here : pred_target_(ag, pred, s)) +
            agent_plan_bonus_(ag, pred->state, pred->action);
        agent_sweep_queue_(ag, pred->state, pred->action, target_pred);
    }
#endif
    return true;
}

static uint32_t plan_(agent_t *ag, uint32_t n)
{
    agent_plan_carry_t *c = ag->alg.dyna_qpc.carry;
    uint32_t done = 0;
    plan_carry_init_(c);
    while (done < n && plan_one_(ag, c)) {
        done++;
    }
    return done;
}

static uint32_t regions_(const agent_t *ag, agent_region_t *out)
{
    return model_regions(&ag->alg.dyna_qpc.model, out);
}

static int check_(const agent_t *ag, const void *const *image, uint32_t state_bits)
{
    (void)state_bits;
    return model_check(&ag->alg.dyna_qpc.model, image);
}

static void restored_(agent_t *ag)
{
    CACHE_FORGET_();
    model_restored(&ag->alg.dyna_qpc.model);
    pq_clear(&ag->alg.dyna_qpc.pq);  // work in progress, not knowledge: never saved
}

// How many of the relocatable model's entries hold something: places with a percept, situations
// seen, positions where an episode ended. A scan of each table: for `--counters` and telemetry at
// the end of a run, not for the planner.
static void reloc_fill_(const world_model_t *m, uint32_t *places, uint32_t *situations,
                        uint32_t *arrivals)
{
    *places = *situations = *arrivals = 0;
    for (uint32_t i = 0; m->percepts != NULL && i < m->places; i++) {
        *places += m->percepts[i] != 0u;
    }
    for (uint32_t i = 0; m->classes != NULL && i < m->n_classes; i++) {
        *situations += m->classes[i].count != 0u;
    }
    for (uint32_t i = 0; m->arrivals != NULL && i < m->positions; i++) {
        *arrivals += m->arrivals[i] != MODEL_NO_ARRIVAL;
    }
}

static int walk_counters_(const agent_t *ag, agent_visit_t visit, void *data)
{
    const world_model_t *m = &ag->alg.dyna_qpc.model;
    uint32_t places, situations, arrivals;
    reloc_fill_(m, &places, &situations, &arrivals);
    AGENT_VISIT_(agent_visit_counter_(visit, data, "cmac_fwd", m->forward.stats.cells_used, m->forward.capacity));
    AGENT_VISIT_(agent_visit_counter_(visit, data, "cmac_evicted", m->forward.stats.evicted, 0u));
    AGENT_VISIT_(agent_visit_counter_(visit, data, "cmac_dropped", m->forward.stats.dropped, 0u));
    AGENT_VISIT_(agent_visit_counter_(visit, data, "model_untrusted", m->untrusted, 0u));
    AGENT_VISIT_(agent_visit_counter_(visit, data, "model_rejected", m->rejected, 0u));
    AGENT_VISIT_(agent_visit_counter_(visit, data, "model_generalised", m->generalised, 0u));
    AGENT_VISIT_(agent_dyna_qpc_queue_counters_(ag, visit, data));
    AGENT_VISIT_(agent_visit_counter_(visit, data, "percept_places", places, m->places));
    AGENT_VISIT_(agent_visit_counter_(visit, data, "situations", situations, m->n_classes));
    return agent_visit_counter_(visit, data, "arrivals", arrivals, m->positions);
}

// CMAC-Model's cells, the percept map, the situations, the arrivals.
static int walk_tables_(const agent_t *ag, agent_visit_t visit, void *data)
{
    const world_model_t *m = &ag->alg.dyna_qpc.model;
    uint32_t places, situations, arrivals;
    reloc_fill_(m, &places, &situations, &arrivals);
    AGENT_VISIT_(agent_visit_table_(visit, data, "cmac", "cells", m->forward.stats.cells_used, m->forward.capacity));
    AGENT_VISIT_(agent_visit_table_(visit, data, "percepts", "places", places, m->places));
    AGENT_VISIT_(agent_visit_table_(visit, data, "situations", "used", situations, m->n_classes));
    return agent_visit_table_(visit, data, "arrivals", "used", arrivals, m->positions);
}

// Each state the map saw or the model predicts an action in, with CMAC-Model's training counts.
static int walk_states_(agent_t *ag, agent_visit_t visit, void *data)
{
    world_model_t *m = &ag->alg.dyna_qpc.model;
    for (agent_state_t s = 0; (s >> ag->state_bits) == 0u; s++) {
        agent_state_facts_t f = {s, false, model_has_seen(m, s), false, {0}};
        bool trained = false;
        model_query_t mq;
        model_query_init(m, s, &mq);
        for (uint32_t a = 0; a < ag->space->n_actions; a++) {
            cmac_tiles_t t = mq.tiles;
            cmac_tiles_set_action(&m->forward, &t, a);
            int32_t out[CMAC_MAX_OUTPUTS];
            f.n[a] = cmac_predict(&m->forward, &t, out);
            trained = trained || f.n[a] != 0u;
            model_step_t step;
            f.modelled = model_query_predict(m, &mq, (uint8_t)a, &step) || f.modelled;
        }
        if (f.visited || f.modelled || trained) {
            AGENT_VISIT_(agent_visit_state_(visit, data, &f));
        }
    }
    return 0;
}

static int walk_(agent_t *ag, uint32_t what, agent_visit_t visit, void *data)
{
    if (what & AGENT_FACT_COUNTER) {
        AGENT_VISIT_(walk_counters_(ag, visit, data));
    }
    if (what & AGENT_FACT_TABLE) {
        AGENT_VISIT_(walk_tables_(ag, visit, data));
    }
    return (what & AGENT_FACT_STATE) ? walk_states_(ag, visit, data) : 0;
}

static bool predict_(const agent_t *ag, agent_state_t s, uint8_t a, agent_outcome_t *out)
{
    model_step_t step;
    if (!model_tried_outcome(&ag->alg.dyna_qpc.model, s, a, &step)) {
        return false;
    }
    *out = (agent_outcome_t){step.next, step.reward, step.terminal != 0u};
    return true;
}

int agent_dyna_qpc_queue_counters_(const agent_t *ag, agent_visit_t visit, void *data)
{
    const pqueue_t *pq = &ag->alg.dyna_qpc.pq;
    AGENT_VISIT_(agent_visit_counter_(visit, data, "queue", pq->size, pq->capacity));
    return agent_visit_counter_(visit, data, "queue_dropped", pq->stats.dropped, 0u);
}

uint32_t agent_dyna_qpc_backlog_(const agent_t *ag)
{
    return pq_size(&ag->alg.dyna_qpc.pq);
}

const agent_algorithm_t agent_dyna_qpc_algorithm = {
    AGENT_OWN_OPERATIONS_,
    .predict = predict_,
    .backlog = agent_dyna_qpc_backlog_,
    // cortex-m4.bench.insn_paper_lab: 4,213 when it was set (issue 13; 4,161 when the others were
    // first measured, 4,647 with main merged at 23fef33), kept so that the idle-time figures in
    // docs/results/ stay as measured.
    .plan_cycles = 4213u,
};
