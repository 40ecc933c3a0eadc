// SPDX-License-Identifier: MIT
// dynaqpc: CMAC-Model and CMAC-R, and what makes their predictions trustworthy.
#include "agent/model.h"

#include <stddef.h>

#include "fw/fw_base.h"

static void cmac_config_for_(cmac_config_t *c, const agent_space_t *sp, uint8_t tilings,
                             float rate, uint8_t n_outputs)
{
    *c = (cmac_config_t){0};
    c->n_inputs = sp->n_components;
    for (uint32_t k = 0; k < sp->n_components; k++) {
        c->input_bits[k] = sp->bits[k];
        c->tile_shift[k] = sp->tile_shift[k];
    }
    c->circular_mask = sp->circular_mask;
    c->n_actions = sp->n_actions;
    c->n_tilings = tilings;
    c->n_outputs = n_outputs;
    c->learning_rate = rate;
}

int model_init(world_model_t *m, const agent_space_t *space, uint8_t tilings,
               float learning_rate, uint8_t min_count, const model_cmac_storage_t *fwd,
               const model_cmac_storage_t *inv)
{
    if (m == NULL || fwd == NULL || inv == NULL || space_validate(space) != FW_OK ||
        min_count < 1u) {
        return FW_ERR_INVAL;
    }
    m->space = space;
    m->min_count = min_count;
    for (uint32_t k = 0; k < space->n_components; k++) {
        // A change wraps around a circular component; a value predicted as such does not.
        const bool absolute = (space->absolute_mask >> k) & 1u;
        const bool circular = (space->circular_mask >> k) & 1u;
        m->field[k].keep_from = absolute ? 0u : UINT32_MAX;
        m->field[k].wrap = circular && !absolute ? (1u << space->bits[k]) - 1u : UINT32_MAX;
    }
    cmac_config_t c;
    cmac_config_for_(&c, space, tilings, learning_rate, (uint8_t)(space->n_components + 2u));
    int err = cmac_init(&m->forward, &c, fwd->keys, fwd->counts, fwd->weights, fwd->cells);
    if (err) {
        return err;
    }
    cmac_config_for_(&c, space, tilings, learning_rate, space->n_components);
    err = cmac_init(&m->inverse, &c, inv->keys, inv->counts, inv->weights, inv->cells);
    if (err) {
        return err;
    }
    m->untrusted = 0;
    m->rejected = 0;
    return FW_OK;
}

void model_clear(world_model_t *m)
{
    cmac_clear(&m->forward);
    cmac_clear(&m->inverse);
    m->untrusted = 0;
    m->rejected = 0;
}

// ---- Encoding states as CMAC outputs ------------------------------------------------------------

static int32_t to_fixed_(float x)
{
    const float scaled = x * (float)CMAC_ONE;
    return (int32_t)(scaled >= 0.0f ? scaled + 0.5f : scaled - 0.5f);
}

// Nearest integer of a fixed-point value, halves away from zero, as a two's complement word (a
// negative is huge): floor((x + 128) / 256) for x >= 0, floor((x + 127) / 256) below. Both floors
// are taken of x + 2^31, which is never negative, and the 2^23 that adds is taken off again: no
// signed value is shifted (implementation-defined in C99), and no branch is taken. Needs
// |x| < 2^31 - 128; a prediction is a sum of at most 16 int16 weights, below 2^20.
static uint32_t round_fixed_(int32_t x)
{
    const uint32_t biased = (uint32_t)x + 0x80000000u + CMAC_ONE / 2u - ((uint32_t)x >> 31);
    return (biased >> CMAC_FRAC_BITS) - (0x80000000u >> CMAC_FRAC_BITS);
}

// The desired output for moving from `from` to `to`: per component, the change (wrapped to the
// shorter way round for a circular one) or, for an absolute component, the new value.
static void encode_(const agent_space_t *sp, const uint32_t *from, const uint32_t *to,
                    int32_t *out)
{
    for (uint32_t k = 0; k < sp->n_components; k++) {
        int32_t v;
        if ((sp->absolute_mask >> k) & 1u) {
            v = (int32_t)to[k];
        } else {
            v = (int32_t)to[k] - (int32_t)from[k];
            if ((sp->circular_mask >> k) & 1u) {
                const int32_t range = (int32_t)1 << sp->bits[k];
                if (v >= range / 2) {
                    v -= range;
                } else if (v < -range / 2) {
                    v += range;
                }
            }
        }
        out[k] = v * CMAC_ONE;
    }
}

// The inverse of encode_(): the components of the state `pred` leads to from `from`, into `to`,
// and that state packed. False if a component falls outside its range. (A planning update
// decodes about ten components: each component's kind is applied by masks, without a branch.)
static bool decode_(const world_model_t *m, const uint32_t *from, const int32_t *pred,
                    uint32_t *to, agent_state_t *packed)
{
    const uint8_t *bits = m->space->bits;
    const uint8_t *const end = bits + m->space->n_components;
    const model_field_t *field = m->field;
    agent_state_t s = 0;
    uint32_t shift = 0;
    do {
        const uint32_t b = *bits++;
        const uint32_t v = (round_fixed_(*pred++) + (*from++ & field->keep_from)) & field->wrap;
        field++;
        if (v >> b) {  // below 0 or past the range
            return false;
        }
        *to++ = v;
        s |= v << shift;
        shift += b;
    } while (bits != end);
    *packed = s;
    return true;
}

