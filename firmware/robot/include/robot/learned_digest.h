// SPDX-License-Identifier: MIT
// dynaqpc robot application: one number for what an agent has learned.
#ifndef ROBOT_LEARNED_DIGEST_H
#define ROBOT_LEARNED_DIGEST_H

#include <stdint.h>

#include "agent/agent.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The CRC-32 (fw_crc32) of every region agent_learned_regions() lists, in its order: the bytes
/// learned_store saves. Equal digests mean equal learning, bit for bit (the QEMU agent and its
/// host build print it; the store's tests compare it across a save and a load). Pure: no I/O.
uint32_t learned_digest(const agent_t *ag);

#ifdef __cplusplus
}
#endif

#endif // ROBOT_LEARNED_DIGEST_H
