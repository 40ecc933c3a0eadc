// SPDX-License-Identifier: MIT
// dynaqpc: CMAC-Model, the relocatable action model, the predecessor search, and what makes a
// prediction trustworthy.
#include "agent/model.h"

#include <stddef.h>
#include <string.h>

#include "fw/fw_base.h"
#include "inline.h"

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

// ---- Packing places, situations and positions ----------------------------------------------------

// The components of `comp` selected by `mask`, packed in order into one index.
static uint32_t pack_masked_(const agent_space_t *sp, const uint32_t *comp, uint32_t mask)
{
    uint32_t index = 0;
    uint32_t shift = 0;
    for (uint32_t k = 0; k < sp->n_components; k++) {
        if ((mask >> k) & 1u) {
            index |= comp[k] << shift;
            shift += sp->bits[k];
        }
    }
    return index;
}

// The inverse of pack_masked_() for the components in `mask`; the others are left as they are.
static void unpack_masked_(const agent_space_t *sp, uint32_t index, uint32_t mask, uint32_t *comp)
{
    for (uint32_t k = 0; k < sp->n_components; k++) {
        if ((mask >> k) & 1u) {
            comp[k] = index & ((1u << sp->bits[k]) - 1u);
            index >>= sp->bits[k];
        }
    }
}

static uint32_t masked_bits_(const agent_space_t *sp, uint32_t mask)
{
    uint32_t bits = 0;
    for (uint32_t k = 0; k < sp->n_components; k++) {
        bits += (mask >> k) & 1u ? sp->bits[k] : 0u;
    }
    return bits;
}

static uint32_t all_mask_(const agent_space_t *sp)
{
    return (1u << sp->n_components) - 1u;
}

static uint32_t lowest_bit_(uint32_t x)  // x != 0
{
#if defined(__GNUC__)
    return (uint32_t)__builtin_ctz(x);
#else
    uint32_t v = 0;
    while (!((x >> v) & 1u)) {
        v++;
    }
    return v;
#endif
}

static uint32_t masked_bits_from_(uint32_t run)  // how many ones
{
    uint32_t n = 0;
    for (; run != 0u; run &= run - 1u) {
        n++;
    }
    return n;
}

static void select_init_(const agent_space_t *sp, uint32_t components, model_select_t *sel)
{
    uint32_t shift = 0;
    for (uint32_t k = 0; k < sp->n_components && !((components >> k) & 1u); k++) {
        shift += sp->bits[k];
    }
    const uint32_t bits = masked_bits_(sp, components);
    const uint32_t run = components != 0u ? components >> lowest_bit_(components) : 0u;
    sel->components = components;
    sel->mask = bits < 32u ? (1u << bits) - 1u : UINT32_MAX;
    sel->shift = (uint8_t)shift;
    sel->adjacent = (uint8_t)((run & (run + 1u)) == 0u);
    sel->first = (uint8_t)(components != 0u ? lowest_bit_(components) : 0u);
    sel->last = (uint8_t)(sel->first + masked_bits_from_(run) - 1u);
}

// The index of the selected components of a state, given packed (`s`) and split (`comp`): the
// planner's tables are indexed by parts of states millions of times, and in the shipped robot
// each part is a run of adjacent components, one shift and one mask.
AGENT_ALWAYS_INLINE uint32_t select_(const world_model_t *m, const model_select_t *sel,
                                     agent_state_t s, const uint32_t *comp)
{
    if (sel->adjacent) {
        return (s >> sel->shift) & sel->mask;
    }
    return pack_masked_(m->space, comp, sel->components);
}

// Sets the absolute components of a state to the percept `v` (an index as percept_of packs
// it), in both forms.
AGENT_ALWAYS_INLINE void set_percept_(const world_model_t *m, uint32_t v, agent_state_t *s,
                                      uint32_t *comp)
{
    const model_select_t *sel = &m->percept_of;
    if (sel->components == 0u) {
        return;
    }
    if (sel->adjacent) {
        *s = (*s & ~(sel->mask << sel->shift)) | (v << sel->shift);
        for (uint32_t k = sel->first; k <= sel->last; k++) {
            comp[k] = v & ((1u << m->space->bits[k]) - 1u);
            v >>= m->space->bits[k];
        }
    } else {
        unpack_masked_(m->space, v, sel->components, comp);
        *s = space_pack(m->space, comp);
    }
}

// State s with its percept set to `v`, packed form only.
static agent_state_t with_percept_(const world_model_t *m, agent_state_t s, uint32_t v)
{
    const model_select_t *sel = &m->percept_of;
    if (sel->adjacent) {
        return (s & ~(sel->mask << sel->shift)) | (v << sel->shift);
    }
    uint32_t comp[FW_CFG_MAX_COMPONENTS];
    space_unpack(m->space, s, comp);
    set_percept_(m, v, &s, comp);
    return s;
}

