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

// Where a hashed table's saved key must lie: oa_path_ok() (oa_table.h).

#endif // AGENT_CHECK_H
