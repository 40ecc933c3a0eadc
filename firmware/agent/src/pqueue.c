// SPDX-License-Identifier: MIT
// dynaqpc: bounded max-priority queue: a binary max-heap with an open-addressing position index.
#include "agent/pqueue.h"

#include <float.h>
#include <stddef.h>
#include <stdint.h>

#include "fw/fw_base.h"
#include "inline.h"

// 2 * capacity index slots and every heap position (2 * i + 2) must fit in 32 bits.
#define PQ_MAX_CAPACITY (1u << 30)

FW_STATIC_ASSERT(PQ_NO_KEY == 0xFFFFFFFFu, pq_no_key_is_all_ones);

// The index (oa_table.h): a half-empty open-addressing table from key to heap position, homes
// from the top bits of the key's Fibonacci hash, which depend on every bit of the key, so packed
// keys (state * actions + action, or fields in high bits) still spread. It never holds more than
// half its slots (size <= capacity = slots / 2), so a search always ends at the key or at an
// empty slot well before the bound.

// Where `key` is queued in the index (its slot), or OA_NONE.
AGENT_ALWAYS_INLINE uint32_t index_of_(const pqueue_t *pq, uint32_t key)
{
    const uint32_t slot = oa_find(&pq->index, key);
    return slot != OA_NONE && pq->index.keys[slot] == key ? slot : OA_NONE;
}

// oa_remove()'s report of a key moved back into a hole: its heap position follows, and the heap
// item learns its new slot, keeping heap -> index links O(1).
AGENT_ALWAYS_INLINE void index_moved_(void *ctx, uint32_t from, uint32_t to)
{
    pqueue_t *const pq = ctx;
    pq->index_pos[to] = pq->index_pos[from];
    pq->heap[pq->index_pos[to]].slot = to;
}

// Backward-shift deletion: no tombstones accumulate and probe lengths stay those of a fresh
// table.
static void index_remove_(pqueue_t *pq, uint32_t slot)
{
    oa_remove(&pq->index, slot, index_moved_, pq);
}

AGENT_ALWAYS_INLINE void heap_place(pqueue_t *pq, uint32_t pos, const pq_item_t *item)
{
    pq->heap[pos] = *item;
    pq->index_pos[item->slot] = pos;
}

// Both sifts carry the item in hand and move the others one level, writing it once at the end.
// Ties do not move, so an equal priority never costs a swap.
static void heap_sift_up(pqueue_t *pq, uint32_t pos)
{
    pq_item_t item = pq->heap[pos];

    while (pos > 0u) {
        uint32_t parent = (pos - 1u) / 2u;
        if (!(item.priority > pq->heap[parent].priority)) {
            break;
        }
        heap_place(pq, pos, &pq->heap[parent]);
        pos = parent;
    }
    heap_place(pq, pos, &item);
}

static void heap_sift_down(pqueue_t *pq, uint32_t pos)
{
    pq_item_t item = pq->heap[pos];
    uint32_t size = pq->size;

    while (2u * pos + 1u < size) {
        uint32_t child = 2u * pos + 1u;
        if (child + 1u < size && pq->heap[child + 1u].priority > pq->heap[child].priority) {
            ++child;
        }
        if (!(pq->heap[child].priority > item.priority)) {
            break;
        }
        heap_place(pq, pos, &pq->heap[child]);
        pos = child;
    }
    heap_place(pq, pos, &item);
}

// The minimum of a max-heap is always among the leaves, the second half of the array, so only
// size / 2 items need a look. Called on a full queue only, where size >= 2.
static uint32_t heap_min_leaf(const pqueue_t *pq)
{
    uint32_t best = pq->size / 2u;
    uint32_t i;

    for (i = best + 1u; i < pq->size; ++i) {
        if (pq->heap[i].priority < pq->heap[best].priority) {
            best = i;
        }
    }
    return best;
}

int pq_init(pqueue_t *pq, pq_item_t *heap, uint32_t *index_keys, uint32_t *index_pos,
            uint32_t capacity)
{
    if (pq == NULL || heap == NULL || index_keys == NULL || index_pos == NULL || capacity < 2u ||
        !FW_IS_POW2(capacity) || capacity > PQ_MAX_CAPACITY) {
        return FW_ERR_INVAL;
    }
    const uint32_t slots = PQ_INDEX_SLOTS(capacity);
    if (oa_init(&pq->index, index_keys, slots, slots, OA_HOME_HIGH) != FW_OK) {
        return FW_ERR_INVAL;
    }
    pq->heap = heap;
    pq->index_pos = index_pos;
    pq->capacity = capacity;
    pq_clear(pq);
    return FW_OK;
}

void pq_clear(pqueue_t *pq)
{
    // Only the index keys say what is queued; heap items and index positions beyond `size` are
    // never read, so they are left as they are.
    oa_clear(&pq->index);
    pq->size = 0;
    pq->floor = FLT_MAX;
    pq->stats.pushed = 0;
    pq->stats.raised = 0;
    pq->stats.kept = 0;
    pq->stats.dropped = 0;
    pq->stats.popped = 0;
    pq->stats.high_water = 0;
}

