// SPDX-License-Identifier: MIT
// dynaqpc: Q(s, a) in a dense array or an open-addressing hash table.
#include "agent/qstore.h"

#include <stdbool.h>
#include <stddef.h>
#include <string.h>

#include "check.h"
#include "fw/fw_base.h"
#include "fw/fw_util.h"
#include "inline.h"

#if FW_CFG_VALUE16_BY_SCALING
// value16_to_float() in one multiplication (fw_config.h): the value16's bits below its sign,
// placed where a float's exponent and fraction are, read a float 2^96 times too small, a
// subnormal one for exponent 0; its sign is the float's. Exact for every value16 (each is a
// float, and scaling by a power of two is exact where the product is normal, as all are), but
// only where the FPU reads subnormal operands as they are.
AGENT_ALWAYS_INLINE float value16_read_(value16_t v)
{
    const uint32_t x = ((uint32_t)(v & 0x8000u) << 16) | ((uint32_t)(v & 0x7fffu) << 14);
    float f;
    memcpy(&f, &x, sizeof f);
    return f * 0x1p96f;
}
#else
#define value16_read_ value16_to_float
#endif

// Value i of the table (row * n_actions + action), in either width. The branch goes the same
// way for the life of the store.
AGENT_ALWAYS_INLINE float load_(const qstore_t *qs, uint32_t i)
{
    return qs->wide ? qs->v.f[i] : value16_read_(qs->v.h[i]);
}

AGENT_ALWAYS_INLINE void store_(qstore_t *qs, uint32_t i, float x)
{
    if (qs->wide) {
        qs->v.f[i] = x;
    } else {
        qs->v.h[i] = value16_from_float(x);
    }
}

// The 16-bit keys (qstore_init16), kept in index.keys's place: no oa_table function that reads
// or writes keys is called on them.
AGENT_ALWAYS_INLINE uint16_t *keys16_(const qstore_t *qs)
{
    return (uint16_t *)(void *)qs->index.keys;
}

AGENT_ALWAYS_INLINE uint16_t key16_(agent_state_t s)
{
    return (uint16_t)(s & ((1u << QSTORE_KEY16_BITS) - 1u));
}

// 16-bit keys: the slot holding s; with `insert`, else the first empty slot of its window (where
// it would go); OA_NONE if neither. oa_find() and oa_lookup() slot for slot: within s's window a
// slot holding s's low bits holds s (qstore_keys16_exact).
AGENT_ALWAYS_INLINE uint32_t find16_(const qstore_t *qs, agent_state_t s, bool insert)
{
    const uint16_t *const keys = keys16_(qs);
    const uint16_t key = key16_(s);
    uint32_t slot = oa_home(&qs->index, s);
    for (uint32_t probe = 0; probe < qs->index.limit; probe++) {
        const uint16_t k = keys[slot];
        if (k == key) {
            return slot;
        }
        if (k == QSTORE_EMPTY16) {
            return insert ? slot : OA_NONE;
        }
        slot = (slot + 1u) & qs->index.mask;
    }
    return OA_NONE;
}

bool qstore_keys16_exact(uint32_t capacity, uint32_t state_bits)
{
    return state_bits <= QSTORE_KEY16_BITS ||
           (state_bits <= 20u && capacity >= (1u << 12) && capacity <= (1u << 16));
}

static int init_(qstore_t *qs, void *q, uint8_t value_bytes, uint32_t *keys, uint32_t capacity,
                 uint8_t n_actions, uint32_t state_bits, bool narrow);

int qstore_init(qstore_t *qs, void *q, uint8_t value_bytes, uint32_t *keys, uint32_t capacity,
                uint8_t n_actions, uint32_t state_bits)
{
    return init_(qs, q, value_bytes, keys, capacity, n_actions, state_bits, false);
}

int qstore_init16(qstore_t *qs, void *q, uint8_t value_bytes, uint16_t *keys, uint32_t capacity,
                  uint8_t n_actions, uint32_t state_bits)
{
    if (((uintptr_t)keys & 3u) != 0u || !qstore_keys16_exact(capacity, state_bits)) {
        return FW_ERR_INVAL;
    }
    return init_(qs, q, value_bytes, (uint32_t *)(void *)keys, capacity, n_actions, state_bits, true);
}

