// SPDX-License-Identifier: MIT
// dynaqpc: the open-addressing key index that the agent's hashed tables share.
#ifndef AGENT_OA_TABLE_H
#define AGENT_OA_TABLE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "fw/fw_base.h"
#include "fw/fw_util.h"
#include "fw_config.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The keys of an open-addressing hash table with linear probing, in caller-owned static storage:
/// a power-of-two array of slots, OA_EMPTY marking an empty one. Each key is held at most once,
/// fewer than `limit` slots past its home slot, with no empty slot between its home and it (so a
/// search may stop at the first empty slot). Any value but OA_EMPTY is a key; a bounded window
/// (below) needs keys of at most 31 bits, which oa_scan_window()'s test for empty slots relies on.
///
/// Only the keys live here. A table that uses the index (the Q store's rows, the CMAC's cells, the
/// priority queue's positions, the Dyna-Q table's record numbers) keeps its payload in arrays of
/// its own, indexed by slot, and its own counters: the index tells it which slot, and when a
/// deletion moves a key it says from where to where. Fixed capacity, no allocation, no
/// randomness: the same calls give the same slots on every build.
///
/// Two ways to stay within the bound, chosen by the table:
/// - **bounded windows** (`limit` = FW_CFG_MAX_PROBE, the Q store and the CMAC): the table may fill
///   up; a key whose window holds no empty slot takes a slot of the window that oa_least() picks,
///   reused in place (its old key gives way), so no probe path ever breaks. Never deleted from.
/// - **half-empty** (`limit` = every slot, the queue's and Dyna-Q's indices): the table holds at
///   most half as many keys as slots, so a search always ends at the key or an empty slot soon;
///   keys are deleted by backward shift (oa_remove), which leaves no tombstones.
typedef struct oa_table {
    uint32_t *keys;        ///< slots entries, OA_EMPTY when empty
    uint32_t mul;          ///< home(key) = (key * mul) >> shift (see oa_init())
    uint32_t shift;
    uint32_t scan_below;   ///< homes below this have a whole window of FW_CFG_MAX_PROBE slots
                           ///< before the array's end (0 unless limit == FW_CFG_MAX_PROBE)
    uint32_t mask;         ///< slots - 1
    uint32_t limit;        ///< most slots a search visits: 1..slots
} oa_table_t;

/// Marks an empty slot; no key may take this value.
#define OA_EMPTY UINT32_MAX
/// "No slot": what a search that reached its limit returns.
#define OA_NONE UINT32_MAX
/// A score oa_least() never picks.
#define OA_SKIP UINT32_MAX

/// Where a key's home slot comes from: the top bits of its Fibonacci hash (spreads keys that
/// differ in any bit: consecutive robot states, packed pairs), or its low bits (the Dyna-Q
/// table's index, which has always been laid out so: its saved records stay valid).
typedef enum oa_home {
    OA_HOME_HIGH = 0,
    OA_HOME_LOW = 1,
} oa_home_t;

/// The probe window of a table of `slots` (a power of two): FW_CFG_MAX_PROBE, or every slot of a
/// smaller table. What the agent's tables pass oa_init() as `limit`.
static inline uint32_t oa_probe_limit(uint32_t slots)
{
    return FW_CFG_MAX_PROBE < slots ? FW_CFG_MAX_PROBE : slots;
}

/// Sets up the index over `keys` (`slots` entries, a power of two; `limit` in 1..slots). Does
/// not touch the keys: call oa_clear() for an empty table. Returns FW_OK or FW_ERR_INVAL.
int oa_init(oa_table_t *t, uint32_t *keys, uint32_t slots, uint32_t limit, oa_home_t home);

/// Empties every slot.
void oa_clear(oa_table_t *t);

/// Number of slots.
static inline uint32_t oa_slots(const oa_table_t *t)
{
    return t->mask + 1u;
}

// Forced inlining: the MCU build is optimised for size (-Os), under which GCC keeps a static
// function that has more than one caller as a call; these run about twenty times per planning
// update, and oa_remove()'s callback folds into its caller only when inlined.
#if defined(__GNUC__)
#define OA_INLINE static inline __attribute__((always_inline))
#else
#define OA_INLINE static inline
#endif

/// The slot a search for `key` starts at: the top or the low log2(slots) bits of fw_fib_mix(key),
/// as oa_init() was told. One multiply and one shift either way (see oa_init()).
OA_INLINE uint32_t oa_home(const oa_table_t *t, uint32_t key)
{
    return (key * t->mul) >> t->shift;
}

/// The slot holding `key`, or else the first empty slot on its probe path (where it would go),
/// or OA_NONE when neither lies within `limit` slots of its home.
OA_INLINE uint32_t oa_find(const oa_table_t *t, uint32_t key)
{
    const uint32_t *const keys = t->keys;
    const uint32_t mask = t->mask;
    uint32_t slot = oa_home(t, key);
    for (uint32_t probe = 0; probe < t->limit; probe++) {
        const uint32_t k = keys[slot];
        if (k == key || k == OA_EMPTY) {
            return slot;
        }
        slot = (slot + 1u) & mask;
    }
    return OA_NONE;
}

FW_STATIC_ASSERT(FW_CFG_MAX_PROBE % 2 == 0, probe_windows_are_scanned_two_slots_at_a_time);

