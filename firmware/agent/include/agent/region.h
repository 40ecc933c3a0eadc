// SPDX-License-Identifier: MIT
// dynaqpc: a piece of memory that holds part of what the agent learned (what flash saves).
#ifndef AGENT_REGION_H
#define AGENT_REGION_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/// A piece of memory that holds part of what the agent learned. Each table lists its own
/// (qstore_regions(), cmac_regions(), dynaq_regions()); agent_learned_regions() strings them
/// together in a fixed order.
typedef struct agent_region {
    void *data;
    uint32_t size;  ///< bytes
} agent_region_t;

/// Appends (data, size) to out[n] unless it is empty (NULL or 0 bytes); returns the new count.
static inline uint32_t agent_region_add(agent_region_t *out, uint32_t n, const void *data,
                                        uint32_t size)
{
    if (data != NULL && size > 0u) {
        out[n].data = (void *)(uintptr_t)data;  // the table's own storage, writable by a restore
        out[n].size = size;
        n++;
    }
    return n;
}

#ifdef __cplusplus
}
#endif

#endif // AGENT_REGION_H
