// SPDX-License-Identifier: MIT
// dynaqpc: Q(s, a) in a dense array or an open-addressing hash table.
#include "agent/qstore.h"

#include <stdbool.h>
#include <stddef.h>

#include "check.h"
#include "fw/fw_base.h"
#include "fw/fw_util.h"
#include "inline.h"
#include "probe.h"

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
    qs->keys = keys;
    qs->capacity = capacity;
    qs->n_actions = n_actions;
    qs->capacity_shift = (uint8_t)fw_log2_ceil(capacity);
    qs->dense = (uint8_t)((1u << state_bits) <= capacity);
    if (!qs->dense && keys == NULL) {
        return FW_ERR_INVAL;
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
        for (uint32_t i = 0; i < qs->capacity; i++) {
            qs->keys[i] = QSTORE_EMPTY;
        }
    }
    qs->rows_used = 0;
    qs->dropped = 0;
    qs->plan_refused = 0;
}

// Multiplicative hashing: the top bits of s * (2^32 / golden ratio) spread consecutive states,
// which neighbouring robot poses are, evenly over the table.
static uint32_t home_(const qstore_t *qs, agent_state_t s)
{
    return fw_fib_mix(s) >> (32u - qs->capacity_shift);
}

// The slot holding s, or the first empty slot where it would go, or capacity if neither is
// within the probe limit.
static uint32_t find_(const qstore_t *qs, agent_state_t s)
{
    const uint32_t mask = qs->capacity - 1u;
    uint32_t slot = qs->capacity_shift ? home_(qs, s) : 0u;
    for (uint32_t probe = 0; probe < FW_CFG_MAX_PROBE && probe < qs->capacity; probe++) {
        const uint32_t key = qs->keys[slot];
        if (key == s || key == QSTORE_EMPTY) {
            return slot;
        }
        slot = (slot + 1u) & mask;
    }
    return qs->capacity;
}

// The row holding s, or capacity if it has none: find_() for reading, which is most of the
// planner's lookups (about three per planning update). A probe window that does not wrap around
// the table's end is scanned by pointer (probe.h).
AGENT_ALWAYS_INLINE uint32_t lookup_(const qstore_t *qs, agent_state_t s)
{
    const uint32_t home = qs->capacity_shift ? home_(qs, s) : 0u;
    if (home + FW_CFG_MAX_PROBE > qs->capacity) {
        const uint32_t slot = find_(qs, s);
        return slot != qs->capacity && qs->keys[slot] == s ? slot : qs->capacity;
    }
    const uint32_t *const row = probe_scan(qs->keys + home, s, qs->rows_used == qs->capacity);
    return row != NULL ? (uint32_t)(row - qs->keys) : qs->capacity;
}

// The row of s for reading; an unknown state reads as zeros.
AGENT_ALWAYS_INLINE const float *row_of_(const qstore_t *qs, agent_state_t s)
{
    if (qs->dense) {
        return &qs->q[s * qs->n_actions];
    }
    const uint32_t slot = lookup_(qs, s);
    return slot == qs->capacity ? zero_row_ : &qs->q[slot * qs->n_actions];
}

const float *qstore_row(const qstore_t *qs, agent_state_t s)
{
    return row_of_(qs, s);
}

// A full probe window: the new state takes the row of the window that has learned least (the
// smallest sum of |Q|: a state seen once or twice), which is emptied. Rows are reused in place,
// so no probe path is broken.
static uint32_t evict_(qstore_t *qs, agent_state_t s)
{
    const uint32_t mask = qs->capacity - 1u;
    uint32_t slot = qs->capacity_shift ? home_(qs, s) : 0u;
    uint32_t victim = slot;
    float least = -1.0f;
    for (uint32_t probe = 0; probe < FW_CFG_MAX_PROBE && probe < qs->capacity; probe++) {
        const float *row = &qs->q[slot * qs->n_actions];
        float sum = 0.0f;
        for (uint32_t a = 0; a < qs->n_actions; a++) {
            sum += row[a] < 0.0f ? -row[a] : row[a];
        }
        if (least < 0.0f || sum < least) {
            least = sum;
            victim = slot;
        }
        slot = (slot + 1u) & mask;
    }
    float *row = &qs->q[victim * qs->n_actions];
    for (uint32_t a = 0; a < qs->n_actions; a++) {
        row[a] = 0.0f;
    }
    qs->keys[victim] = QSTORE_EMPTY;
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
    uint32_t slot = lookup_(qs, s);  // the common case: s has its row
    if (slot == qs->capacity) {
        slot = find_(qs, s);
        if (slot == qs->capacity) {
            if (!may_evict) {
                qs->plan_refused++;
                return NULL;
            }
            slot = evict_(qs, s);
        }
        qs->keys[slot] = s;
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

int qstore_check(const qstore_t *qs, const float *q, const uint32_t *keys, uint32_t state_bits)
{
    const uint32_t n = qs->n_actions;
    for (uint32_t i = 0; i < qs->capacity * n; i++) {
        if (!check_finite(q[i]) || q[i] > QSTORE_VALUE_LIMIT || q[i] < -QSTORE_VALUE_LIMIT) {
            return FW_ERR_CORRUPT;
        }
    }
    if (qs->dense) {
        return FW_OK;
    }
    const uint32_t mask = qs->capacity - 1u;
    const uint32_t limit = FW_CFG_MAX_PROBE < qs->capacity ? FW_CFG_MAX_PROBE : qs->capacity;
    for (uint32_t slot = 0; slot < qs->capacity; slot++) {
        const uint32_t key = keys[slot];
        if (key == QSTORE_EMPTY) {
            for (uint32_t a = 0; a < n; a++) {
                if (q[slot * n + a] != 0.0f) {
                    return FW_ERR_CORRUPT;
                }
            }
        } else if ((state_bits < 32u && (key >> state_bits) != 0u) ||
                   !check_probe_path(keys, mask, qs->capacity_shift ? home_(qs, key) : 0u, slot,
                                     limit)) {
            return FW_ERR_CORRUPT;
        }
    }
    return FW_OK;
}
