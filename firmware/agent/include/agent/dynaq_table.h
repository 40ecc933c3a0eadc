// SPDX-License-Identifier: MIT
// dynaqpc: the table model of table-based Dyna-Q (the paper's Fig. 5).
#ifndef AGENT_DYNAQ_TABLE_H
#define AGENT_DYNAQ_TABLE_H

#include <stdbool.h>
#include <stdint.h>

#include "fw/fw_prng.h"
#include "agent/oa_table.h"
#include "agent/region.h"
#include "agent/space.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Bytes of one action mask: a bit per action (FW_CFG_MAX_ACTIONS may be up to 128), rounded
/// up to an even count so that the two masks end on a word boundary and a record has no padding
/// (its bytes are saved to flash as they are).
#define DYNAQ_MASK_BYTES ((((FW_CFG_MAX_ACTIONS) + 15) / 16) * 2)

/// Everything observed in one state: for each action tried there, the last outcome (the model
/// assumes a deterministic environment, as Fig. 5 does).
typedef struct dynaq_record {
    agent_state_t state;
    uint8_t tried[DYNAQ_MASK_BYTES];     ///< bit a (byte a / 8, bit a % 8): a was observed
    uint8_t terminal[DYNAQ_MASK_BYTES];  ///< bit a: a ended the episode
    agent_state_t next[FW_CFG_MAX_ACTIONS];
    float reward[FW_CFG_MAX_ACTIONS];
} dynaq_record_t;

/// Whether bit a of an action mask is set.
static inline bool dynaq_bit(const uint8_t *mask, uint32_t a)
{
    return ((mask[a >> 3] >> (a & 7u)) & 1u) != 0u;
}

/// Records live in a dense array (so a uniformly random observed state is one index) and an
/// open-addressing index (oa_table.h, half empty, deletion by backward shift) maps a state to its
/// record. When the array is full, a new state takes
/// the record of the state first stored longest ago (first in, first out, as a replay buffer),
/// and the forgotten state is counted.
typedef struct dynaq_table {
    dynaq_record_t *records;  // capacity
    oa_table_t index;         // DYNAQ_INDEX_SLOTS(capacity) slots: the recorded states
    uint32_t *index_rec;      // record number of the key in the same slot
    uint32_t capacity;
    uint32_t count;
    uint32_t oldest;   ///< once full: the record a new state takes next
    uint8_t n_actions;
    uint32_t evicted;  ///< states forgotten to make room for new ones
} dynaq_table_t;

#define DYNAQ_EMPTY OA_EMPTY
#define DYNAQ_NO_RECORD UINT32_MAX
/// The largest |reward| a restored record may hold: beyond any robot's settings, and small
/// enough that the values learned from it stay within QSTORE_VALUE_LIMIT (for gamma < 0.999).
#define DYNAQ_REWARD_LIMIT 1e6f
/// The index's slots for `cap` records: the power of two at least twice as many (2 * cap for a
/// power of two), so that the index is at most half full. A constant expression for cap up to
/// 2^30.
// Every bit below x's highest set: each step ORs in the previous step's result shifted, so the
// ones double in length (ORing shifts of x itself leaves gaps: 2,621 gave 4,031, not 4,095).
#define DYNAQ_SMEAR1_(x) ((x) | ((x) >> 1))
#define DYNAQ_SMEAR2_(x) (DYNAQ_SMEAR1_(x) | (DYNAQ_SMEAR1_(x) >> 2))
#define DYNAQ_SMEAR4_(x) (DYNAQ_SMEAR2_(x) | (DYNAQ_SMEAR2_(x) >> 4))
#define DYNAQ_SMEAR8_(x) (DYNAQ_SMEAR4_(x) | (DYNAQ_SMEAR4_(x) >> 8))
#define DYNAQ_POW2_SMEAR_(x) (DYNAQ_SMEAR8_(x) | (DYNAQ_SMEAR8_(x) >> 16))
#define DYNAQ_INDEX_SLOTS(cap) (DYNAQ_POW2_SMEAR_(2u * (uint32_t)(cap) - 1u) + 1u)

