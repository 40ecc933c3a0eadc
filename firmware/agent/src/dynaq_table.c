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
        capacity < 1u || capacity > (1u << 30) || n_actions < 1u || n_actions > FW_CFG_MAX_ACTIONS) {
        return FW_ERR_INVAL;
    }
    // The index: half empty (twice as many slots as records), so a search always ends at the key
    // or at an empty slot; homes from the low bits of the state's hash, as the index has always
    // been laid out (saved tables stay valid).
    const uint32_t slots = DYNAQ_INDEX_SLOTS(capacity);
    if (oa_init(&t->index, index_keys, slots, slots, OA_HOME_LOW) != FW_OK) {
        return FW_ERR_INVAL;
    }
    t->records = records;
    t->index_rec = index_rec;
    t->capacity = capacity;
    t->n_actions = n_actions;
    dynaq_clear(t);
    return FW_OK;
}

void dynaq_clear(dynaq_table_t *t)
{
    oa_clear(&t->index);
    t->count = 0;
    t->oldest = 0;
    t->evicted = 0;
}

// oa_remove()'s report of a state moved back into a hole: its record number follows.
static void index_moved_(void *ctx, uint32_t from, uint32_t to)
{
    dynaq_table_t *const t = ctx;
    t->index_rec[to] = t->index_rec[from];
}

uint32_t dynaq_remember(dynaq_table_t *t, agent_state_t s, uint8_t a, float r,
                        agent_state_t s_next, bool terminal)
{
    uint32_t slot = oa_find(&t->index, s);
    if (slot == OA_NONE) {
        return DYNAQ_NO_RECORD;  // cannot happen: at most half the index's slots hold a state
    }
    if (t->index.keys[slot] == DYNAQ_EMPTY) {
        uint32_t rec_no = t->count;
        if (t->count == t->capacity) {  // the oldest state makes room
            rec_no = t->oldest;
            t->oldest = t->oldest + 1u == t->capacity ? 0u : t->oldest + 1u;
            oa_remove(&t->index, oa_find(&t->index, t->records[rec_no].state), index_moved_, t);
            t->evicted++;
            slot = oa_find(&t->index, s);  // the shift may have emptied a slot before this one
        } else {
            t->count++;
        }
        dynaq_record_t *fresh = &t->records[rec_no];
        fresh->state = s;
        memset(fresh->tried, 0, sizeof fresh->tried);
        memset(fresh->terminal, 0, sizeof fresh->terminal);
        oa_put(&t->index, slot, s);
        t->index_rec[slot] = rec_no;
    }
    const uint32_t rec_no = t->index_rec[slot];
    dynaq_record_t *rec = &t->records[rec_no];
    const uint8_t bit = (uint8_t)(1u << (a & 7u));
    rec->tried[a >> 3] |= bit;
    rec->terminal[a >> 3] =
        (uint8_t)(terminal ? (rec->terminal[a >> 3] | bit) : (rec->terminal[a >> 3] & ~bit));
    rec->next[a] = s_next;
    rec->reward[a] = r;
    return rec_no;
}

const dynaq_record_t *dynaq_find(const dynaq_table_t *t, agent_state_t s)
{
    const uint32_t slot = oa_lookup(&t->index, s, false);
    return slot == OA_NONE ? NULL : &t->records[t->index_rec[slot]];
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

uint32_t dynaq_regions(const dynaq_table_t *t, agent_region_t *out)
{
    const uint32_t index_bytes = DYNAQ_INDEX_SLOTS(t->capacity) * (uint32_t)sizeof(uint32_t);
    uint32_t n = agent_region_add(out, 0, t->records, t->capacity * (uint32_t)sizeof(dynaq_record_t));
    n = agent_region_add(out, n, t->index.keys, index_bytes);
    return agent_region_add(out, n, t->index_rec, index_bytes);
}

int dynaq_check(const dynaq_table_t *t, const void *const *image, uint32_t state_bits)
{
    const dynaq_record_t *const records = image[0];
    const uint32_t *const index_keys = image[1];
    const uint32_t *const index_rec = image[2];
    const uint32_t slots = oa_slots(&t->index);
    // More states than records would overrun the record array; a full index would make every
    // search for a new state spin for ever.
    const uint32_t count = oa_count(&t->index, index_keys);
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
            records[index_rec[i]].state != key || !oa_path_ok(&t->index, index_keys, i)) {
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
    t->count = oa_count(&t->index, t->index.keys);
    t->oldest = 0;
    t->evicted = 0;
}
