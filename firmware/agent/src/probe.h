// SPDX-License-Identifier: MIT
// dynaqpc: private to the agent's sources: the probe-window scan of its open-addressing tables.
#ifndef AGENT_PROBE_H
#define AGENT_PROBE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "fw/fw_base.h"
#include "fw_config.h"
#include "inline.h"

// The CMAC's cells and the Q store's rows are open-addressing tables alike: keys of at most 31
// bits, UINT32_MAX marking an empty slot, linear probing within FW_CFG_MAX_PROBE slots of a key's
// home. A slot is emptied only to be filled again at once (the tables' evict_()), so a key is
// never stored past an empty slot of its probe path.
FW_STATIC_ASSERT(FW_CFG_MAX_PROBE % 2 == 0, probe_windows_are_scanned_two_slots_at_a_time);

// Where `key` sits among the FW_CFG_MAX_PROBE slots from `slot` on, or NULL. Two slots at a time:
// of two slots either is empty exactly when the top bit of both keys or-ed together is set.
// Testing for the key before testing for empty slots finds nothing more than a one-at-a-time
// search that stops at the first empty slot, as no key lies past one. For the same reason the
// test for empty slots only saves time, and in a full table, which has none, it is left out.
AGENT_ALWAYS_INLINE const uint32_t *probe_scan(const uint32_t *slot, uint32_t key, bool full)
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

#endif // AGENT_PROBE_H
