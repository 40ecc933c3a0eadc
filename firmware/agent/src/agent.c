// SPDX-License-Identifier: MIT
// dynaqpc: the agent: what every algorithm shares (the Q store, acting, the real step's Q update)
// and the dispatch to the chosen algorithm's operations (algorithm.h, one file per algorithm).
#include "agent/agent.h"

#include <stddef.h>
#include <string.h>

#include "algorithm.h"
#include "fw/fw_base.h"

// ---- The registry: every algorithm of algorithms.h, by kind ------------------------------------

#define AGENT_ALGORITHM_ENTRY_(kind, number, name, label, id, d) [number] = &agent_##id##_algorithm,
static const agent_algorithm_t *const algorithms_[] = {AGENT_ALGORITHMS(AGENT_ALGORITHM_ENTRY_)};
#undef AGENT_ALGORITHM_ENTRY_

#define AGENT_NAME_ENTRY_(kind, number, name, label, id, d) [number] = name,
static const char *const names_[] = {AGENT_ALGORITHMS(AGENT_NAME_ENTRY_)};
#undef AGENT_NAME_ENTRY_

#define AGENT_LABEL_ENTRY_(kind, number, name, label, id, d) [number] = label,
static const char *const labels_[] = {AGENT_ALGORITHMS(AGENT_LABEL_ENTRY_)};
#undef AGENT_LABEL_ENTRY_

FW_STATIC_ASSERT(sizeof algorithms_ / sizeof algorithms_[0] == AGENT_KINDS &&
                     sizeof names_ / sizeof names_[0] == AGENT_KINDS &&
                     sizeof labels_ / sizeof labels_[0] == AGENT_KINDS,
                 kinds_are_numbered_0_to_AGENT_KINDS_without_gaps);

const char *agent_kind_name(agent_kind_t kind)
{
    return (uint32_t)kind < AGENT_KINDS ? names_[kind] : NULL;
}

int agent_kind_from_name(const char *name, agent_kind_t *kind)
{
    for (uint32_t k = 0; name != NULL && k < AGENT_KINDS; k++) {
        if (strcmp(name, names_[k]) == 0) {
            *kind = (agent_kind_t)k;
            return FW_OK;
        }
    }
    return FW_ERR_INVAL;
}

int agent_kind_info(agent_kind_t kind, agent_info_t *info)
{
    if ((uint32_t)kind >= AGENT_KINDS || info == NULL) {
        return FW_ERR_INVAL;
    }
    info->name = names_[kind];
    info->label = labels_[kind];
    info->plan_cycles = algorithms_[kind]->plan_cycles;
    return FW_OK;
}

// ---- The models: every line of AGENT_MODELS_OF ------------------------------------------------

typedef struct {
    agent_kind_t kind;
    uint8_t model;
    const agent_algorithm_t *algorithm;
} model_entry_t;

#define AGENT_MODEL_ENTRY_(kind, model, name, id) {kind, model, &agent_##id##_algorithm},
static const model_entry_t models_[] = {AGENT_MODELS_OF(AGENT_MODEL_ENTRY_)};
#undef AGENT_MODEL_ENTRY_

#define AGENT_MODEL_NAME_(kind, model, name, id) [model] = name,
static const char *const model_names_[] = {AGENT_MODELS_OF(AGENT_MODEL_NAME_)};
#undef AGENT_MODEL_NAME_

FW_STATIC_ASSERT(sizeof model_names_ / sizeof model_names_[0] == AGENT_MODELS,
                 models_are_numbered_0_to_AGENT_MODELS_once_each);

const char *agent_model_name(uint8_t model)
{
    return model < AGENT_MODELS ? model_names_[model] : NULL;
}

int agent_model_from_name(const char *name, uint8_t *model)
{
    for (uint32_t k = 0; name != NULL && k < AGENT_MODELS; k++) {
        if (strcmp(name, model_names_[k]) == 0) {
            *model = (uint8_t)k;
            return FW_OK;
        }
    }
    return FW_ERR_INVAL;
}

// The operations an agent of `kind` runs with `model`: the model's line, else the kind's own.
static const agent_algorithm_t *operations_(agent_kind_t kind, uint8_t model)
{
    for (uint32_t i = 0; i < sizeof models_ / sizeof models_[0]; i++) {
        if (models_[i].kind == kind && models_[i].model == model) {
            return models_[i].algorithm;
        }
    }
    return algorithms_[kind];
}

bool agent_kind_has_model(agent_kind_t kind, uint8_t model)
{
    for (uint32_t i = 0; i < sizeof models_ / sizeof models_[0]; i++) {
        if (models_[i].kind == kind && models_[i].model == model) {
            return true;
        }
    }
    return false;
}

