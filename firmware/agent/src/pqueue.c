// SPDX-License-Identifier: MIT
// dynaqpc: bounded max-priority queue: a min-max heap with an open-addressing position index.
#include "agent/pqueue.h"

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

// ---- The min-max heap (Atkinson, Sack, Santoro & Strothotte 1986) ----------------------------
// Positions on even levels (the root's, its grandchildren's, ...) hold the minimum of their
// subtree, on odd levels the maximum, so the lowest item is the root and the highest is one of
// its children: a full queue finds what to drop in O(1) and replaces it in O(log n), where a
// max-heap scans its leaves (the cost of every drop on a full queue: 23 % of a Cortex-M4
// planning update on paper-lab). All moves carry the item in hand and write it once at the end;
// comparisons are strict, so equal priorities never move.

// True on a min level: the level, floor(log2(pos + 1)), is even, that is the highest set bit of
// pos + 1 sits at an even bit position, and then the even bits alone outweigh the odd ones.
AGENT_ALWAYS_INLINE bool on_min_level_(uint32_t pos)
{
    const uint32_t n = pos + 1u;
    return (n & 0x55555555u) > (n & 0xAAAAAAAAu);
}

// True if an item of priority x belongs above one of priority y on this kind of level: the
// higher on a max level, the lower on a min level.
AGENT_ALWAYS_INLINE bool before_(float x, float y, bool max_level)
{
    return max_level ? x > y : x < y;
}

// Moves `item` from the hole at `pos` up along the grandparents of its own kind of level.
AGENT_ALWAYS_INLINE uint32_t bubble_up_kind_(pqueue_t *pq, uint32_t pos, const pq_item_t *item,
                                             bool max_level)
{
    while (pos > 2u) {
        const uint32_t grand = ((pos - 1u) / 2u - 1u) / 2u;
        if (!before_(item->priority, pq->heap[grand].priority, max_level)) {
            break;
        }
        heap_place(pq, pos, &pq->heap[grand]);
        pos = grand;
    }
    return pos;
}

// Places `item` into the hole at `pos`, moving it up to where both orders hold above it.
static void heap_bubble_up(pqueue_t *pq, uint32_t pos, const pq_item_t *item)
{
    bool max_level = !on_min_level_(pos);
    if (pos > 0u) {
        const uint32_t parent = (pos - 1u) / 2u;
        // An item on the wrong side of its parent belongs to the parent's kind of level.
        if (before_(pq->heap[parent].priority, item->priority, max_level)) {
            heap_place(pq, pos, &pq->heap[parent]);
            pos = parent;
            max_level = !max_level;
        }
    }
    heap_place(pq, bubble_up_kind_(pq, pos, item, max_level), item);
}

// Moves `item` from the hole at `pos`, on a level of the given kind, down to where both orders
// hold below it. Inlined with a constant kind, so each comparison is one instruction.
AGENT_ALWAYS_INLINE void trickle_down_kind_(pqueue_t *pq, uint32_t pos, pq_item_t item,
                                            const bool max_level)
{
    const uint32_t size = pq->size;
    const pq_item_t *const h = pq->heap;
    for (;;) {
        // The most extreme of the children and the grandchildren (4 pos + 3 to 4 pos + 6).
        const uint32_t child = 2u * pos + 1u;
        if (child >= size) {
            break;
        }
        uint32_t best = child;
        if (child + 1u < size && before_(h[child + 1u].priority, h[best].priority, max_level)) {
            best = child + 1u;
        }
        const uint32_t first_grand = 2u * child + 1u;
        const uint32_t end = first_grand + 4u < size ? first_grand + 4u : size;
        for (uint32_t g = first_grand; g < end; g++) {
            if (before_(h[g].priority, h[best].priority, max_level)) {
                best = g;
            }
        }
        if (!before_(h[best].priority, item.priority, max_level)) {
            break;
        }
        heap_place(pq, pos, &h[best]);
        pos = best;
        if (best < first_grand) {  // a child: the other kind of level, with nothing to pass below
            break;
        }
        // A grandchild's place: the item may be on the wrong side of the parent between.
        const uint32_t parent = (best - 1u) / 2u;
        if (before_(h[parent].priority, item.priority, max_level)) {
            const pq_item_t swapped = h[parent];
            heap_place(pq, parent, &item);
            item = swapped;
        }
    }
    heap_place(pq, pos, &item);
}

// Places `item` into the hole at `pos`, moving it down to where both orders hold below it.
static void heap_trickle_down(pqueue_t *pq, uint32_t pos, const pq_item_t *item)
{
    if (on_min_level_(pos)) {
        trickle_down_kind_(pq, pos, *item, false);
    } else {
        trickle_down_kind_(pq, pos, *item, true);
    }
}

