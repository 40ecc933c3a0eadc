// SPDX-License-Identifier: MIT
// dynaqpc: the tried-pairs table of directed exploration (explore.h).
#include "agent/explore.h"

#include <math.h>
#include <stddef.h>

#include "fw/fw_base.h"
#include "fw/fw_util.h"

int explore_init(explore_table_t *t, uint32_t *keys, uint32_t *tried_at, uint32_t capacity)
{
    if (t == NULL || keys == NULL || tried_at == NULL || !FW_IS_POW2(capacity)) {
        return FW_ERR_INVAL;
    }
    if (oa_init(&t->index, keys, capacity, oa_probe_limit(capacity), OA_HOME_HIGH) != FW_OK) {
        return FW_ERR_INVAL;
    }
    t->tried_at = tried_at;
    t->capacity = capacity;
    explore_clear(t);
    return FW_OK;
}

void explore_clear(explore_table_t *t)
{
    oa_clear(&t->index);
    for (uint32_t i = 0; i < t->capacity; i++) {
        t->tried_at[i] = 0u;
    }
    t->used = 0u;
    t->forgotten = 0u;
}

// Older goes first: a full window forgets the pair whose tau is largest, which a missing pair's
// tau (now) changes least.
static uint32_t age_score_(void *ctx, uint32_t slot)
{
    const explore_table_t *t = ctx;
    return t->tried_at[slot];
}

void explore_tried(explore_table_t *t, uint32_t pair, uint32_t now)
{
    FW_ASSERT((pair >> 31) == 0u);
    uint32_t slot = oa_lookup(&t->index, pair, t->used == t->capacity);
    if (slot == OA_NONE) {
        slot = oa_insert(&t->index, pair);
        if (slot == OA_NONE) {
            slot = oa_least(&t->index, pair, age_score_, t);
            oa_put(&t->index, slot, pair);
            t->forgotten++;
        } else {
            t->used++;
        }
    }
    t->tried_at[slot] = now;
}

uint32_t explore_untried_for(const explore_table_t *t, uint32_t pair, uint32_t now)
{
    uint32_t tau;
    return explore_last_tried(t, pair, now, &tau) ? tau : now;
}

bool explore_last_tried(const explore_table_t *t, uint32_t pair, uint32_t now, uint32_t *tau)
{
    const uint32_t slot = oa_lookup(&t->index, pair, t->used == t->capacity);
    if (slot == OA_NONE) {
        return false;
    }
    const uint32_t when = t->tried_at[slot];
    *tau = when <= now ? now - when : 0u;
    return true;
}

bool explore_sample(const explore_table_t *t, prng_t *rng, uint32_t *pair)
{
    if (t->used == 0u) {
        return false;
    }
    uint32_t slot = prng_below(rng, t->capacity);
    while (t->index.keys[slot] == OA_EMPTY) {  // ends: some slot holds a pair
        slot = (slot + 1u) & (t->capacity - 1u);
    }
    *pair = t->index.keys[slot];
    return true;
}

float explore_bonus(float kappa, uint32_t tau)
{
    return kappa * sqrtf((float)tau);
}