static int init_(qstore_t *qs, void *q, uint8_t value_bytes, uint32_t *keys, uint32_t capacity,
                 uint8_t n_actions, uint32_t state_bits, bool narrow)
{
    if (qs == NULL || q == NULL || (value_bytes != 2u && value_bytes != 4u) ||
        !FW_IS_POW2(capacity) || n_actions < 1u || n_actions > FW_CFG_MAX_ACTIONS ||
        state_bits > 31u) {
        return FW_ERR_INVAL;
    }
    qs->narrow = (uint8_t)narrow;
    qs->wide = (uint8_t)(value_bytes == 4u);
    if (qs->wide) {
        qs->v.f = q;
    } else {
        qs->v.h = q;
    }
    qs->capacity = capacity;
    qs->n_actions = n_actions;
    qs->dense = (uint8_t)((1u << state_bits) <= capacity);
    qs->prior = 0.0f;
    qs->index = (oa_table_t){0};
    if (!qs->dense) {
        // Multiplicative hashing: the top bits of s * (2^32 / golden ratio) spread consecutive
        // states, which neighbouring robot poses are, evenly over the table.
        if (oa_init(&qs->index, keys, capacity, oa_probe_limit(capacity), OA_HOME_HIGH) != FW_OK) {
            return FW_ERR_INVAL;
        }
    }
    qstore_clear(qs);
    return FW_OK;
}

void qstore_set_prior(qstore_t *qs, float prior)
{
    qs->prior = prior;
    qstore_clear(qs);
}

void qstore_clear(qstore_t *qs)
{
    // +0.0 is all zero bits in both widths. A dense store's rows all exist: they start at the
    // prior. A hashed store's empty rows stay zero (qstore_check() holds them to it) and take the
    // prior when a state is given one.
    const uint32_t n = qs->capacity * qs->n_actions;
    if (qs->dense && qs->prior != 0.0f) {
        for (uint32_t i = 0; i < n; i++) {
            store_(qs, i, qs->prior);
        }
    } else {
        memset(qs->wide ? (void *)qs->v.f : (void *)qs->v.h, 0, n * (qs->wide ? 4u : 2u));
    }
    if (qs->narrow && !qs->dense) {
        memset(keys16_(qs), 0xFF, qs->capacity * sizeof(uint16_t));
    } else if (!qs->dense) {
        oa_clear(&qs->index);
    }
    qs->rows_used = 0;
    qs->dropped = 0;
    qs->plan_refused = 0;
}

// The row of state s for reading, QSTORE_NO_ROW for an unknown state (which reads the prior).
// The planner's lookups (about three per planning update) come here.
AGENT_ALWAYS_INLINE qstore_row_t row_of_(const qstore_t *qs, agent_state_t s)
{
    if (qs->dense) {
        return s;
    }
    const uint32_t slot = qs->narrow ? find16_(qs, s, false)
                                     : oa_lookup(&qs->index, s, qs->rows_used == qs->capacity);
    return slot == OA_NONE ? QSTORE_NO_ROW : slot;
}

AGENT_ALWAYS_INLINE float max_of_(const qstore_t *qs, qstore_row_t row)
{
    if (row == QSTORE_NO_ROW) {
        return qs->prior;
    }
    const uint32_t base = row * qs->n_actions;
    float best = load_(qs, base);
    for (uint32_t a = 1; a < qs->n_actions; a++) {
        const float v = load_(qs, base + a);
        if (v > best) {
            best = v;
        }
    }
    return best;
}

float qstore_get(const qstore_t *qs, agent_state_t s, uint8_t a)
{
    const qstore_row_t row = row_of_(qs, s);
    return row == QSTORE_NO_ROW ? qs->prior : load_(qs, row * qs->n_actions + a);
}

void qstore_values(const qstore_t *qs, agent_state_t s, float *out)
{
    const qstore_row_t row = row_of_(qs, s);
    for (uint32_t a = 0; a < qs->n_actions; a++) {
        out[a] = row == QSTORE_NO_ROW ? qs->prior : load_(qs, row * qs->n_actions + a);
    }
}

bool qstore_has_row(const qstore_t *qs, agent_state_t s)
{
    if (!qs->dense) {
        return row_of_(qs, s) != QSTORE_NO_ROW;
    }
    float v[FW_CFG_MAX_ACTIONS];
    qstore_values(qs, s, v);
    for (uint32_t a = 0; a < qs->n_actions; a++) {
        if (v[a] != 0.0f) {
            return true;
        }
    }
    return false;
}