// ---- Set-up -----------------------------------------------------------------------------------

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
    p.ablate = 0;
    p.explore = AGENT_EXPLORE_EGREEDY;
    p.kappa = 0.0f;
    p.model = AGENT_MODEL_RELOCATABLE;
    for (uint32_t k = 0; k < FW_CFG_MAX_COMPONENTS; k++) {
        p.model_tile_shift[k] = k == PAPER_DEFAULT_TILED_COMPONENT ? 1u : 0u;
    }
    p.stays = 0;
    p.step_reward = 0.0f;
    p.q_prior = 0.0f;
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
           p->tilings <= FW_CFG_MAX_TILINGS && p->min_count >= 1u &&
           (p->ablate & ~AGENT_ABLATE_ALL) == 0u && p->model < AGENT_MODELS &&
           p->explore < AGENT_EXPLORE_MODES && p->kappa >= 0.0f && p->kappa <= AGENT_KAPPA_MAX &&
           p->q_prior >= -QSTORE_VALUE_LIMIT && p->q_prior <= QSTORE_VALUE_LIMIT;
}

int agent_init(agent_t *ag, const agent_config_t *cfg)
{
    if (ag == NULL || cfg == NULL || cfg->storage == NULL || space_validate(cfg->space) != FW_OK ||
        !params_valid_(&cfg->params) || (uint32_t)cfg->kind >= AGENT_KINDS) {
        return FW_ERR_INVAL;
    }
    const agent_storage_t *st = cfg->storage;
    const agent_space_t *sp = cfg->space;
    ag->kind = cfg->kind;
    ag->algorithm = operations_(cfg->kind, cfg->params.model);
    ag->space = sp;
    ag->state_bits = space_state_bits(sp);
    ag->params = cfg->params;
    int err = st->q_keys16 != NULL
                  ? qstore_init16(&ag->q, st->q, st->q_value_bytes, st->q_keys16, st->q_states,
                                  sp->n_actions, ag->state_bits)
                  : qstore_init(&ag->q, st->q, st->q_value_bytes, st->q_keys, st->q_states,
                                sp->n_actions, ag->state_bits);
    if (err) {
        return err;
    }
    qstore_set_prior(&ag->q, cfg->params.q_prior);
    err = ag->algorithm->init(ag, st);
    if (err) {
        return err;
    }
    // The bonus modes need the tried-pairs table; epsilon-greedy leaves it untouched.
    ag->tried = (explore_table_t){0};
    if (cfg->params.explore != AGENT_EXPLORE_EGREEDY &&
        explore_init(&ag->tried, st->tried_keys, st->tried_at, st->tried_pairs) != FW_OK) {
        return FW_ERR_INVAL;
    }
    alias_init(&ag->alias);
    prng_seed(&ag->rng, cfg->seed);
    ag->stats = (agent_stats_t){0};
    return FW_OK;
}

void agent_reset(agent_t *ag, uint32_t seed)
{
    FW_ASSERT(ag != NULL && ag->algorithm != NULL);
    qstore_clear(&ag->q);
    ag->algorithm->clear(ag);
    if (ag->params.explore != AGENT_EXPLORE_EGREEDY) {
        explore_clear(&ag->tried);
    }
    alias_clear(&ag->alias);
    prng_seed(&ag->rng, seed);
    ag->stats = (agent_stats_t){0};
}

// ---- Acting -----------------------------------------------------------------------------------

// A state the space can hold (a caller's programming error otherwise: the dense Q store indexes
// by it).
#define ASSERT_STATE_(ag, s) FW_ASSERT(((s) >> (ag)->state_bits) == 0u)
#define ASSERT_ACTION_(ag, a) FW_ASSERT((uint32_t)(a) < (ag)->space->n_actions)

// The bonus on acting: the largest Q(s, a) + kappa * sqrt(tau(s, a)), ties broken uniformly. A
// pair never tried has tau = now, so from a place it knows the robot first tries what it has not.
static uint8_t act_bonus_(agent_t *ag, agent_state_t s)
{
    const uint32_t n = ag->space->n_actions;
    float row[FW_CFG_MAX_ACTIONS];
    qstore_values(&ag->q, s, row);
    uint32_t best = 0;
    uint32_t ties = 1;
    float best_v = 0.0f;
    for (uint32_t a = 0; a < n; a++) {
        const float v = row[a] + agent_bonus_(ag, s, (uint8_t)a);
        if (a == 0u || v > best_v) {
            best = a;
            best_v = v;
            ties = 1;
        } else if (v == best_v) {
            ties++;
            if (prng_below(&ag->rng, ties) == 0u) {
                best = a;
            }
        }
    }
    return (uint8_t)best;
}

