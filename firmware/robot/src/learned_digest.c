// SPDX-License-Identifier: MIT
// dynaqpc robot application: the digest of what was learned (learned_digest.h).
#include "robot/learned_digest.h"

#include "fw/fw_crc.h"

uint32_t learned_digest(const agent_t *ag)
{
    agent_region_t regions[AGENT_MAX_REGIONS];
    const uint32_t n = agent_learned_regions(ag, regions);
    uint32_t crc = 0;
    for (uint32_t i = 0; i < n; i++) {
        crc = fw_crc32(crc, regions[i].data, regions[i].size);
    }
    return crc;
}
