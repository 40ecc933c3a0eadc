// SPDX-License-Identifier: MIT
// dynaqpc: a bounded max-priority queue of state-action pairs for prioritized sweeping.
#ifndef AGENT_PQUEUE_H
#define AGENT_PQUEUE_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/oa_table.h"

#ifdef __cplusplus
extern "C" {
#endif

/// One queued item: an opaque 32-bit key (the agent packs a state-action pair into it) and its
/// priority. Keys must not be PQ_NO_KEY.
typedef struct pq_item {
    uint32_t key;    // 4
    float priority;  // 4
    uint32_t slot;   // 4: where this key sits in the position index
} pq_item_t;

/// The one key value a caller may not queue: it marks an empty index slot.
#define PQ_NO_KEY OA_EMPTY

/// Counters, for telemetry and tests. They only ever grow, until pq_clear().
typedef struct pq_stats {
    uint32_t pushed;  ///< keys inserted that were not queued before
    uint32_t raised;  ///< pushes of a queued key that raised its priority
    uint32_t kept;    ///< pushes of a queued key whose priority was already at least as high
    uint32_t dropped; ///< items lost because the queue was full (the lowest priority goes)
    uint32_t popped;  ///< items taken out by pq_pop()
    uint32_t high_water; ///< largest size seen
} pq_stats_t;

/// A min-max heap with a position index, in caller-owned static storage: the highest and the
/// lowest item are both found in O(1), and pushes, pops and drops cost O(log capacity).
///
/// The index is an open-addressing hash table from key to heap position (oa_table.h, half
/// empty, deletion by backward shift), so a key that is already queued has its priority raised in place instead of being queued twice. When the
/// heap is full, a push drops whichever is lowest: the new item or the current minimum.
typedef struct pqueue {
    pq_item_t *heap;        // capacity items
    oa_table_t index;       // PQ_INDEX_SLOTS(capacity) slots: the queued keys
    uint32_t *index_pos;    // heap position of the key in the same slot
    uint32_t capacity;
    uint32_t size;
    pq_stats_t stats;
} pqueue_t;

/// Storage for a queue of `cap` items; the index has 2 * cap slots (load factor <= 0.5).
#define PQ_INDEX_SLOTS(cap) (2u * (cap))

/// Prepares an empty queue over the given arrays. `capacity` must be a power of two in
/// [2, 2^30];
/// `index_keys` and `index_pos` must each hold PQ_INDEX_SLOTS(capacity) entries.
/// Returns FW_OK or FW_ERR_INVAL.
int pq_init(pqueue_t *pq, pq_item_t *heap, uint32_t *index_keys, uint32_t *index_pos,
            uint32_t capacity);

/// Empties the queue and zeroes its counters.
void pq_clear(pqueue_t *pq);

/// Queues `key` with `priority` (>= 0), or raises the priority of the queued `key` if `priority`
/// is higher (a lower or equal one leaves it unchanged). On a full queue the lowest-priority
/// item is dropped and counted; on a tie with the lowest, the new item is the one dropped.
/// PQ_NO_KEY and a NaN priority are refused with no counter changed.
/// Returns true if `key` is queued afterwards.
bool pq_push(pqueue_t *pq, uint32_t key, float priority);

/// Takes out the highest-priority item; either output may be NULL. Returns false, leaving the
/// outputs untouched, if the queue is empty.
bool pq_pop(pqueue_t *pq, uint32_t *key, float *priority);

/// The priority of `key` if queued, else a negative number. O(1) expected.
float pq_priority_of(const pqueue_t *pq, uint32_t key);

/// Number of queued items.
static inline uint32_t pq_size(const pqueue_t *pq)
{
    return pq->size;
}

/// Checks every heap and index invariant; for tests. Returns true when all hold.
bool pq_check(const pqueue_t *pq);

#ifdef __cplusplus
}
#endif

#endif // AGENT_PQUEUE_H