uint8_t agent_act(agent_t *ag, agent_state_t s)
{
    if (prng_unit(&ag->rng) < ag->params.epsilon) {
        return (uint8_t)prng_below(&ag->rng, ag->space->n_actions);
    }
    if (ag->params.explore == AGENT_EXPLORE_ACT_BONUS) {
        ASSERT_STATE_(ag, s);
        return act_bonus_(ag, s);
    }
    return agent_act_greedy(ag, s);
}

uint8_t agent_act_greedy(agent_t *ag, agent_state_t s)
{
    ASSERT_STATE_(ag, s);
    // Ties broken uniformly: while every value is still 0 the robot must not always pick
    // action 0 (a replayed policy would drive into a wall forever from a state it never saw).
    const uint32_t n = ag->space->n_actions;
    float row[FW_CFG_MAX_ACTIONS];
    qstore_values(&ag->q, s, row);
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
    ASSERT_STATE_(ag, s);
    float row[FW_CFG_MAX_ACTIONS];
    qstore_values(&ag->q, s, row);
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
    ASSERT_STATE_(ag, s);
    ASSERT_ACTION_(ag, a);
    return qstore_get(&ag->q, s, a);
}

// ---- Learning ---------------------------------------------------------------------------------

// A cell's real steps learn at alpha / (1 + k) after k aliasing steps there, k at most this.
// One unlucky outcome of a pair that usually passes (a bump from a place that the state cannot
// tell from its neighbour) then moves its value by a share of the difference instead of
// overwriting it (alpha 0.9), and the value tends to the mean over the cell's outcomes, as a
// backup over the outcomes' counts would (Moore & Atkeson's prioritized sweeping); the bound
// keeps a cell that aliased long ago learning at alpha / 8 (0.11 for alpha 0.9).
#define ALIAS_DAMP_MAX 7u

// Compares the real step with the algorithm's own experience of (s, a) and counts the cell
// (alias.h): returns s's cell's count, 0 when the algorithm keeps no outcome for the pair.
static uint32_t watch_aliasing_(agent_t *ag, agent_state_t s, uint8_t a, float r,
                                agent_state_t s_next, bool terminal)
{
    agent_outcome_t kept;
    const agent_state_t cell = s & space_position_mask(ag->space);
    if (ag->algorithm->predict == NULL || !ag->algorithm->predict(ag, s, a, &kept)) {
        return alias_count(&ag->alias, cell);
    }
    return alias_note(&ag->alias, cell, agent_outcome_differs_(&kept, r, s_next, terminal));
}

void agent_observe(agent_t *ag, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                   bool terminal)
{
    ASSERT_STATE_(ag, s);
    ASSERT_STATE_(ag, s_next);
    ASSERT_ACTION_(ag, a);
    const float target = agent_target_(ag, r, s_next, terminal);
    const float priority = agent_abs_(target - agent_q(ag, s, a));
    const uint32_t aliased = watch_aliasing_(ag, s, a, r, s_next, terminal);
    ag->stats.real_steps++;
    if (ag->params.explore != AGENT_EXPLORE_EGREEDY) {
        explore_tried(&ag->tried, agent_pair_(ag, s, a), ag->stats.real_steps);
    }
    const float alpha = (ag->params.ablate & AGENT_ABLATE_ALIAS) != 0u
                            ? ag->params.alpha
                            : ag->params.alpha / (float)(1u + (aliased < ALIAS_DAMP_MAX ? aliased : ALIAS_DAMP_MAX));
    if (agent_q_update_(ag, s, a, target, alpha, false)) {
        ag->stats.real_updates++;
    }
    ag->algorithm->observe(ag, s, a, r, s_next, terminal, priority);
}

bool agent_plan_step(agent_t *ag)
{
    return ag->algorithm->plan(ag, 1u) != 0u;
}

uint32_t agent_plan(agent_t *ag, uint32_t n)
{
    return ag->algorithm->plan(ag, n);
}

// ---- Counters ---------------------------------------------------------------------------------

// ---- What the agent knows: the walk ----------------------------------------------------------

// The Q store's facts: its counters, its fill, its rows.
static int walk_q_(const agent_t *ag, uint32_t what, agent_visit_t visit, void *data)
{
    const qstore_t *q = &ag->q;
    if (what & AGENT_FACT_COUNTER) {
        AGENT_VISIT_(agent_visit_counter_(visit, data, "q_rows", q->rows_used, q->capacity));
        AGENT_VISIT_(agent_visit_counter_(visit, data, "q_dropped", q->dropped, 0u));
        AGENT_VISIT_(agent_visit_counter_(visit, data, "q_plan_refused", q->plan_refused, 0u));
    }
    if (what & AGENT_FACT_TABLE) {
        agent_fact_t f;
        f.kind = AGENT_FACT_TABLE;
        f.u.table = (agent_table_fill_t){"q", "rows", q->dense ? 0u : q->rows_used, q->capacity,
                                         (int8_t)(q->dense ? 1 : 0)};
        AGENT_VISIT_(visit(data, &f));
    }
    if (what & AGENT_FACT_STATE) {
        for (agent_state_t s = 0; (s >> ag->state_bits) == 0u; s++) {
            if (qstore_has_row(q, s)) {
                const agent_state_facts_t f = {s, true, false, false, {0}};
                AGENT_VISIT_(agent_visit_state_(visit, data, &f));
            }
        }
    }
    return 0;
}

