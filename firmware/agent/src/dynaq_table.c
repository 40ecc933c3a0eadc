// SPDX-License-Identifier: MIT
// dynaqpc: the transition table of table-based Dyna-Q.
#include "agent/dynaq_table.h"

#include <stddef.h>
#include <string.h>

#include "check.h"
#include "fw/fw_base.h"
#include "fw/fw_util.h"

int dynaq_init(dynaq_table_t *t, dynaq_record_t *records, uint32_t *index_keys,
               uint32_t *index_rec, uint32_t capacity, uint8_t n_actions)
{
    if (t == NULL || records == NULL || index_keys == NULL || index_rec == NULL ||
        !FW_IS_POW2(capacity) || n_actions < 1u || n_actions > FW_CFG_MAX_ACTIONS) {
        return FW_ERR_INVAL;
    }
    t->records = records;
    t->index_keys = index_keys;
    t->index_rec = index_rec;
    t->capacity = capacity;
    t->index_mask = DYNAQ_INDEX_SLOTS(capacity) - 1u;
    t->n_actions = n_actions;
    dynaq_clear(t);
    return FW_OK;
}

void dynaq_clear(dynaq_table_t *t)
{
    for (uint32_t i = 0; i <= t->index_mask; i++) {
        t->index_keys[i] = DYNAQ_EMPTY;
    }
    t->count = 0;
    t->oldest = 0;
    t->evicted = 0;
}

static uint32_t home_(const dynaq_table_t *t, agent_state_t s)
{
    return fw_fib_mix(s) & t->index_mask;
}

// Linear probing without tombstones (Knuth's Algorithm R): empty the slot, then move back every
// key after it in its run that would no longer be found from its home slot.
static void unindex_(dynaq_table_t *t, agent_state_t s)
{
    uint32_t hole = home_(t, s);
    while (t->index_keys[hole] != s) {
        hole = (hole + 1u) & t->index_mask;
    }
    t->index_keys[hole] = DYNAQ_EMPTY;
    for (uint32_t j = (hole + 1u) & t->index_mask; t->index_keys[j] != DYNAQ_EMPTY;
         j = (j + 1u) & t->index_mask) {
        const uint32_t h = home_(t, t->index_keys[j]);
        // The key at j stays if its home lies cyclically in (hole, j].
        const bool stays = hole <= j ? (h > hole && h <= j) : (h > hole || h <= j);
        if (!stays) {
            t->index_keys[hole] = t->index_keys[j];
            t->index_rec[hole] = t->index_rec[j];
            t->index_keys[j] = DYNAQ_EMPTY;
            hole = j;
        }
    }
}

void dynaq_remember(dynaq_table_t *t, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                  bool terminal)
{
    // The index has twice as many slots as there are records, so its load stays at or below
    // one half and a probe always ends at the key or at an empty slot.
    uint32_t slot = home_(t, s);
    while (t->index_keys[slot] != s && t->index_keys[slot] != DYNAQ_EMPTY) {
        slot = (slot + 1u) & t->index_mask;
    }
    if (t->index_keys[slot] == DYNAQ_EMPTY) {
        uint32_t rec_no = t->count;
        if (t->count == t->capacity) {  // the oldest state makes room
            rec_no = t->oldest;
            t->oldest = (t->oldest + 1u) & (t->capacity - 1u);
            unindex_(t, t->records[rec_no].state);
            t->evicted++;
            slot = home_(t, s);  // the move-back may have emptied a slot before this one
            while (t->index_keys[slot] != DYNAQ_EMPTY) {
                slot = (slot + 1u) & t->index_mask;
            }
        } else {
            t->count++;
        }
        dynaq_record_t *fresh = &t->records[rec_no];
        fresh->state = s;
        memset(fresh->tried, 0, sizeof fresh->tried);
        memset(fresh->terminal, 0, sizeof fresh->terminal);
        t->index_keys[slot] = s;
        t->index_rec[slot] = rec_no;
    }
    dynaq_record_t *rec = &t->records[t->index_rec[slot]];
    const uint8_t bit = (uint8_t)(1u << (a & 7u));
    rec->tried[a >> 3] |= bit;
    rec->terminal[a >> 3] =
        (uint8_t)(terminal ? (rec->terminal[a >> 3] | bit) : (rec->terminal[a >> 3] & ~bit));
    rec->next[a] = s_next;
    rec->reward[a] = r;
}

