// SPDX-License-Identifier: MIT
// dynaqpc: bounded max-priority queue: a binary max-heap with an open-addressing position index.
#include "agent/pqueue.h"

#include <stddef.h>
#include <stdint.h>

#include "fw/fw_base.h"
#include "fw/fw_util.h"
#include "inline.h"

// 2 * capacity index slots and every heap position (2 * i + 2) must fit in 32 bits.
#define PQ_MAX_CAPACITY (1u << 30)

FW_STATIC_ASSERT(PQ_NO_KEY == 0xFFFFFFFFu, pq_no_key_is_all_ones);

// Fibonacci hashing: the product's top bits depend on every bit of the key, so packed keys
// (state * actions + action, or fields in high bits) still spread. The 32x32->64 multiply by
// the slot count takes those top log2(slots) bits without storing a shift (one UMULL on a
// Cortex-M4); the low bits of the product would depend only on the key's low bits.
static uint32_t index_home(const pqueue_t *pq, uint32_t key)
{
    uint32_t h = fw_fib_mix(key);
    return (uint32_t)(((uint64_t)h * ((uint64_t)pq->index_mask + 1u)) >> 32);
}

// Looks `key` up. Returns true with its slot, or false with the first empty slot on its probe
// path (where it would be inserted). The index never holds more than half its slots, so an empty
// slot always ends the probe well before the bound.
static bool index_find(const pqueue_t *pq, uint32_t key, uint32_t *slot)
{
    uint32_t mask = pq->index_mask;
    uint32_t s = index_home(pq, key);
    uint32_t n;

    for (n = 0; n <= mask; ++n) {
        uint32_t k = pq->index_keys[s];
        if (k == key || k == PQ_NO_KEY) {
            *slot = s;
            return k == key;
        }
        s = (s + 1u) & mask;
    }
    *slot = s;  // unreachable while size <= capacity; pq_check() would catch a full index
    return false;
}

// Backward-shift deletion: entries after the hole move back into it when their home lies at or
// before the hole, so no tombstones accumulate and probe lengths stay those of a fresh table.
// A moved entry's heap item learns its new slot, keeping heap -> index links O(1).
static void index_remove(pqueue_t *pq, uint32_t hole)
{
    uint32_t mask = pq->index_mask;
    uint32_t j = hole;
    uint32_t n;

    for (n = 0; n < mask; ++n) {
        uint32_t k;
        j = (j + 1u) & mask;
        k = pq->index_keys[j];
        if (k == PQ_NO_KEY) {
            break;
        }
        // Distances are taken modulo the table size so a probe run that wraps past slot 0
        // compares like any other.
        if (((j - index_home(pq, k)) & mask) >= ((j - hole) & mask)) {
            pq->index_keys[hole] = k;
            pq->index_pos[hole] = pq->index_pos[j];
            pq->heap[pq->index_pos[hole]].slot = hole;
            hole = j;
        }
    }
    pq->index_keys[hole] = PQ_NO_KEY;
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
    pq->heap = heap;
    pq->index_keys = index_keys;
    pq->index_pos = index_pos;
    pq->capacity = capacity;
    pq->index_mask = PQ_INDEX_SLOTS(capacity) - 1u;
    pq_clear(pq);
    return FW_OK;
}

void pq_clear(pqueue_t *pq)
{
    uint32_t s;

    // Only the index keys say what is queued; heap items and index positions beyond `size` are
    // never read, so they are left as they are.
    for (s = 0; s <= pq->index_mask; ++s) {
        pq->index_keys[s] = PQ_NO_KEY;
    }
    pq->size = 0;
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
    if (index_find(pq, key, &slot)) {
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
        // equal priorities does not churn the queue.
        pos = heap_min_leaf(pq);
        ++pq->stats.dropped;
        if (!(priority > pq->heap[pos].priority)) {
            return false;
        }
        // The new item takes the leaf's place; being higher than the leaf, it can only need to
        // go up. The removal may shift the new key's probe path, so look its slot up again.
        index_remove(pq, pq->heap[pos].slot);
        (void)index_find(pq, key, &slot);
    }

    pq->index_keys[slot] = key;
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
    index_remove(pq, top.slot);
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
    uint32_t slot;

    if (key == PQ_NO_KEY || !index_find(pq, key, &slot)) {
        return -1.0f;
    }
    return pq->heap[pq->index_pos[slot]].priority;
}

bool pq_check(const pqueue_t *pq)
{
    uint32_t i;
    uint32_t s;
    uint32_t occupied = 0;

    if (pq == NULL || pq->heap == NULL || pq->index_keys == NULL || pq->index_pos == NULL) {
        return false;
    }
    if (pq->capacity < 2u || !FW_IS_POW2(pq->capacity) || pq->capacity > PQ_MAX_CAPACITY ||
        pq->index_mask != PQ_INDEX_SLOTS(pq->capacity) - 1u) {
        return false;
    }
    if (pq->size > pq->capacity || pq->stats.high_water < pq->size) {
        return false;
    }

    // Heap order, and each item's link to the index slot that holds its key and position.
    for (i = 0; i < pq->size; ++i) {
        const pq_item_t *it = &pq->heap[i];
        if (it->key == PQ_NO_KEY || it->priority != it->priority || it->slot > pq->index_mask) {
            return false;
        }
        if (pq->index_keys[it->slot] != it->key || pq->index_pos[it->slot] != i) {
            return false;
        }
        if (i > 0u && !(pq->heap[(i - 1u) / 2u].priority >= it->priority)) {
            return false;
        }
    }

    // The index holds exactly the heap's keys (each entry points at the item that points back,
    // and the counts match), and every key is reachable from its home without an empty slot.
    for (s = 0; s <= pq->index_mask; ++s) {
        uint32_t k = pq->index_keys[s];
        uint32_t t;
        uint32_t n;
        if (k == PQ_NO_KEY) {
            continue;
        }
        ++occupied;
        if (pq->index_pos[s] >= pq->size || pq->heap[pq->index_pos[s]].key != k ||
            pq->heap[pq->index_pos[s]].slot != s) {
            return false;
        }
        t = index_home(pq, k);
        for (n = 0; t != s; ++n) {
            if (n > pq->index_mask || pq->index_keys[t] == PQ_NO_KEY) {
                return false;
            }
            t = (t + 1u) & pq->index_mask;
        }
    }
    return occupied == pq->size;
}
