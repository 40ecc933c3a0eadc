// SPDX-License-Identifier: MIT
// dynaqpc: the paper's world model (paper_model.h): CMAC-Model and CMAC-R over tiles wider than a
// state cell.
//
// Why it is built this way:
// - Both CMACs predict a change per component (s' - s; for CMAC-R s_{t-1} - s_t) rather than the
//   next state's value, except for the absolute components (a sensor reading, whose value is what
//   there is to predict). A CMAC's output is a weighted mean over the tiles an input shares with
//   the inputs it was trained on; the mean of the neighbours' next positions is the neighbours'
//   positions plus a step, which is the wrong place for an untried cell, while the mean of their
//   changes is the step itself. The paper says only that the output is (s', r); docs/agent.md
//   lists this as one of the departures that apply to both models.
// - The outputs are rounded to the nearest integer per component: a state is discrete. A
//   rounded value out of the component's range is refused (the trust gate).
// - CMAC-R's input is the pair a trajectory went on with, its output the pair before (§3.2):
//   that is what "the predecessor of the input state-action pair" reads as, and what Fig. 8's
//   cyclic path needs. The action is an output like the components (rounded), as the paper has
//   it; averaged over tiles trained with different actions it may name a pair that does not lead
//   to s, which CMAC-Model's confirmation then refuses.
// - Episode boundaries: a step that ended its episode names no successor pair. An episode cut by
//   the step cap is not told to the agent; the next episode's first step then names the capped
//   step as its predecessor only if it starts where that step ended (a coincidence the start
//   positions make rare, and a real transition's neighbour at worst).
#include "agent/paper_model.h"

#include <stddef.h>

#include "fw/fw_base.h"

static int32_t round_q_(int32_t v)  // fixed point (CMAC_FRAC_BITS) to the nearest integer
{
    return v >= 0 ? (v + CMAC_ONE / 2) / CMAC_ONE : -((-v + CMAC_ONE / 2) / CMAC_ONE);
}

// Applies predicted outputs out[0 .. n-1] (fixed point) to comp[]; false if a component leaves its
// range (a circular one wraps).
static bool apply_(const agent_space_t *sp, const uint32_t *comp, const int32_t *out, uint32_t *next)
{
    for (uint32_t k = 0; k < sp->n_components; k++) {
        const int32_t n = (int32_t)1 << sp->bits[k];
        const int32_t d = round_q_(out[k]);
        int32_t v;
        if ((sp->absolute_mask >> k) & 1u) {
            v = d;
        } else if ((sp->circular_mask >> k) & 1u) {
            v = ((int32_t)comp[k] + d) & (n - 1);
        } else {
            v = (int32_t)comp[k] + d;
        }
        if (v < 0 || v >= n) {
            return false;
        }
        next[k] = (uint32_t)v;
    }
    return true;
}

static int init_cmac_(cmac_t *c, const agent_space_t *sp, const uint8_t *tile_shift, uint8_t tilings,
                      float rate, uint8_t n_outputs, const model_cmac_storage_t *st)
{
    if (st == NULL || st->keys == NULL) {
        return FW_ERR_INVAL;
    }
    cmac_config_t cfg = {0};
    cfg.n_inputs = sp->n_components;
    for (uint32_t k = 0; k < sp->n_components; k++) {
        if (tile_shift[k] > PAPER_MAX_TILE_SHIFT) {
            return FW_ERR_INVAL;
        }
        cfg.input_bits[k] = sp->bits[k];
        cfg.tile_shift[k] = tile_shift[k];
    }
    cfg.circular_mask = sp->circular_mask;
    cfg.n_actions = sp->n_actions;
    cfg.n_tilings = tilings;
    cfg.n_outputs = n_outputs;
    cfg.learning_rate = rate;
    return cmac_init(c, &cfg, st->keys, st->counts, st->weights, st->cells);
}

int paper_model_init(paper_model_t *m, const agent_space_t *space, const uint8_t *tile_shift,
                     uint8_t tilings, float rate, uint8_t min_count, const paper_model_storage_t *st)
{
    if (m == NULL || space == NULL || tile_shift == NULL || st == NULL || min_count < 1u) {
        return FW_ERR_INVAL;
    }
    int err = init_cmac_(&m->forward, space, tile_shift, tilings, rate,
                         (uint8_t)(space->n_components + 2u), &st->forward);
    if (err == FW_OK) {
        err = init_cmac_(&m->inverse, space, tile_shift, tilings, rate,
                         (uint8_t)(space->n_components + 1u), &st->inverse);
    }
    if (err != FW_OK) {
        return FW_ERR_INVAL;
    }
    m->space = space;
    m->min_count = min_count;
    paper_model_clear(m);
    return FW_OK;
}

void paper_model_clear(paper_model_t *m)
{
    cmac_clear(&m->forward);
    cmac_clear(&m->inverse);
    m->last_valid = 0;
    m->last_action = 0;
    m->last_state = m->last_next = 0;
    m->untrusted = m->rejected = 0;
}