// The aliasing watch's counters and cells (alias.h).
static int walk_alias_(const agent_t *ag, uint32_t what, agent_visit_t visit, void *data)
{
    alias_cell_t cells[FW_CFG_ALIAS_CELLS];
    const uint32_t n = alias_cells(&ag->alias, cells);
    if (what & AGENT_FACT_COUNTER) {
        AGENT_VISIT_(agent_visit_counter_(visit, data, "alias_checked", ag->alias.checked, 0u));
        AGENT_VISIT_(agent_visit_counter_(visit, data, "alias_steps", ag->alias.aliased, 0u));
        AGENT_VISIT_(agent_visit_counter_(visit, data, "alias_cells", n, FW_CFG_ALIAS_CELLS));
    }
    for (uint32_t i = 0; (what & AGENT_FACT_ALIAS) && i < n; i++) {
        agent_fact_t f;
        f.kind = AGENT_FACT_ALIAS;
        f.u.alias = cells[i];
        AGENT_VISIT_(visit(data, &f));
    }
    return 0;
}

int agent_walk(agent_t *ag, uint32_t what, agent_visit_t visit, void *data)
{
    FW_ASSERT(ag != NULL && ag->algorithm != NULL && visit != NULL);
    AGENT_VISIT_(walk_q_(ag, what, visit, data));
    AGENT_VISIT_(ag->algorithm->walk(ag, what, visit, data));
    if ((what & AGENT_FACT_COUNTER) && ag->params.explore != AGENT_EXPLORE_EGREEDY) {
        AGENT_VISIT_(agent_visit_counter_(visit, data, "tried_pairs", ag->tried.used, ag->tried.capacity));
        AGENT_VISIT_(agent_visit_counter_(visit, data, "tried_forgotten", ag->tried.forgotten, 0u));
    }
    return ag->algorithm->predict == NULL ? 0 : walk_alias_(ag, what, visit, data);
}

typedef struct {
    agent_counter_t *out;
    uint32_t n;
} counter_list_t;

static int list_counter_(void *data, const agent_fact_t *fact)
{
    counter_list_t *list = data;
    FW_ASSERT(list->n < AGENT_MAX_COUNTERS);
    list->out[list->n++] = fact->u.counter;
    return 0;
}

uint32_t agent_counters(agent_t *ag, agent_counter_t out[AGENT_MAX_COUNTERS])
{
    counter_list_t list = {out, 0u};
    (void)agent_walk(ag, AGENT_FACT_COUNTER, list_counter_, &list);
    return list.n;
}

uint32_t agent_aliasing(const agent_t *ag, agent_state_t s)
{
    return alias_count(&ag->alias, s & space_position_mask(ag->space));
}

float agent_value(const agent_t *ag, agent_state_t s)
{
    ASSERT_STATE_(ag, s);
    return qstore_max(&ag->q, s);
}

uint32_t agent_backlog(const agent_t *ag)
{
    return ag->algorithm->backlog(ag);
}

// ---- Saving and restoring what was learned ----------------------------------------------------

// Each module lists its own regions, checks its own part of a saved image and recounts its own
// fill; the agent only strings them together, in this order: the Q store, then the algorithm's.

uint32_t agent_learned_regions(const agent_t *ag, agent_region_t out[AGENT_MAX_REGIONS])
{
    const uint32_t n = qstore_regions(&ag->q, out);
    return n + ag->algorithm->regions(ag, out + n);
}

void agent_learned_restored(agent_t *ag)
{
    qstore_restored(&ag->q);
    ag->algorithm->restored(ag);
}

int agent_learned_check(const agent_t *ag, const void *const image[AGENT_MAX_REGIONS])
{
    // The regions in agent_learned_regions()' order: each module checks its own, starting where
    // the one before it ends.
    agent_region_t scratch[AGENT_MAX_REGIONS];
    if (qstore_check(&ag->q, image, ag->state_bits) != FW_OK) {
        return FW_ERR_CORRUPT;
    }
    const void *const *const rest = image + qstore_regions(&ag->q, scratch);
    return ag->algorithm->check(ag, rest, ag->state_bits) == FW_OK ? FW_OK : FW_ERR_CORRUPT;
}