/// A place the percept map does not keep (its heading lies between the motion's turns).
#define NO_PLACE_ UINT32_MAX

// The percept map's index of the place of s: the place's components packed, with the low
// turn_step_bits of the heading (always 0 once the robot has turned) squeezed out. Without a
// turn step it is the packed place itself.
AGENT_ALWAYS_INLINE uint32_t place_(const world_model_t *m, agent_state_t s, const uint32_t *comp)
{
    const uint32_t p = select_(m, &m->place_of, s, comp);
    if ((p & m->place_gap) != 0u) {
        return NO_PLACE_;
    }
    return (p & m->place_low) | ((p >> m->place_gap_bits) & ~m->place_low);
}

// The percepts seen at the place of s (a mask; 0 for a place the map does not keep).
AGENT_ALWAYS_INLINE uint32_t seen_at_(const world_model_t *m, agent_state_t s, const uint32_t *comp)
{
    const uint32_t place = place_(m, s, comp);
    return place == NO_PLACE_ ? 0u : m->percepts[place];
}

// Notes that the absolute components of s were perceived at its place.
static void perceive_(world_model_t *m, agent_state_t s, const uint32_t *comp)
{
    const uint32_t place = place_(m, s, comp);
    if (place != NO_PLACE_) {
        m->percepts[place] |= (uint16_t)(1u << select_(m, &m->percept_of, s, comp));
    }
}

static model_class_t *class_of_(const world_model_t *m, agent_state_t s, const uint32_t *comp,
                                uint32_t a)
{
    return &m->classes[select_(m, &m->situation_of, s, comp) * m->space->n_actions + a];
}

FW_STATIC_ASSERT(MODEL_MAX_PERCEPTS == 1u << SPACE_MAX_ABSOLUTE_BITS, a_percept_class_per_value);

static model_class_t *percept_class_of_(world_model_t *m, agent_state_t s, const uint32_t *comp,
                                        uint32_t a)
{
    return &m->percept_classes[select_(m, &m->percept_of, s, comp) * m->space->n_actions + a];
}

// ---- Set-up ---------------------------------------------------------------------------------------

int model_init(world_model_t *m, const agent_space_t *space, uint8_t tilings,
               float learning_rate, uint8_t min_count, const model_cmac_storage_t *fwd,
               const model_reloc_storage_t *reloc)
{
    if (m == NULL || fwd == NULL || reloc == NULL || space_validate(space) != FW_OK ||
        min_count < 1u) {
        return FW_ERR_INVAL;
    }
    const uint32_t all = all_mask_(space);
    // The percept map keeps every place when the storage has room for them all (so a start's
    // heading before its first turn is mapped too), else only the headings turns reach.
    const uint32_t every_place_bits = masked_bits_(space, all & ~(uint32_t)space->absolute_mask);
    const uint32_t gap_bits =
        every_place_bits <= 24u && reloc->places >= (1u << every_place_bits) ? 0u
                                                                             : space->turn_step_bits;
    const uint32_t place_bits = every_place_bits - gap_bits;
    const uint32_t context_bits = masked_bits_(space, space->context_mask);
    const uint32_t position_bits =
        masked_bits_(space, all & ~(uint32_t)(space->absolute_mask | space->context_mask));
    if (space->absolute_mask != 0u &&
        (reloc->percepts == NULL || place_bits > 24u || reloc->places < (1u << place_bits))) {
        return FW_ERR_INVAL;
    }
    if (space->context_mask != 0u &&
        (reloc->classes == NULL || reloc->arrivals == NULL || context_bits > 16u ||
         reloc->n_classes < (1u << context_bits) * space->n_actions ||
         position_bits > 24u || reloc->positions < (1u << position_bits))) {
        return FW_ERR_INVAL;
    }
    m->space = space;
    m->min_count = min_count;
    m->ablate = 0;
    m->stay_reward = MODEL_NO_STAY;
    for (uint32_t k = 0; k < space->n_components; k++) {
        // A change wraps around a circular component; a value predicted as such does not.
        const bool absolute = (space->absolute_mask >> k) & 1u;
        const bool circular = (space->circular_mask >> k) & 1u;
        m->field[k].keep_from = absolute ? 0u : UINT32_MAX;
        m->field[k].wrap = circular && !absolute ? (1u << space->bits[k]) - 1u : UINT32_MAX;
        m->field[k].shift = k == 0u ? 0u : m->field[k - 1u].shift + space->bits[k - 1u];
        m->field[k].bits = space->bits[k];
    }
    select_init_(space, all & ~(uint32_t)space->absolute_mask, &m->place_of);
    select_init_(space, all & ~(uint32_t)(space->absolute_mask | space->context_mask),
                 &m->position_of);
    select_init_(space, space->context_mask, &m->situation_of);
    select_init_(space, space->context_mask & ~(uint32_t)space->absolute_mask, &m->heading_of);
    select_init_(space, space->absolute_mask, &m->percept_of);
    cmac_config_t c;
    cmac_config_for_(&c, space, tilings, learning_rate, (uint8_t)(space->n_components + 2u));
    const int err = cmac_init(&m->forward, &c, fwd->keys, fwd->counts, fwd->weights, fwd->cells);
    if (err) {
        return err;
    }
    m->percepts = space->absolute_mask != 0u ? reloc->percepts : NULL;
    m->places = space->absolute_mask != 0u ? 1u << place_bits : 0u;
    // The heading's offset in a place index: the bits of the place components below it.
    const uint32_t below = gap_bits != 0u
                               ? masked_bits_(space, (space->circular_mask - 1u) &
                                                         ~(uint32_t)space->absolute_mask)
                               : 0u;
    m->place_gap_bits = (uint8_t)gap_bits;
    m->place_gap = ((1u << gap_bits) - 1u) << below;
    m->place_low = (1u << below) - 1u;
    m->classes = space->context_mask != 0u ? reloc->classes : NULL;
    m->n_classes = space->context_mask != 0u ? (1u << context_bits) * space->n_actions : 0u;
    m->arrivals = space->context_mask != 0u ? reloc->arrivals : NULL;
    m->positions = space->context_mask != 0u ? 1u << position_bits : 0u;
    m->n_percept_classes = space->context_mask != 0u && space->absolute_mask != 0u
                               ? (1u << masked_bits_(space, space->absolute_mask)) * space->n_actions
                               : 0u;
    model_clear(m);
    return FW_OK;
}