bool paper_model_learn(paper_model_t *m, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                       bool terminal)
{
    const agent_space_t *sp = m->space;
    const uint32_t n = sp->n_components;
    uint32_t comp[FW_CFG_MAX_COMPONENTS], next[FW_CFG_MAX_COMPONENTS];
    int32_t desired[CMAC_MAX_OUTPUTS];
    cmac_tiles_t tiles;
    space_unpack(sp, s, comp);
    space_unpack(sp, s_next, next);

    // CMAC-Model: (s, a) -> (s' as changes, r, terminal).
    for (uint32_t k = 0; k < n; k++) {
        desired[k] = space_change(sp, k, comp[k], next[k]) * CMAC_ONE;
    }
    const float rq = r * (float)CMAC_ONE;
    desired[n] = (int32_t)(rq < 0.0f ? rq - 0.5f : rq + 0.5f);
    desired[n + 1u] = terminal ? CMAC_ONE : 0;
    cmac_tiles_of(&m->forward, comp, a, &tiles);
    const bool stored = cmac_train(&m->forward, &tiles, desired);

    // CMAC-R: (s, a) -> the pair that led into s, when the last step did.
    if (m->last_valid && m->last_next == s) {
        uint32_t before[FW_CFG_MAX_COMPONENTS];
        space_unpack(sp, m->last_state, before);
        for (uint32_t k = 0; k < n; k++) {
            desired[k] = space_change(sp, k, comp[k], before[k]) * CMAC_ONE;
        }
        desired[n] = (int32_t)m->last_action * CMAC_ONE;
        cmac_tiles_of(&m->inverse, comp, a, &tiles);
        (void)cmac_train(&m->inverse, &tiles, desired);
    }
    m->last_valid = terminal ? 0u : 1u;
    m->last_state = s;
    m->last_action = a;
    m->last_next = s_next;
    return stored;
}

// CMAC-Model's prediction for comp[] (the state s) and a, through the trust gate.
static bool predict_(paper_model_t *m, agent_state_t s, const uint32_t *comp, uint8_t a,
                     model_step_t *out)
{
    const agent_space_t *sp = m->space;
    int32_t y[CMAC_MAX_OUTPUTS];
    uint32_t next[FW_CFG_MAX_COMPONENTS];
    cmac_tiles_t tiles;
    (void)s;
    cmac_tiles_of(&m->forward, comp, a, &tiles);
    if (cmac_predict(&m->forward, &tiles, y) < m->min_count || !apply_(sp, comp, y, next)) {
        m->untrusted++;
        return false;
    }
    out->next = space_pack(sp, next);
    out->reward = (float)y[sp->n_components] / (float)CMAC_ONE;
    out->terminal = y[sp->n_components + 1u] * 2 > CMAC_ONE ? 1u : 0u;
    out->others = 0;
    return true;
}

bool paper_model_predict(paper_model_t *m, agent_state_t s, uint8_t a, model_step_t *out)
{
    uint32_t comp[FW_CFG_MAX_COMPONENTS];
    space_unpack(m->space, s, comp);
    return predict_(m, s, comp, a, out);
}

uint32_t paper_model_predecessors(paper_model_t *m, agent_state_t s, model_pred_t *out)
{
    const agent_space_t *sp = m->space;
    uint32_t comp[FW_CFG_MAX_COMPONENTS], before[FW_CFG_MAX_COMPONENTS];
    int32_t y[CMAC_MAX_OUTPUTS];
    cmac_tiles_t tiles;
    uint32_t found = 0;
    space_unpack(sp, s, comp);
    cmac_tiles_of(&m->inverse, comp, 0u, &tiles);
    for (uint32_t a = 0; a < sp->n_actions; a++) {
        cmac_tiles_set_action(&m->inverse, &tiles, a);
        if (cmac_predict(&m->inverse, &tiles, y) < m->min_count || !apply_(sp, comp, y, before)) {
            m->untrusted++;
            continue;
        }
        const int32_t pa = round_q_(y[sp->n_components]);
        if (pa < 0 || pa >= (int32_t)sp->n_actions) {
            m->untrusted++;
            continue;
        }
        const agent_state_t ps = space_pack(sp, before);
        uint32_t i = 0;
        while (i < found && !(out[i].state == ps && out[i].action == (uint8_t)pa)) {
            i++;
        }
        if (i < found) {
            continue;  // named through another action already
        }
        model_step_t step;
        if (!predict_(m, ps, before, (uint8_t)pa, &step)) {
            continue;
        }
        if (step.next != s || step.terminal) {
            m->rejected++;
            continue;
        }
        out[found].state = ps;
        out[found].action = (uint8_t)pa;
        out[found].others = 0;
        out[found].reward = step.reward;
        found++;
    }
    return found;
}

uint32_t paper_model_regions(const paper_model_t *m, agent_region_t *out)
{
    const uint32_t n = cmac_regions(&m->forward, out);
    return n + cmac_regions(&m->inverse, out + n);
}

int paper_model_check(const paper_model_t *m, const void *const *image)
{
    if (cmac_check(&m->forward, image) != FW_OK || cmac_check(&m->inverse, image + CMAC_REGIONS) != FW_OK) {
        return FW_ERR_CORRUPT;
    }
    return FW_OK;
}

void paper_model_restored(paper_model_t *m)
{
    cmac_restored(&m->forward);
    cmac_restored(&m->inverse);
    m->last_valid = 0;
}