/// Where `key` sits among the FW_CFG_MAX_PROBE slots from `slot` on, or NULL (the window must
/// not run past the array's end). Two slots at a time: of two slots either is empty exactly when
/// the top bit of both keys or-ed together is set. Testing for the key before testing for empty
/// slots finds nothing more than a one-at-a-time search that stops at the first empty slot, as
/// no key lies past one. For the same reason the test for empty slots only saves time, and in a
/// `full` table, which has none, it is left out.
OA_INLINE const uint32_t *oa_scan_window(const uint32_t *slot, uint32_t key, bool full)
{
    const uint32_t *const end = slot + FW_CFG_MAX_PROBE;
    do {
        const uint32_t k0 = slot[0];
        const uint32_t k1 = slot[1];
        if (k0 == key) {
            return slot;
        }
        if (k1 == key) {
            return slot + 1;
        }
        if (!full && ((k0 | k1) >> 31)) {
            return NULL;
        }
        slot += 2;
    } while (slot != end);
    return NULL;
}

/// The slot holding `key`, or OA_NONE: oa_find() for reading. `full` says that no slot is empty
/// (the caller counts its keys), which lets a bounded window skip the test for empty slots. A
/// window that does not wrap around the array's end (nearly always) is scanned by pointer.
OA_INLINE uint32_t oa_lookup(const oa_table_t *t, uint32_t key, bool full)
{
    const uint32_t home = oa_home(t, key);
    if (home < t->scan_below) {
        const uint32_t *const hit = oa_scan_window(t->keys + home, key, full);
        return hit != NULL ? (uint32_t)(hit - t->keys) : OA_NONE;
    }
    const uint32_t slot = oa_find(t, key);
    return slot != OA_NONE && t->keys[slot] == key ? slot : OA_NONE;
}

/// Stores `key` in `slot`: an empty slot oa_find() gave for it, or the slot of its window that
/// oa_least() picked (whose old key gives way: the slot is reused in place, so every other key's
/// probe path stays as it was).
OA_INLINE void oa_put(oa_table_t *t, uint32_t slot, uint32_t key)
{
    t->keys[slot] = key;
}

/// Stores `key`, which the index does not hold, in the first empty slot of its probe path.
/// Returns that slot, or OA_NONE (nothing stored) when there is none within `limit`.
OA_INLINE uint32_t oa_insert(oa_table_t *t, uint32_t key)
{
    const uint32_t slot = oa_find(t, key);
    if (slot != OA_NONE) {
        t->keys[slot] = key;
    }
    return slot;
}

/// How a table scores the slots of a full window for oa_least(): lower goes first; OA_SKIP is
/// never picked. Called once per slot of the window, in probe order, so a table may also age
/// what it scores.
typedef uint32_t (*oa_score_fn)(void *ctx, uint32_t slot);

/// The window scan for eviction: of the `limit` slots from key's home on, the one `score` rates
/// lowest, the first of equals; OA_NONE if every slot scores OA_SKIP. Changes no key: the caller
/// clears the slot's payload and oa_put()s the new key there.
uint32_t oa_least(const oa_table_t *t, uint32_t key, oa_score_fn score, void *ctx);

/// What oa_remove() tells the table when it moves a key from one slot to another, so that the
/// payload follows.
typedef void (*oa_moved_fn)(void *ctx, uint32_t from, uint32_t to);

/// Backward-shift deletion (Knuth's Algorithm R) of the key in `slot`: the slot is emptied, and
/// each later key of the same run that a search from its home would then no longer reach moves
/// back into the hole (reported through `moved`, from its old slot to its new one, in order),
/// leaving a new hole where it was. No tombstones: probe paths are those of a table that never
/// held the key. For half-empty indices (a run always ends at an empty slot).
OA_INLINE void oa_remove(oa_table_t *t, uint32_t slot, oa_moved_fn moved, void *ctx)
{
    uint32_t *const keys = t->keys;
    const uint32_t mask = t->mask;
    uint32_t hole = slot;
    uint32_t j = slot;
    for (uint32_t n = 0; n < mask; n++) {
        j = (j + 1u) & mask;
        const uint32_t k = keys[j];
        if (k == OA_EMPTY) {
            break;
        }
        // k stays when its home lies cyclically in (hole, j], that is, nearer to j than the
        // hole is; distances are taken modulo the table size so a run that wraps past slot 0
        // compares like any other.
        if (((j - oa_home(t, k)) & mask) >= ((j - hole) & mask)) {
            keys[hole] = k;
            moved(ctx, j, hole);
            hole = j;
        }
    }
    keys[hole] = OA_EMPTY;
}

/// The restore-time check of one slot of saved keys (`keys`, laid out as `t`'s: same slot count,
/// limit and home), which must hold a key: whether a search from its home finds it there, fewer
/// than `limit` slots on, with neither an empty slot (a search stops there) nor another copy of
/// the key (a search would find that one) before it. Reads only.
bool oa_path_ok(const oa_table_t *t, const uint32_t *keys, uint32_t slot);

/// Slots of `keys` (laid out as `t`'s; t->keys itself after a restore) that hold a key.
uint32_t oa_count(const oa_table_t *t, const uint32_t *keys);

#ifdef __cplusplus
}
#endif

#endif // AGENT_OA_TABLE_H