// Every table but the arrivals is integers whose empty value is 0, so a memset clears it: a
// fresh agent and a RESET_LEARNING clear up to ~50 KB (paper-sim's places), and element loops
// cost several times as much where the compiler does not turn them into memset itself (the
// fuzz preset's instrumented builds: a fifth of the firmware target's time).
void model_clear(world_model_t *m)
{
    FW_ASSERT(m != NULL);
    cmac_clear(&m->forward);
    if (m->places > 0u) {
        memset(m->percepts, 0, m->places * sizeof *m->percepts);
    }
    if (m->n_classes > 0u) {
        memset(m->classes, 0, m->n_classes * sizeof *m->classes);
    }
    for (uint32_t i = 0; i < m->positions; i++) {
        m->arrivals[i] = MODEL_NO_ARRIVAL;
    }
    memset(m->deltas, 0, sizeof m->deltas);
    memset(m->percept_classes, 0, m->n_percept_classes * sizeof *m->percept_classes);
    m->untrusted = 0;
    m->rejected = 0;
    m->generalised = 0;
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

// The desired output for moving from `from` to `to`: per component, its change (space_change:
// wrapped to the shorter way round for a circular one; for an absolute component, the new value).
static void encode_(const agent_space_t *sp, const uint32_t *from, const uint32_t *to,
                    int32_t *out)
{
    for (uint32_t k = 0; k < sp->n_components; k++) {
        out[k] = space_change(sp, k, from[k], to[k]) * CMAC_ONE;
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

// ---- Learning and predicting ---------------------------------------------------------------------

static bool same_delta_(const int8_t *x, const int8_t *y)
{
    for (uint32_t k = 0; k < FW_CFG_MAX_COMPONENTS; k++) {
        if (x[k] != y[k]) {
            return false;
        }
    }
    return true;
}

// The change from `from` to `to` of every component but the absolute ones (those are 0),
// circular ones the shorter way round. False if a change does not fit an int8.
static bool delta_of_(const agent_space_t *sp, const uint32_t *from, const uint32_t *to,
                      int8_t *delta)
{
    int32_t d[FW_CFG_MAX_COMPONENTS];
    encode_(sp, from, to, d);
    for (uint32_t k = 0; k < FW_CFG_MAX_COMPONENTS; k++) {
        const int32_t v = k < sp->n_components && !((sp->absolute_mask >> k) & 1u) ? d[k] / CMAC_ONE : 0;
        if (v < -128 || v > 127) {
            return false;
        }
        delta[k] = (int8_t)v;
    }
    return true;
}

// The bucket of changes that arrive in the state `to` (its heading).
static uint32_t delta_bucket_(const world_model_t *m, agent_state_t to, const uint32_t *comp)
{
    return select_(m, &m->heading_of, to, comp) % MODEL_DELTA_BUCKETS;
}

// Keeps the change an action made, so that predecessors can be searched by undoing it; a full
// list replaces the change seen least often.
static void remember_delta_(world_model_t *m, uint32_t a, agent_state_t s_to, const uint32_t *to,
                            const int8_t *delta)
{
    model_delta_t *list = m->deltas[a][delta_bucket_(m, s_to, to)];
    model_delta_t *least = &list[0];
    for (uint32_t i = 0; i < MODEL_MAX_DELTAS; i++) {
        if (list[i].count != 0u && same_delta_(list[i].delta, delta)) {
            if (list[i].count < UINT16_MAX) {
                list[i].count++;
            }
            return;
        }
        if (list[i].count < least->count) {
            least = &list[i];
        }
    }
    for (uint32_t k = 0; k < FW_CFG_MAX_COMPONENTS; k++) {
        least->delta[k] = delta[k];
    }
    least->count = 1;
}

static bool moves_(const int8_t *delta);

// Counts are halved together when one would pass 255, so their ratios stay.
static void halve_class_(model_class_t *c)
{
    c->count /= 2u;
    c->miss /= 2u;
    c->stay /= 2u;
}

// One observation of a situation's outcome: it agrees with the kept outcome, or counts against
// it; an outcome disagreed with more often than agreed with is replaced by the new one. With
// `stays`, a change of nothing that earns what a kept move earns is a stay, counted beside the
// move (the step ended in the cell it began in); a move that earns what a kept change of
// nothing earned shows that those observations were stays of it.
static void train_class_(model_class_t *c, const int8_t *delta, int16_t reward, bool stays)
{
    if (stays && c->count != 0u && c->reward == reward && moves_(c->delta) != moves_(delta)) {
        if (!moves_(delta)) {
            if (c->stay == UINT8_MAX) {
                halve_class_(c);
            }
            c->stay++;
            return;
        }
        const uint32_t stayed = (uint32_t)c->stay + c->count;
        c->stay = (uint8_t)(stayed > UINT8_MAX ? UINT8_MAX : stayed);
        for (uint32_t k = 0; k < FW_CFG_MAX_COMPONENTS; k++) {
            c->delta[k] = delta[k];
        }
        c->count = 1;
        c->miss = 0;
        return;
    }
    if (c->count != 0u && same_delta_(c->delta, delta) && c->reward == reward) {
        if (c->count == UINT8_MAX) {  // keep the ratio, make room
            halve_class_(c);
        }
        c->count++;
        return;
    }
    if (c->count != 0u && c->miss < c->count) {
        c->miss++;
        return;
    }
    for (uint32_t k = 0; k < FW_CFG_MAX_COMPONENTS; k++) {
        c->delta[k] = delta[k];
    }
    c->reward = reward;
    c->count = 1;
    c->miss = 0;
}

// CMAC-Model's prediction for taking `a` in the state `from` (its components, and its tiles for
// any action): the next state, the reward and the terminal flag to `out`. False if (s, a) was not tried (a cell trained fewer than min_count
// times) or the prediction leaves the space.
static bool predict_exact_(const world_model_t *m, const uint32_t *from, const cmac_tiles_t *tiles,
                           uint32_t a, model_step_t *out)
{
    int32_t pred[CMAC_MAX_OUTPUTS];
    uint32_t to[FW_CFG_MAX_COMPONENTS];
    const uint32_t n_comp = m->space->n_components;
    if (!cmac_predict_trusted(&m->forward, tiles, a, m->min_count, pred) ||
        !decode_(m, from, pred, to, &out->next)) {
        return false;
    }
    out->reward = (float)pred[n_comp] / (float)CMAC_ONE;
    out->terminal = (uint8_t)(pred[n_comp + 1u] >= CMAC_ONE / 2);
    out->others = 0;
    out->stay = 0;
    return true;
}

static int16_t reward_fixed_(float r, bool *fits)
{
    const int32_t v = to_fixed_(r);
    *fits = v >= -32767 && v <= 32767;
    return (int16_t)(*fits ? v : 0);
}

bool model_learn(world_model_t *m, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                 bool terminal)
{
    FW_ASSERT(m != NULL && m->space != NULL && a < m->space->n_actions);
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
    // Stochastic outcomes: a tried pair keeps the outcome most of its observations agreed on. An
    // observation that contradicts the kept outcome counts against it (cmac_contradict()) and
    // replaces it only once as many observations disagreed as agreed; CMAC-Model's learning rule
    // alone (rate 0.999) would predict whatever happened last.
    // A stay (model.h) of a tried move leaves its outcome as it is; a move where only stays were
    // seen replaces them at once. Only with the relocatable model, whose situations count the
    // stays: in a gridworld a move into a wall is an outcome (and earns what moves earn).
    model_step_t kept;
    bool ordinary;  // the reward of an ordinary step: it marks a stay
    ordinary = reward_fixed_(r, &ordinary) == m->stay_reward && ordinary;
    const bool stays = m->classes != NULL && (m->ablate & MODEL_ABLATE_STAY) == 0u && ordinary;
    const bool tried = predict_exact_(m, from, &tiles, a, &kept);
    const bool same_reward = tried && kept.reward - r <= 0.5f && r - kept.reward <= 0.5f;
    const bool stay_of_move = stays && same_reward && !terminal && !kept.terminal && s_next == s;
    const bool kept_stays = kept.next == s;  // only read when tried
    const bool move_of_stay = stays && same_reward && !terminal && !kept.terminal && s_next != s &&
                              kept_stays;
    const bool contradicts =
        (m->ablate & MODEL_ABLATE_MAJORITY) == 0u && tried && !move_of_stay &&
        (kept.next != s_next || kept.terminal != (uint8_t)terminal || !same_reward);
    const bool stored =
        (stay_of_move && !kept_stays) ||
        (contradicts && cmac_contradict(&m->forward, &tiles)) || cmac_train(&m->forward, &tiles, desired);

    if (m->percepts != NULL) {
        perceive_(m, s, from);
        perceive_(m, s_next, to);
    }
    int8_t delta[FW_CFG_MAX_COMPONENTS];
    bool fits = delta_of_(sp, from, to, delta);
    if (fits) {
        remember_delta_(m, a, s_next, to, delta);
    }
    const int16_t reward = reward_fixed_(r, &fits);
    if (m->classes != NULL && fits) {
        if (terminal) {
            // Where an episode ends is a fact about the place, not about the situation.
            m->arrivals[select_(m, &m->position_of, s_next, to)] = reward;
        } else {
            train_class_(class_of_(m, s, from, a), delta, reward, stays);
            if (m->n_percept_classes != 0u) {
                train_class_(percept_class_of_(m, s, from, a), delta, reward, stays);
            }
        }
    }
    return stored;
}

// A situation's outcome is always the majority of its observations (train_class_()); it is
// trusted once seen MODEL_CLASS_MIN_COUNT times, however often it was contradicted. (A gate on
// the share of contradictions, at most 1 in 8, predicted less and learned slower on the tuning
// rooms: 804 against 586 real steps to learn, 108 sets; docs/agent.md.)
static bool class_trusted_(const model_class_t *c)
{
    return (uint32_t)c->count + c->stay >= MODEL_CLASS_MIN_COUNT;  // a stay is of its move
}

// Applies a change (undoes it, for `sign` -1) to every non-absolute component of `from`, into
// `to` and packed into `*s` (absolute ones copied). False if a component leaves its range (a
// circular one wraps). Inlined with a constant sign: the predecessor search undoes about six
// changes per planning update.
AGENT_ALWAYS_INLINE bool apply_delta_(const world_model_t *m, const uint32_t *from,
                                      const int8_t *delta, const int32_t sign, uint32_t *to,
                                      agent_state_t *s)
{
    const model_field_t *field = m->field;
    const model_field_t *const end = field + m->space->n_components;
    agent_state_t packed = 0;
    for (; field != end; field++, from++, delta++, to++) {
        const uint32_t d = (uint32_t)(int32_t)*delta;
        const uint32_t v = (sign > 0 ? *from + d : *from - d) & field->wrap;
        if (v >> field->bits) {  // below 0 or past the range
            return false;
        }
        *to = v;
        packed |= v << field->shift;
    }
    *s = packed;
    return true;
}

static bool moves_(const int8_t *delta)
{
    uint32_t any = 0;
    for (uint32_t k = 0; k < FW_CFG_MAX_COMPONENTS; k++) {
        any |= (uint8_t)delta[k];
    }
    return any != 0u;
}

static float agent_absf_(float x)
{
    return x < 0.0f ? -x : x;
}

// Of 255: how often a situation whose outcome moves stayed where it was (model.h), rounded.
static uint8_t stay_share_(const world_model_t *m, const model_class_t *c)
{
    const uint32_t all = (uint32_t)c->count + c->miss + c->stay;
    if ((m->ablate & MODEL_ABLATE_STAY) != 0u || c->stay == 0u || !moves_(c->delta)) {
        return 0u;
    }
    return (uint8_t)((c->stay * 255u + all / 2u) / all);
}

// Where the relocatable model's prediction for an untried pair leads, before what it says there:
// the situation's (or percept's) outcome `*cls`; the state its change reaches (`to` and `*next`,
// still with the percept of `from`); whether it moves; and, for a move in a space with a percept
// map, the percepts seen there (`*seen`, never 0), else 0. False where predict_general_()
// refuses.
AGENT_ALWAYS_INLINE bool general_reach_(world_model_t *m, const uint32_t *from, agent_state_t s,
                                        uint32_t a, const model_class_t **cls, uint32_t *to,
                                        agent_state_t *next, bool *moved, uint32_t *seen)
{
    if (m->classes == NULL || (m->ablate & MODEL_ABLATE_GENERALISE) != 0u) {
        return false;
    }
    const model_class_t *c = class_of_(m, s, from, a);
    if (!class_trusted_(c)) {
        // Not yet seen often enough in this heading: what the action does at this percept in
        // any heading (a bump, a turn, a step too short to leave the cell), seen at least
        // MODEL_PERCEPT_MIN_COUNT times.
        if (m->n_percept_classes == 0u) {
            return false;
        }
        c = percept_class_of_(m, s, from, a);
        if (c->count < MODEL_PERCEPT_MIN_COUNT) {
            return false;
        }
    }
    if (!apply_delta_(m, from, c->delta, 1, to, next)) {
        return false;
    }
    *moved = moves_(c->delta);
    *seen = 0u;
    if (*moved && m->percepts != NULL) {  // a step that goes nowhere keeps what it perceives
        *seen = seen_at_(m, *next, to);
        if (*seen == 0u) {
            return false;
        }
    }
    *cls = c;
    return true;
}

// The rest of the relocatable model's prediction, from what general_reach_() found: the
// outcomes, the reward, the end of an episode, the stay share. Counts it in `generalised`.
AGENT_ALWAYS_INLINE void general_outcome_(world_model_t *m, const model_class_t *c, uint32_t *to,
                                          agent_state_t next, bool moved, uint32_t seen,
                                          model_step_t *out)
{
    uint32_t others = 0;
    if (seen != 0u) {
        // A place seen with several percepts: each is an outcome.
        others = seen & (seen - 1u);
        set_percept_(m, lowest_bit_(seen), &next, to);
    }
    const int16_t arrival = m->arrivals[select_(m, &m->position_of, next, to)];
    out->next = next;
    out->terminal = (uint8_t)(arrival != MODEL_NO_ARRIVAL && moved);
    out->reward = (float)(out->terminal ? arrival : c->reward) / (float)CMAC_ONE;
    out->others = (uint16_t)others;
    out->stay = out->terminal ? 0u : stay_share_(m, c);
    m->generalised++;
}

// The relocatable model's prediction for an untried pair: the situation's usual change, the
// percepts the map has for the place it leads to (a place never seen is not predictable; one
// seen with several percepts, where the range code depends on where in the cell the robot is,
// has each as an outcome: refusing it left the values of pairs leading there as they were when
// the place still showed one, and learned slower: docs/agent.md), and the reward of arriving
// there if an episode ended there before (else the situation's reward).
static bool predict_general_(world_model_t *m, const uint32_t *from, agent_state_t s, uint32_t a,
                             model_step_t *out)
{
    const model_class_t *c;
    uint32_t to[FW_CFG_MAX_COMPONENTS];
    agent_state_t next;
    bool moved;
    uint32_t seen;
    if (!general_reach_(m, from, s, a, &c, to, &next, &moved, &seen)) {
        return false;
    }
    general_outcome_(m, c, to, next, moved, seen, out);
    return true;
}

// A tried pair's prediction (predict_exact_()) with its stay share: a tried move stays as often
// as its situation's moves do (a property of the heading against the cell, not of the place); its
// own stays were not kept (model_learn()). A tried pair that only ever stayed, with its
// situation's reward, is predicted as the situation's move: it was the same step, not finished.
static void exact_stays_(world_model_t *m, const uint32_t *from, agent_state_t s, uint32_t a,
                         model_step_t *out)
{
    if (m->classes != NULL && !out->terminal && (m->ablate & MODEL_ABLATE_STAY) == 0u) {
        const model_class_t *c = class_of_(m, s, from, a);
        if (!class_trusted_(c) && m->n_percept_classes != 0u) {
            c = percept_class_of_(m, s, from, a);
        }
        const uint8_t share = stay_share_(m, c);
        if (out->next != s) {
            out->stay = share;
        } else if (share != 0u && agent_absf_((float)c->reward / (float)CMAC_ONE - out->reward) <= 0.5f) {
            const model_step_t kept = *out;
            if (!predict_general_(m, from, s, a, out)) {
                *out = kept;
            }
        }
    }
}

// The model's prediction for (from, a): CMAC-Model's if the pair was tried, else the
// relocatable model's. Counts a refusal in `untrusted`.
static bool predict_(world_model_t *m, const uint32_t *from, agent_state_t s,
                     const cmac_tiles_t *tiles, uint32_t a, model_step_t *out)
{
    if (predict_exact_(m, from, tiles, a, out)) {
        exact_stays_(m, from, s, a, out);
        return true;
    }
    if (predict_general_(m, from, s, a, out)) {
        return true;
    }
    m->untrusted++;
    return false;
}

void model_set_stay_reward(world_model_t *m, float step_reward)
{
    FW_ASSERT(m != NULL);
    bool fits;
    const int16_t v = reward_fixed_(step_reward, &fits);
    m->stay_reward = fits ? v : MODEL_NO_STAY;
}

int model_percepts_check(const world_model_t *m, const uint16_t *percepts)
{
    FW_ASSERT(m != NULL && percepts != NULL);
    const uint32_t values = 1u << masked_bits_(m->space, m->space->absolute_mask);
    const uint32_t allowed = values >= 16u ? 0xFFFFu : (1u << values) - 1u;
    // One test after the loop, not one a place: the loop has no branch and vectorises (paper-sim
    // checks 16,384 places at every save and boot).
    uint32_t stray = 0;
    for (uint32_t i = 0; i < m->places; i++) {
        stray |= percepts[i] & ~allowed;
    }
    return stray != 0u ? FW_ERR_CORRUPT : FW_OK;
}

bool model_has_seen(const world_model_t *m, agent_state_t s)
{
    FW_ASSERT(m != NULL);
    if (m->percepts == NULL) {
        return false;
    }
    uint32_t comp[FW_CFG_MAX_COMPONENTS];
    space_unpack(m->space, s, comp);
    return (seen_at_(m, s, comp) >> select_(m, &m->percept_of, s, comp)) & 1u;
}

void model_query_init(const world_model_t *m, agent_state_t s, model_query_t *q)
{
    FW_ASSERT(m != NULL && q != NULL);
    q->state = s;
    space_unpack(m->space, s, q->comp);
    cmac_tiles_of_packed(&m->forward, s, q->comp, 0, &q->tiles);
}

bool model_tried_outcome(const world_model_t *m, agent_state_t s, uint8_t a, model_step_t *out)
{
    model_query_t q;
    model_query_init(m, s, &q);
    return predict_exact_(m, q.comp, &q.tiles, a, out);
}

bool model_query_predict(world_model_t *m, const model_query_t *q, uint8_t a, model_step_t *out)
{
    FW_ASSERT(m != NULL && q != NULL && a < m->space->n_actions && out != NULL);
    return predict_(m, q->comp, q->state, &q->tiles, a, out);
}

bool model_predict(world_model_t *m, agent_state_t s, uint8_t a, model_step_t *out)
{
    model_query_t q;
    model_query_init(m, s, &q);
    return model_query_predict(m, &q, a, out);
}

// The percept value of a packed state: select_() for a caller without its components (a space
// without absolute components has the one value 0).
static uint32_t percept_value_(const world_model_t *m, agent_state_t s)
{
    uint32_t comp[FW_CFG_MAX_COMPONENTS] = {0};
    if (!m->percept_of.adjacent) {
        space_unpack(m->space, s, comp);
    }
    return select_(m, &m->percept_of, s, comp);
}

// Whether q's state (its percept value `percept`) is one of the step's outcomes.
AGENT_ALWAYS_INLINE bool leads_to_(const world_model_t *m, const model_step_t *step,
                                   const model_query_t *q, uint32_t percept)
{
    if (step->next == q->state) {
        return true;
    }
    return ((step->others >> percept) & 1u) != 0u &&
           with_percept_(m, step->next, percept) == q->state;
}

// Whether the candidate predecessor `prev` (its state, components and tiles) confirms by `a`:
// predict_() leads to q's state (q's percept value `percept`) without ending the episode, as the
// predecessor search asks, into *step. Counts what predict_() counts, but works out a
// prediction's reward, end and stay share only where it leads to q: about three candidates in
// four lead elsewhere (paper-sim), and for them only whether there is a prediction (the counts)
// and where it goes are needed.
AGENT_ALWAYS_INLINE bool confirms_(world_model_t *m, const model_query_t *prev, uint32_t a,
                                   const model_query_t *q, uint32_t percept, model_step_t *step)
{
    if (predict_exact_(m, prev->comp, &prev->tiles, a, step)) {
        // A tried pair's one outcome is step->next, which its stay share leaves as it is unless
        // it stays where it is (exact_stays_() may then take the situation's move).
        if (step->terminal || (step->next != prev->state && step->next != q->state)) {
            return false;
        }
        exact_stays_(m, prev->comp, prev->state, a, step);
        return !step->terminal && leads_to_(m, step, q, percept);
    }
    const model_class_t *c;
    uint32_t to[FW_CFG_MAX_COMPONENTS];
    agent_state_t next;
    bool moved;
    uint32_t seen;
    if (!general_reach_(m, prev->comp, prev->state, a, &c, to, &next, &moved, &seen)) {
        m->untrusted++;
        return false;
    }
    // Without a map's percepts the outcome is `next`; with them, `next` with each percept seen
    // there (general_outcome_()), of which leads_to_() looks for q's.
    if (seen == 0u ? next != q->state
                   : ((seen >> percept) & 1u) == 0u || with_percept_(m, next, percept) != q->state) {
        m->generalised++;  // a prediction all the same
        return false;
    }
    general_outcome_(m, c, to, next, moved, seen, step);
    return !step->terminal && leads_to_(m, step, q, percept);
}

uint32_t model_step_outcomes(const world_model_t *m, const model_step_t *step, agent_state_t *out)
{
    FW_ASSERT(m != NULL && step != NULL && out != NULL);
    uint32_t n = 0;
    out[n++] = step->next;
    for (uint32_t rest = step->others; rest != 0u; rest &= rest - 1u) {
        out[n++] = with_percept_(m, step->next, lowest_bit_(rest));
    }
    return n;
}

uint32_t model_query_predecessors(world_model_t *m, const model_query_t *q, model_pred_t *out,
                                  model_query_t *const *queries)
{
    FW_ASSERT(m != NULL && q != NULL && out != NULL);
    const agent_space_t *sp = m->space;
    model_query_t scratch;
    model_step_t step;
    uint32_t n = 0;

    const uint32_t bucket = delta_bucket_(m, q->state, q->comp);
    const uint32_t percept = select_(m, &m->percept_of, q->state, q->comp);
    for (uint32_t a = 0; a < sp->n_actions; a++) {
        for (uint32_t d = 0; d < MODEL_MAX_DELTAS && n < MODEL_MAX_PREDECESSORS; d++) {
            const model_delta_t *delta = &m->deltas[a][bucket][d];
            // Undo a change a has made: where the robot was before, but for what it perceived.
            // Into the next candidate's query; a place with several percepts copies it on.
            model_query_t *prev = queries != NULL ? queries[n] : &scratch;
            agent_state_t back_state;
            if (delta->count == 0u ||
                !apply_delta_(m, q->comp, delta->delta, -1, prev->comp, &back_state)) {
                continue;
            }
            const uint32_t *const back = prev->comp;
            // Each percept seen at that place is a candidate (one, for a space without them).
            uint32_t seen =
                m->percepts != NULL ? seen_at_(m, back_state, back) : 1u;
            for (; seen != 0u && n < MODEL_MAX_PREDECESSORS; seen &= seen - 1u) {
                model_query_t *const next = queries != NULL ? queries[n] : &scratch;
                if (next != prev) {  // the last candidate was confirmed: it keeps its query
                    for (uint32_t k = 0; k < sp->n_components; k++) {
                        next->comp[k] = prev->comp[k];
                    }
                    prev = next;
                }
                prev->state = back_state;
                set_percept_(m, lowest_bit_(seen), &prev->state, prev->comp);
                cmac_tiles_of_packed(&m->forward, prev->state, prev->comp, a, &prev->tiles);
                // Confirmed only if the forward prediction leads here, not ending the episode;
                // the same lookup gives the predecessor's reward.
                if (!confirms_(m, prev, a, q, percept, &step)) {
                    m->rejected++;
                    continue;
                }
                out[n].state = prev->state;
                out[n].action = (uint8_t)a;
                // The step's other outcomes, seen from here (with one outcome, it is here).
                const uint32_t outcomes =
                    step.others == 0u ? 0u : step.others | (1u << percept_value_(m, step.next));
                out[n].others = (uint16_t)(outcomes & ~(1u << percept));
                out[n].stay = step.stay;
                out[n].reward = step.reward;
                n++;
            }
        }
    }
    return n;
}

uint32_t model_predecessors(world_model_t *m, agent_state_t s, model_pred_t *out)
{
    model_query_t q;
    model_query_init(m, s, &q);
    return model_query_predecessors(m, &q, out, NULL);
}