/// The most records a table may have in `bytes` (at least sizeof(dynaq_record_t) + extra + 16)
/// when each record also needs `extra` bytes beside it: its records and its index
/// (DYNAQ_INDEX_SLOTS, 8 bytes a slot). With H the largest power of two whose records and 2 H
/// slots fit (H (record + 16) <= bytes), the answer is H or, if more records fit beside 4 H
/// slots, that many (fewer than 2 H, by the choice of H); more slots leave room for fewer.
#define DYNAQ_RECORDS_IN(bytes, extra)                                                         \
    (DYNAQ_FIT4_(bytes, extra) > DYNAQ_HALF_(bytes, extra) ? DYNAQ_FIT4_(bytes, extra)         \
                                                           : DYNAQ_HALF_(bytes, extra))
#define DYNAQ_REC_(extra) ((uint32_t)sizeof(dynaq_record_t) + (uint32_t)(extra))
#define DYNAQ_HALF_(bytes, extra) \
    ((DYNAQ_POW2_SMEAR_((uint32_t)(bytes) / (DYNAQ_REC_(extra) + 16u)) >> 1) + 1u)
#define DYNAQ_FIT4_(bytes, extra)                                                              \
    ((uint32_t)(bytes) >= 32u * DYNAQ_HALF_(bytes, extra)                                      \
         ? ((uint32_t)(bytes) - 32u * DYNAQ_HALF_(bytes, extra)) / DYNAQ_REC_(extra)           \
         : 0u)

/// Prepares an empty table of `capacity` records (any number from 1; a profile gives the table
/// the bytes it has). Returns FW_OK or FW_ERR_INVAL.
int dynaq_init(dynaq_table_t *t, dynaq_record_t *records, uint32_t *index_keys,
               uint32_t *index_rec, uint32_t capacity, uint8_t n_actions);

/// Forgets everything.
void dynaq_clear(dynaq_table_t *t);

/// Model(s, a) <- s', r (Fig. 5 step e). Returns the number of the record that holds s now (a
/// state new to the table takes a fresh record: no action tried but a), or DYNAQ_NO_RECORD if
/// the index had no slot for it (cannot happen: it is at most half full).
uint32_t dynaq_remember(dynaq_table_t *t, agent_state_t s, uint8_t a, float r,
                        agent_state_t s_next, bool terminal);

/// The record of state s, or NULL if the table holds none.
const dynaq_record_t *dynaq_find(const dynaq_table_t *t, agent_state_t s);

/// Fig. 5 step f: a random previously observed state, then a random action previously taken in
/// it, and its recorded outcome. Returns false if nothing has been observed.
bool dynaq_sample(const dynaq_table_t *t, prng_t *rng, agent_state_t *s, uint8_t *a, float *r,
                  agent_state_t *s_next, bool *terminal);

/// The regions dynaq_regions() lists.
#define DYNAQ_REGIONS 3u

/// Lists the memory that holds what the table learned, in a fixed order: the records, the
/// index's keys, the index's record numbers. Returns DYNAQ_REGIONS.
uint32_t dynaq_regions(const dynaq_table_t *t, agent_region_t *out);

/// Checks restored contents before they are copied into `t` (which gives the shape: capacity,
/// actions): image[i] holds the bytes of region i as dynaq_regions() lists them (capacity records,
/// DYNAQ_INDEX_SLOTS(capacity) keys and record numbers). The index must hold at most `capacity`
/// states, each of `state_bits` bits, found by a search from its home slot (no empty slot and no
/// copy of it before it), pointing at a record below the count that names the same state: so the
/// records in use are exactly the first `count` and every one is indexed once. Each of those
/// must have at least one action tried and none past n_actions, terminal bits only on tried
/// actions, and for every tried action a next state of `state_bits` bits and a finite reward
/// within DYNAQ_REWARD_LIMIT. Reads only. Returns FW_OK or FW_ERR_CORRUPT.
int dynaq_check(const dynaq_table_t *t, const void *const *image, uint32_t state_bits);

/// After contents that passed dynaq_check() were copied into the regions: recounts the records
/// in use (the table's fill, which only the table computes) and starts replacing from record 0;
/// `evicted` starts again from 0.
void dynaq_restored(dynaq_table_t *t);

#ifdef __cplusplus
}
#endif

#endif // AGENT_DYNAQ_TABLE_H