// Whether `pred` leads from `from` to exactly the components `to`: decode_() compared instead of
// stored, for a predecessor's confirmation.
static bool leads_to_(const world_model_t *m, const uint32_t *from, const int32_t *pred,
                      const uint32_t *to)
{
    const model_field_t *field = m->field;
    const model_field_t *const end = field + m->space->n_components;
    do {
        const uint32_t v = (round_fixed_(*pred++) + (*from++ & field->keep_from)) & field->wrap;
        if (v != *to++) {
            return false;
        }
    } while (++field != end);
    return true;
}

// ---- Learning and predicting ---------------------------------------------------------------------

bool model_learn(world_model_t *m, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                 bool terminal)
{
    const agent_space_t *sp = m->space;
    uint32_t from[FW_CFG_MAX_COMPONENTS];
    uint32_t to[FW_CFG_MAX_COMPONENTS];
    int32_t desired[CMAC_MAX_OUTPUTS];
    cmac_tiles_t tiles;

    space_unpack(sp, s, from);
    space_unpack(sp, s_next, to);

    encode_(sp, from, to, desired);
    desired[sp->n_components] = to_fixed_(r);
    desired[sp->n_components + 1u] = terminal ? CMAC_ONE : 0;
    cmac_tiles_of(&m->forward, from, a, &tiles);
    const bool stored = cmac_train(&m->forward, &tiles, desired);

    // A step that leaves the state as it was (a bump into a wall) is no route from anywhere;
    // teaching it to CMAC-R would overwrite the real predecessor that arrives by the same action.
    if (s_next != s) {
        encode_(sp, to, from, desired);
        cmac_tiles_of(&m->inverse, to, a, &tiles);
        (void)cmac_train(&m->inverse, &tiles, desired);
    }
    return stored;
}

// CMAC-Model's prediction for taking `a` in the state `from` (its components, and its tiles for
// any action): the next state's components go to `to` and packed to `next`, the raw outputs to
// `pred`. Counts a refusal in `untrusted`.
static bool predict_(world_model_t *m, const uint32_t *from, const cmac_tiles_t *tiles, uint32_t a,
                     uint32_t *to, agent_state_t *next, int32_t *pred)
{
    if (!cmac_predict_trusted(&m->forward, tiles, a, m->min_count, pred) ||
        !decode_(m, from, pred, to, next)) {
        m->untrusted++;
        return false;
    }
    return true;
}

void model_query_init(const world_model_t *m, agent_state_t s, model_query_t *q)
{
    q->state = s;
    space_unpack(m->space, s, q->comp);
    cmac_tiles_of(&m->forward, q->comp, 0, &q->tiles);
}

bool model_query_predict(world_model_t *m, const model_query_t *q, uint8_t a, model_step_t *out)
{
    const uint32_t n_comp = m->space->n_components;
    int32_t pred[CMAC_MAX_OUTPUTS];
    uint32_t to[FW_CFG_MAX_COMPONENTS];

    if (!predict_(m, q->comp, &q->tiles, a, to, &out->next, pred)) {
        return false;
    }
    out->reward = (float)pred[n_comp] / (float)CMAC_ONE;
    out->terminal = (uint8_t)(pred[n_comp + 1u] >= CMAC_ONE / 2);
    return true;
}

bool model_predict(world_model_t *m, agent_state_t s, uint8_t a, model_step_t *out)
{
    model_query_t q;
    model_query_init(m, s, &q);
    return model_query_predict(m, &q, a, out);
}

uint32_t model_query_predecessors(world_model_t *m, const model_query_t *q, model_pred_t *out,
                                  model_query_t *const *queries)
{
    const agent_space_t *sp = m->space;
    const uint32_t n_comp = sp->n_components;
    uint32_t back[FW_CFG_MAX_COMPONENTS];
    int32_t pred[CMAC_MAX_OUTPUTS];
    model_query_t scratch;
    agent_state_t back_state;
    uint32_t n = 0;

    for (uint32_t a = 0; a < sp->n_actions; a++) {
        // The predecessor's query is built where it is kept if it is confirmed.
        model_query_t *const prev = queries != NULL ? queries[n] : &scratch;
        // CMAC-R shares CMAC-Model's key layout: the query's tiles serve both.
        if (!cmac_predict_trusted(&m->inverse, &q->tiles, a, m->min_count, pred) ||
            !decode_(m, q->comp, pred, prev->comp, &prev->state)) {
            continue;  // nothing trained arrives here by a: the common case, not worth counting
        }
        // CMAC-R averages when several states lead here by the same action; only a predecessor
        // that CMAC-Model confirms is a real one. The forward lookup also gives its reward.
        cmac_tiles_of(&m->forward, prev->comp, a, &prev->tiles);
        if (!cmac_predict_trusted(&m->forward, &prev->tiles, a, m->min_count, pred)) {
            m->untrusted++;
            m->rejected++;
            continue;
        }
        if (pred[n_comp + 1u] >= CMAC_ONE / 2 || !leads_to_(m, prev->comp, pred, q->comp)) {
            if (!decode_(m, prev->comp, pred, back, &back_state)) {
                m->untrusted++;  // as model_predict() counts a prediction out of range
            }
            m->rejected++;
            continue;
        }
        out[n].state = prev->state;
        out[n].action = (uint8_t)a;
        out[n].reward = (float)pred[n_comp] / (float)CMAC_ONE;
        n++;
    }
    return n;
}

uint32_t model_predecessors(world_model_t *m, agent_state_t s, model_pred_t *out)
{
    model_query_t q;
    model_query_init(m, s, &q);
    return model_query_predecessors(m, &q, out, NULL);
}
