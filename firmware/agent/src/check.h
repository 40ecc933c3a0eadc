// SPDX-License-Identifier: MIT
// dynaqpc: private to the agent's sources: what the tables' restore checks share.
//
// A table restored from flash passed its CRCs, which prove only that the bytes are the ones a
// save wrote: a save from another build, a bug, or a record crafted to pass the CRCs can still
// hold counts, indices or keys that would make the table read or write out of bounds, or spin
// for ever. Each table module checks its own invariants on the restored bytes (the *_check()
// functions) before the agent is touched; these are the pieces they share.
#ifndef AGENT_CHECK_H
#define AGENT_CHECK_H

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

// A float that is neither infinite nor NaN (by its bits: the build may assume finite maths).
static inline bool check_finite(float x)
{
    uint32_t bits;
    memcpy(&bits, &x, sizeof bits);
    return ((bits >> 23) & 0xFFu) != 0xFFu;
}

// Whether the key in keys[slot] of an open-addressing table with linear probing (slots
// mask + 1, UINT32_MAX empty) is where a search from its home slot finds it: fewer than `limit`
// slots on, with neither an empty slot (a search stops there) nor another copy of the key (a
// search would find that one) before it.
static inline bool check_probe_path(const uint32_t *keys, uint32_t mask, uint32_t home,
                                    uint32_t slot, uint32_t limit)
{
    const uint32_t key = keys[slot];
    if (((slot - home) & mask) >= limit) {
        return false;
    }
    for (uint32_t j = home; j != slot; j = (j + 1u) & mask) {
        if (keys[j] == UINT32_MAX || keys[j] == key) {
            return false;
        }
    }
    return true;
}

#endif // AGENT_CHECK_H