float qstore_max(const qstore_t *qs, agent_state_t s)
{
    return max_of_(qs, row_of_(qs, s));
}

qstore_row_t qstore_row_of(const qstore_t *qs, agent_state_t s)
{
    return row_of_(qs, s);
}

float qstore_row_get(const qstore_t *qs, qstore_row_t row, uint8_t a)
{
    return row == QSTORE_NO_ROW ? qs->prior : load_(qs, row * qs->n_actions + a);
}

bool qstore_moves(const qstore_t *qs, float q, float target, float alpha)
{
    const float next = q + alpha * (target - q);
    return qs->wide ? next != q : value16_from_float(next) != value16_from_float(q);
}

// How much a row has learned: the sum of |Q - prior| over its actions (a state seen once or
// twice has little), for oa_least(). The sum is never negative, and non-negative floats order as their
// bits do, so the bits are the score.
static uint32_t learned_(void *ctx, uint32_t slot)
{
    const qstore_t *qs = ctx;
    float sum = 0.0f;
    for (uint32_t a = 0; a < qs->n_actions; a++) {
        const float v = load_(qs, slot * qs->n_actions + a) - qs->prior;
        sum += v < 0.0f ? -v : v;
    }
    uint32_t bits;
    memcpy(&bits, &sum, sizeof bits);
    return bits;
}

// A row given to a new state: every action at the prior.
static void start_row_(qstore_t *qs, uint32_t row)
{
    for (uint32_t a = 0; a < qs->n_actions; a++) {
        store_(qs, row * qs->n_actions + a, qs->prior);
    }
}

// A full probe window: the new state takes the row of the window that has learned least, reused
// in place (the caller starts it afresh), so no probe path is broken.
static uint32_t evict_(qstore_t *qs, agent_state_t s)
{
    const uint32_t victim = oa_least(&qs->index, s, learned_, qs);
    qs->rows_used--;
    qs->dropped++;  // a state forgotten
    return victim;
}

// The row of s for writing, created in a free slot of its window if it has none; a full window
// forgets the row that learned least when `may_evict`, else refuses (QSTORE_NO_ROW, counted).
static qstore_row_t row_for_write_(qstore_t *qs, agent_state_t s, bool may_evict)
{
    if (qs->dense) {
        return s;
    }
    const bool narrow = qs->narrow;
    uint32_t slot = narrow ? find16_(qs, s, false)
                           : oa_lookup(&qs->index, s, qs->rows_used == qs->capacity);
    if (slot == OA_NONE) {  // not the common case: s has no row yet
        slot = narrow ? find16_(qs, s, true) : oa_insert(&qs->index, s);
        if (slot == OA_NONE) {
            if (!may_evict) {
                qs->plan_refused++;
                return QSTORE_NO_ROW;
            }
            slot = evict_(qs, s);
            if (!narrow) {
                oa_put(&qs->index, slot, s);
            }
        }
        if (narrow) {
            keys16_(qs)[slot] = key16_(s);
        }
        start_row_(qs, slot);  // a free row or a forgotten one: the new state starts at the prior
        qs->rows_used++;
    }
    return slot;
}

qstore_row_t qstore_row_for_update(qstore_t *qs, agent_state_t s)
{
    return row_for_write_(qs, s, true);
}

qstore_row_t qstore_row_for_plan(qstore_t *qs, agent_state_t s)
{
    return row_for_write_(qs, s, false);
}

bool qstore_learn(qstore_t *qs, qstore_row_t row, uint8_t a, float target, float alpha,
                  float *value)
{
    const uint32_t i = row * qs->n_actions + a;
    const float before = load_(qs, i);
    store_(qs, i, before + alpha * (target - before));
    const float after = load_(qs, i);
    if (value != NULL) {
        *value = after;
    }
    return after != before;
}

void qstore_set(qstore_t *qs, qstore_row_t row, uint8_t a, float v)
{
    store_(qs, row * qs->n_actions + a, v);
}

float qstore_row_max(const qstore_t *qs, qstore_row_t row)
{
    return max_of_(qs, row);
}