// The highest item's position: the root alone, else the higher of its children (the first on a
// tie).
static uint32_t heap_max_pos(const pqueue_t *pq)
{
    if (pq->size <= 2u) {
        return pq->size - 1u;
    }
    return pq->heap[2].priority > pq->heap[1].priority ? 2u : 1u;
}

// Raises the item at `pos` to `priority`. On a max level nothing below it can be higher, so it
// can only go up; on a min level it may now be above what is below it, and above its parent:
// then the parent, which was above everything below `pos`, takes the hole and goes down, and
// the raised item takes the parent's place on the max levels.
static void heap_raise(pqueue_t *pq, uint32_t pos, float priority)
{
    pq_item_t item = pq->heap[pos];
    item.priority = priority;
    if (!on_min_level_(pos)) {
        heap_place(pq, bubble_up_kind_(pq, pos, &item, true), &item);
        return;
    }
    if (pos > 0u) {  // the root has no parent
        const uint32_t parent = (pos - 1u) / 2u;
        if (priority > pq->heap[parent].priority) {
            const pq_item_t down = pq->heap[parent];
            heap_trickle_down(pq, pos, &down);
            heap_place(pq, bubble_up_kind_(pq, parent, &item, true), &item);
            return;
        }
    }
    heap_trickle_down(pq, pos, &item);
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
    FW_ASSERT(pq != NULL);
    // Only the index keys say what is queued; heap items and index positions beyond `size` are
    // never read, so they are left as they are.
    oa_clear(&pq->index);
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
    FW_ASSERT(pq != NULL && pq->heap != NULL);
    // A NaN compares false with everything and would silently break the heap order.
    if (key == PQ_NO_KEY || priority != priority) {
        return false;
    }
    uint32_t slot = oa_find(&pq->index, key);
    if (slot == OA_NONE) {
        return false;  // cannot happen: at most half the index's slots hold a key
    }
    if (pq->index.keys[slot] == key) {
        const uint32_t pos = pq->index_pos[slot];
        if (priority > pq->heap[pos].priority) {
            heap_raise(pq, pos, priority);
            ++pq->stats.raised;
        } else {
            ++pq->stats.kept;
        }
        return true;
    }

    if (pq->size < pq->capacity) {
        oa_put(&pq->index, slot, key);
        const pq_item_t item = {key, priority, slot};
        const uint32_t pos = pq->size++;
        if (pq->size > pq->stats.high_water) {
            pq->stats.high_water = pq->size;
        }
        heap_bubble_up(pq, pos, &item);
    } else {
        // Full: something is dropped either way, and the lowest is the root. On a tie the queued
        // item stays, so a stream of equal priorities does not churn the queue.
        ++pq->stats.dropped;
        if (!(priority > pq->heap[0].priority)) {
            return false;
        }
        // The new item takes the root's place and goes down. The removal may shift the new
        // key's probe path, so look its slot up again.
        index_remove_(pq, pq->heap[0].slot);
        slot = oa_find(&pq->index, key);
        oa_put(&pq->index, slot, key);
        const pq_item_t item = {key, priority, slot};
        heap_trickle_down(pq, 0, &item);
    }
    ++pq->stats.pushed;
    return true;
}

bool pq_pop(pqueue_t *pq, uint32_t *key, float *priority)
{
    FW_ASSERT(pq != NULL);
    if (pq->size == 0u) {
        return false;
    }
    const uint32_t pos = heap_max_pos(pq);
    const pq_item_t top = pq->heap[pos];
    // Unlink from the index first: the shift may update slots of items still in the heap,
    // including the last one, which is about to move.
    index_remove_(pq, top.slot);
    --pq->size;
    if (pos < pq->size) {  // the last item fills the hole; it is not below the root
        const pq_item_t last = pq->heap[pq->size];
        heap_trickle_down(pq, pos, &last);
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
    FW_ASSERT(pq != NULL);
    const uint32_t slot = key == PQ_NO_KEY ? OA_NONE : index_of_(pq, key);
    if (slot == OA_NONE) {
        return -1.0f;
    }
    return pq->heap[pq->index_pos[slot]].priority;
}

bool pq_check(const pqueue_t *pq)
{
    FW_ASSERT(pq != NULL);
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
        // Against its parent and grandparent, which covers every item against its children and
        // grandchildren: on a min level nothing below is lower, on a max level nothing higher.
        if (i > 0u) {
            const float parent = pq->heap[(i - 1u) / 2u].priority;
            if (on_min_level_(i) ? !(it->priority <= parent) : !(it->priority >= parent)) {
                return false;
            }
        }
        if (i > 2u) {
            const float grand = pq->heap[((i - 1u) / 2u - 1u) / 2u].priority;
            if (on_min_level_(i) ? !(it->priority >= grand) : !(it->priority <= grand)) {
                return false;
            }
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