bool dynaq_sample(const dynaq_table_t *t, prng_t *rng, agent_state_t *s, uint8_t *a, float *r,
                  agent_state_t *s_next, bool *terminal)
{
    if (t->count == 0) {
        return false;
    }
    const dynaq_record_t *rec = &t->records[prng_below(rng, t->count)];
    uint32_t tried = 0;
    for (uint32_t b = 0; b < t->n_actions; b++) {
        tried += dynaq_bit(rec->tried, b);
    }
    uint32_t pick = prng_below(rng, tried);
    uint32_t action = 0;
    for (; action < t->n_actions; action++) {
        if (dynaq_bit(rec->tried, action)) {
            if (pick == 0u) {
                break;
            }
            pick--;
        }
    }
    *s = rec->state;
    *a = (uint8_t)action;
    *r = rec->reward[action];
    *s_next = rec->next[action];
    *terminal = dynaq_bit(rec->terminal, action);
    return true;
}

static bool state_ok_(agent_state_t s, uint32_t state_bits)
{
    return state_bits >= 32u || (s >> state_bits) == 0u;
}

static bool record_ok_(const dynaq_table_t *t, const dynaq_record_t *rec, uint32_t state_bits)
{
    bool any = false;
    for (uint32_t a = 0; a < 8u * DYNAQ_MASK_BYTES; a++) {
        const bool tried = dynaq_bit(rec->tried, a);
        if ((tried && a >= t->n_actions) || (!tried && dynaq_bit(rec->terminal, a))) {
            return false;  // an action the robot does not have, or an outcome never observed
        }
        if (tried && (!state_ok_(rec->next[a], state_bits) || !check_finite(rec->reward[a]) ||
                      rec->reward[a] > DYNAQ_REWARD_LIMIT || rec->reward[a] < -DYNAQ_REWARD_LIMIT)) {
            return false;
        }
        any = any || tried;
    }
    return any;  // a record exists because an action was observed in its state
}

int dynaq_check(const dynaq_table_t *t, const dynaq_record_t *records, const uint32_t *index_keys,
                const uint32_t *index_rec, uint32_t state_bits)
{
    const uint32_t slots = t->index_mask + 1u;
    uint32_t count = 0;
    for (uint32_t i = 0; i < slots; i++) {
        count += index_keys[i] != DYNAQ_EMPTY;
    }
    // More states than records would overrun the record array; a full index would make every
    // search for a new state spin for ever.
    if (count > t->capacity) {
        return FW_ERR_CORRUPT;
    }
    for (uint32_t i = 0; i < slots; i++) {
        const uint32_t key = index_keys[i];
        if (key == DYNAQ_EMPTY) {
            continue;
        }
        // Keys are unique and each names its record, so the count records pointed at are the
        // first count, each once.
        if (!state_ok_(key, state_bits) || index_rec[i] >= count ||
            records[index_rec[i]].state != key ||
            !check_probe_path(index_keys, t->index_mask, home_(t, key), i, slots)) {
            return FW_ERR_CORRUPT;
        }
    }
    for (uint32_t r = 0; r < count; r++) {
        if (!record_ok_(t, &records[r], state_bits)) {
            return FW_ERR_CORRUPT;
        }
    }
    return FW_OK;
}

void dynaq_restored(dynaq_table_t *t)
{
    uint32_t count = 0;
    for (uint32_t i = 0; i <= t->index_mask; i++) {
        count += t->index_keys[i] != DYNAQ_EMPTY;
    }
    t->count = count;
    t->oldest = 0;
    t->evicted = 0;
}