uint32_t qstore_regions(const qstore_t *qs, agent_region_t *out)
{
    const uint32_t bytes = qs->capacity * qs->n_actions * (qs->wide ? 4u : 2u);
    uint32_t n = agent_region_add(out, 0, qs->wide ? (void *)qs->v.f : (void *)qs->v.h, bytes);
    if (!qs->dense) {
        n = agent_region_add(out, n, qs->index.keys,
                             qs->capacity * (uint32_t)(qs->narrow ? sizeof(uint16_t) : sizeof(uint32_t)));
    }
    return n;
}

// qstore_check() of an empty slot, whatever its keys' width: its row of restored values is all
// zeros (float or value16), since a new row is used as it is.
static bool row_zero_(const qstore_t *qs, const float *qf, const value16_t *qh, uint32_t slot)
{
    const uint32_t n = qs->n_actions;
    for (uint32_t a = 0; a < n; a++) {
        if (qs->wide ? qf[slot * n + a] != 0.0f : qh[slot * n + a] != 0u) {
            return false;
        }
    }
    return true;
}

// qstore_check() of 16-bit keys: each non-empty slot's state is the one state of `state_bits`
// bits with those low bits whose window holds the slot, found with no empty slot and no copy of
// its key between its home and it; an empty row all zeros.
static int check16_(const qstore_t *qs, const float *qf, const value16_t *qh, const uint16_t *keys,
                    uint32_t state_bits)
{
    const uint32_t highs =
        state_bits > QSTORE_KEY16_BITS ? 1u << (state_bits - QSTORE_KEY16_BITS) : 1u;
    for (uint32_t slot = 0; slot < qs->capacity; slot++) {
        const uint16_t key = keys[slot];
        if (key == QSTORE_EMPTY16) {
            if (!row_zero_(qs, qf, qh, slot)) {
                return FW_ERR_CORRUPT;
            }
            continue;
        }
        if ((key >> QSTORE_KEY16_BITS) != 0u || (state_bits <= QSTORE_KEY16_BITS && (key >> state_bits) != 0u)) {
            return FW_ERR_CORRUPT;
        }
        uint32_t home = OA_NONE;
        for (uint32_t hi = 0; hi < highs && home == OA_NONE; hi++) {
            const uint32_t h = oa_home(&qs->index, key | (hi << QSTORE_KEY16_BITS));
            if (((slot - h) & qs->index.mask) < qs->index.limit) {
                home = h;
            }
        }
        if (home == OA_NONE) {
            return FW_ERR_CORRUPT;
        }
        for (uint32_t j = home; j != slot; j = (j + 1u) & qs->index.mask) {
            if (keys[j] == QSTORE_EMPTY16 || keys[j] == key) {
                return FW_ERR_CORRUPT;
            }
        }
    }
    return FW_OK;
}

int qstore_check(const qstore_t *qs, const void *const *image, uint32_t state_bits)
{
    const uint32_t n = qs->n_actions;
    // Each value a number within the limit; an empty row all zero bits.
    const float *const qf = image[0];
    const value16_t *const qh = image[0];
    for (uint32_t i = 0; i < qs->capacity * n; i++) {
        if (qs->wide ? !check_finite(qf[i]) || qf[i] > QSTORE_VALUE_LIMIT || qf[i] < -QSTORE_VALUE_LIMIT
                     : !value16_ok(qh[i])) {
            return FW_ERR_CORRUPT;
        }
    }
    if (qs->dense) {
        return FW_OK;
    }
    if (qs->narrow) {
        return check16_(qs, qf, qh, image[1], state_bits);
    }
    const uint32_t *const keys = image[1];
    for (uint32_t slot = 0; slot < qs->capacity; slot++) {
        const uint32_t key = keys[slot];
        if (key == QSTORE_EMPTY) {
            if (!row_zero_(qs, qf, qh, slot)) {
                return FW_ERR_CORRUPT;
            }
        } else if ((key >> state_bits) != 0u || !oa_path_ok(&qs->index, keys, slot)) {
            return FW_ERR_CORRUPT;
        }
    }
    return FW_OK;
}

void qstore_restored(qstore_t *qs)
{
    if (qs->narrow && !qs->dense) {
        const uint16_t *const keys = keys16_(qs);
        qs->rows_used = 0;
        for (uint32_t i = 0; i < qs->capacity; i++) {
            qs->rows_used += keys[i] != QSTORE_EMPTY16;
        }
    } else if (!qs->dense) {
        qs->rows_used = oa_count(&qs->index, qs->index.keys);
    }
}