bool pq_push(pqueue_t *pq, uint32_t key, float priority)
{
    uint32_t slot;
    uint32_t pos;
    pq_item_t item;

    // A NaN compares false with everything and would silently break the heap order.
    if (key == PQ_NO_KEY || priority != priority) {
        return false;
    }
    slot = oa_find(&pq->index, key);
    if (slot == OA_NONE) {
        return false;  // cannot happen: at most half the index's slots hold a key
    }
    if (pq->index.keys[slot] == key) {
        pos = pq->index_pos[slot];
        if (priority > pq->heap[pos].priority) {
            pq->heap[pos].priority = priority;
            heap_sift_up(pq, pos);
            ++pq->stats.raised;
        } else {
            ++pq->stats.kept;
        }
        return true;
    }

    if (pq->size < pq->capacity) {
        pos = pq->size++;
        if (pq->size > pq->stats.high_water) {
            pq->stats.high_water = pq->size;
        }
    } else {
        // Full: something is dropped either way. On a tie the queued item stays, so a stream of
        // equal priorities does not churn the queue. Finding the lowest item is a scan of the
        // leaves; `floor` is a bound below every queued priority (the lowest a scan found, or a
        // lower one pushed since: raises, pops and replacements never lower the lowest), so an
        // item at or below it is dropped without one. On a full paper-lab queue that is most of
        // the drops.
        ++pq->stats.dropped;
        if (!(priority > pq->floor)) {
            return false;
        }
        pos = heap_min_leaf(pq);
        pq->floor = pq->heap[pos].priority;
        if (!(priority > pq->heap[pos].priority)) {
            return false;
        }
        // The new item takes the leaf's place; being higher than the leaf, it can only need to
        // go up. The removal may shift the new key's probe path, so look its slot up again.
        index_remove_(pq, pq->heap[pos].slot);
        slot = oa_find(&pq->index, key);
    }

    oa_put(&pq->index, slot, key);
    if (priority < pq->floor) {
        pq->floor = priority;
    }
    item.key = key;
    item.priority = priority;
    item.slot = slot;
    heap_place(pq, pos, &item);
    heap_sift_up(pq, pos);
    ++pq->stats.pushed;
    return true;
}

bool pq_pop(pqueue_t *pq, uint32_t *key, float *priority)
{
    pq_item_t top;

    if (pq->size == 0u) {
        return false;
    }
    top = pq->heap[0];
    // Unlink from the index first: the shift may update slots of items still in the heap,
    // including the last one, which is about to move.
    index_remove_(pq, top.slot);
    --pq->size;
    if (pq->size > 0u) {
        pq->heap[0] = pq->heap[pq->size];
        heap_sift_down(pq, 0);
    }
    ++pq->stats.popped;
    if (key != NULL) {
        *key = top.key;
    }
    if (priority != NULL) {
        *priority = top.priority;
    }
    return true;
}

float pq_priority_of(const pqueue_t *pq, uint32_t key)
{
    const uint32_t slot = key == PQ_NO_KEY ? OA_NONE : index_of_(pq, key);
    if (slot == OA_NONE) {
        return -1.0f;
    }
    return pq->heap[pq->index_pos[slot]].priority;
}

bool pq_check(const pqueue_t *pq)
{
    uint32_t i;
    uint32_t s;
    uint32_t occupied = 0;

    if (pq == NULL || pq->heap == NULL || pq->index.keys == NULL || pq->index_pos == NULL) {
        return false;
    }
    if (pq->capacity < 2u || !FW_IS_POW2(pq->capacity) || pq->capacity > PQ_MAX_CAPACITY ||
        oa_slots(&pq->index) != PQ_INDEX_SLOTS(pq->capacity)) {
        return false;
    }
    if (pq->size > pq->capacity || pq->stats.high_water < pq->size) {
        return false;
    }

    // Heap order, and each item's link to the index slot that holds its key and position.
    const uint32_t *const keys = pq->index.keys;
    for (i = 0; i < pq->size; ++i) {
        const pq_item_t *it = &pq->heap[i];
        if (it->key == PQ_NO_KEY || it->priority != it->priority || it->slot > pq->index.mask) {
            return false;
        }
        if (keys[it->slot] != it->key || pq->index_pos[it->slot] != i) {
            return false;
        }
        if (i > 0u && !(pq->heap[(i - 1u) / 2u].priority >= it->priority)) {
            return false;
        }
        if (!(it->priority >= pq->floor)) {
            return false;
        }
    }

    // The index holds exactly the heap's keys (each entry points at the item that points back,
    // and the counts match), and every key is where a search from its home finds it.
    for (s = 0; s <= pq->index.mask; ++s) {
        const uint32_t k = keys[s];
        if (k == PQ_NO_KEY) {
            continue;
        }
        ++occupied;
        if (pq->index_pos[s] >= pq->size || pq->heap[pq->index_pos[s]].key != k ||
            pq->heap[pq->index_pos[s]].slot != s || !oa_path_ok(&pq->index, keys, s)) {
            return false;
        }
    }
    return occupied == pq->size;
}
