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

// What an unknown state reads as. Large enough for any action count.
static const float zero_row_[FW_CFG_MAX_ACTIONS];

int qstore_init(qstore_t *qs, float *q, uint32_t *keys, uint32_t capacity, uint8_t n_actions,
                uint32_t state_bits)
{
    if (qs == NULL || q == NULL || !FW_IS_POW2(capacity) || n_actions < 1u ||
        n_actions > FW_CFG_MAX_ACTIONS || state_bits > 31u) {
        return FW_ERR_INVAL;
    }
    qs->q = q;
    qs->capacity = capacity;
    qs->n_actions = n_actions;
    qs->dense = (uint8_t)((1u << state_bits) <= capacity);
    qs->index = (oa_table_t){0};
    if (!qs->dense) {
        // Multiplicative hashing: the top bits of s * (2^32 / golden ratio) spread consecutive
        // states, which neighbouring robot poses are, evenly over the table.
        const uint32_t limit = FW_CFG_MAX_PROBE < capacity ? FW_CFG_MAX_PROBE : capacity;
        if (oa_init(&qs->index, keys, capacity, limit, OA_HOME_HIGH) != FW_OK) {
            return FW_ERR_INVAL;
        }
    }
    qstore_clear(qs);
    return FW_OK;
}

void qstore_clear(qstore_t *qs)
{
    const uint32_t n = qs->capacity * qs->n_actions;
    for (uint32_t i = 0; i < n; i++) {
        qs->q[i] = 0.0f;
    }
    if (!qs->dense) {
        oa_clear(&qs->index);
    }
    qs->rows_used = 0;
    qs->dropped = 0;
    qs->plan_refused = 0;
}

// The row of state s for reading; an unknown state reads as zeros. The planner's lookups (about
// three per planning update) come here.
AGENT_ALWAYS_INLINE const float *row_of_(const qstore_t *qs, agent_state_t s)
{
    if (qs->dense) {
        return &qs->q[s * qs->n_actions];
    }
    const uint32_t slot = oa_lookup(&qs->index, s, qs->rows_used == qs->capacity);
    return slot == OA_NONE ? zero_row_ : &qs->q[slot * qs->n_actions];
}

const float *qstore_row(const qstore_t *qs, agent_state_t s)
{
    return row_of_(qs, s);
}

// How much a row has learned: the sum of |Q| over its actions (a state seen once or twice has
// little), for oa_least(). The sum is never negative, and non-negative floats order as their
// bits do, so the bits are the score.
static uint32_t learned_(void *ctx, uint32_t slot)
{
    const qstore_t *qs = ctx;
    const float *row = &qs->q[slot * qs->n_actions];
    float sum = 0.0f;
    for (uint32_t a = 0; a < qs->n_actions; a++) {
        sum += row[a] < 0.0f ? -row[a] : row[a];
    }
    uint32_t bits;
    memcpy(&bits, &sum, sizeof bits);
    return bits;
}

// A full probe window: the new state takes the row of the window that has learned least, which
// is emptied and reused in place, so no probe path is broken.
static uint32_t evict_(qstore_t *qs, agent_state_t s)
{
    const uint32_t victim = oa_least(&qs->index, s, learned_, qs);
    float *row = &qs->q[victim * qs->n_actions];
    for (uint32_t a = 0; a < qs->n_actions; a++) {
        row[a] = 0.0f;
    }
    qs->rows_used--;
    qs->dropped++;  // a state forgotten
    return victim;
}

// The row of s for writing, created in a free slot of its window if it has none; a full window
// forgets the row that learned least when `may_evict`, else refuses (NULL, counted).
static float *row_for_write_(qstore_t *qs, agent_state_t s, bool may_evict)
{
    if (qs->dense) {
        return &qs->q[s * qs->n_actions];
    }
    uint32_t slot = oa_lookup(&qs->index, s, qs->rows_used == qs->capacity);
    if (slot == OA_NONE) {  // not the common case: s has no row yet
        slot = oa_insert(&qs->index, s);
        if (slot == OA_NONE) {
            if (!may_evict) {
                qs->plan_refused++;
                return NULL;
            }
            slot = evict_(qs, s);
            oa_put(&qs->index, slot, s);
        }
        qs->rows_used++;
    }
    return &qs->q[slot * qs->n_actions];
}

float *qstore_row_for_update(qstore_t *qs, agent_state_t s)
{
    return row_for_write_(qs, s, true);
}

float *qstore_row_for_plan(qstore_t *qs, agent_state_t s)
{
    return row_for_write_(qs, s, false);
}

float qstore_max(const qstore_t *qs, agent_state_t s)
{
    const float *row = row_of_(qs, s);
    float best = row[0];
    for (uint32_t a = 1; a < qs->n_actions; a++) {
        if (row[a] > best) {
            best = row[a];
        }
    }
    return best;
}

uint32_t qstore_regions(const qstore_t *qs, agent_region_t *out)
{
    uint32_t n = agent_region_add(out, 0, qs->q, qs->capacity * qs->n_actions * (uint32_t)sizeof(float));
    if (!qs->dense) {
        n = agent_region_add(out, n, qs->index.keys, qs->capacity * (uint32_t)sizeof(uint32_t));
    }
    return n;
}

int qstore_check(const qstore_t *qs, const void *const *image, uint32_t state_bits)
{
    const float *const q = image[0];
    const uint32_t n = qs->n_actions;
    for (uint32_t i = 0; i < qs->capacity * n; i++) {
        if (!check_finite(q[i]) || q[i] > QSTORE_VALUE_LIMIT || q[i] < -QSTORE_VALUE_LIMIT) {
            return FW_ERR_CORRUPT;
        }
    }
    if (qs->dense) {
        return FW_OK;
    }
    const uint32_t *const keys = image[1];
    for (uint32_t slot = 0; slot < qs->capacity; slot++) {
        const uint32_t key = keys[slot];
        if (key == QSTORE_EMPTY) {
            for (uint32_t a = 0; a < n; a++) {
                if (q[slot * n + a] != 0.0f) {
                    return FW_ERR_CORRUPT;
                }
            }
        } else if ((key >> state_bits) != 0u || !oa_path_ok(&qs->index, keys, slot)) {
            return FW_ERR_CORRUPT;
        }
    }
    return FW_OK;
}

void qstore_restored(qstore_t *qs)
{
    if (!qs->dense) {
        qs->rows_used = oa_count(&qs->index, qs->index.keys);
    }
}
