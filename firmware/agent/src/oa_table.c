// SPDX-License-Identifier: MIT
// dynaqpc: the open-addressing key index that the agent's hashed tables share.
#include "agent/oa_table.h"

#include <string.h>

#include "fw/fw_base.h"

FW_STATIC_ASSERT(OA_EMPTY == 0xFFFFFFFFu, oa_empty_is_all_ones);  // oa_clear memsets 0xFF

// Why one index for four tables: the Q store, the CMAC, the priority queue and the Dyna-Q table
// each had a probe loop, a delete or an eviction scan and a restore check of their own, written
// four times with four loop bounds and two ways of testing "is this key still reachable". The
// invariant they all rely on is the same (a key lies fewer than `limit` slots past its home with
// no empty slot before it), so it is kept in one place, and each table keeps only what differs:
// its payload, its eviction score and its counters.
//
// Linear probing, because a probe window of FW_CFG_MAX_PROBE consecutive words is one cache line
// pair on the host and a pointer walk on the Cortex-M4 (oa_scan_window), and because backward-
// shift deletion exists for it: no tombstones, so a long-lived index never degrades.

int oa_init(oa_table_t *t, uint32_t *keys, uint32_t slots, uint32_t limit, oa_home_t home)
{
    if (t == NULL || keys == NULL || !FW_IS_POW2(slots) || limit < 1u || limit > slots ||
        (home != OA_HOME_HIGH && home != OA_HOME_LOW)) {
        return FW_ERR_INVAL;
    }
    t->keys = keys;
    t->mask = slots - 1u;
    t->limit = limit;
    // A window scanned by pointer must lie within the array: homes up to slots - FW_CFG_MAX_PROBE.
    t->scan_below = limit == FW_CFG_MAX_PROBE ? slots - FW_CFG_MAX_PROBE + 1u : 0u;
    // A home is the top b = log2(slots) bits of key * FW_FIB_HASH_MUL, or its low b bits. The low
    // ones are the top bits of the product shifted left by 32 - b, which is key times the
    // multiplier shifted left so (mod 2^32): both are one multiply and one shift by 32 - b, and
    // neither needs a mask. With one slot every home is 0 (a shift by 32 would be undefined).
    const uint32_t bits = fw_log2_ceil(slots);
    if (slots == 1u) {
        t->mul = 0;
        t->shift = 0;
    } else {
        t->mul = home == OA_HOME_LOW ? FW_FIB_HASH_MUL << (32u - bits) : FW_FIB_HASH_MUL;
        t->shift = 32u - bits;
    }
    return FW_OK;
}

void oa_clear(oa_table_t *t)
{
    // OA_EMPTY is every bit set: a memset, as in model_clear.
    memset(t->keys, 0xFF, ((size_t)t->mask + 1u) * sizeof *t->keys);
}

// Eviction happens on a real step's write only (planning never evicts), so a call per scored
// slot costs nothing that matters; the first of equal scores wins, which makes the choice
// depend on nothing but the table's contents.
uint32_t oa_least(const oa_table_t *t, uint32_t key, oa_score_fn score, void *ctx)
{
    uint32_t slot = oa_home(t, key);
    uint32_t victim = OA_NONE;
    uint32_t least = OA_SKIP;
    for (uint32_t probe = 0; probe < t->limit; probe++, slot = (slot + 1u) & t->mask) {
        const uint32_t s = score(ctx, slot);
        if (s < least) {
            least = s;
            victim = slot;
        }
    }
    return victim;
}

// A restored key that fails this would be invisible to every search (past an empty slot or the
// limit), or shadowed by an earlier copy; either way the table's counts and contents would
// disagree, and an insert could store the same key twice.
bool oa_path_ok(const oa_table_t *t, const uint32_t *keys, uint32_t slot)
{
    const uint32_t key = keys[slot];
    const uint32_t home = oa_home(t, key);
    if (((slot - home) & t->mask) >= t->limit) {
        return false;
    }
    for (uint32_t j = home; j != slot; j = (j + 1u) & t->mask) {
        if (keys[j] == OA_EMPTY || keys[j] == key) {
            return false;
        }
    }
    return true;
}

uint32_t oa_count(const oa_table_t *t, const uint32_t *keys)
{
    uint32_t used = 0;
    for (uint32_t i = 0; i <= t->mask; i++) {
        used += keys[i] != OA_EMPTY;
    }
    return used;
}
