// SPDX-License-Identifier: MIT
// dynaqpc robot application: what the robot learned, kept in flash across reboots.
//
// The flash region (hal_flash.h) is split into two slots. A save writes a complete record into
// the slot that does NOT hold the newest good copy: first the payload (the agent's learned
// tables), then, last, a header carrying a sequence number and CRCs. A power cut at any moment
// leaves either the old record intact (the header of the new one was not complete) or the new one
// complete, so a reboot always finds the last good copy. Loading picks the valid record with the
// highest sequence number; a record from a firmware whose agent layout differs is refused.
#ifndef ROBOT_LEARNED_STORE_H
#define ROBOT_LEARNED_STORE_H

#include <stdint.h>

#include "agent/agent.h"
#include "hal/hal_flash.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LEARNED_STORE_MAGIC 0x43505144u  // "DQPC" little-endian
#define LEARNED_STORE_VERSION 1u

/// A record's header, at the start of its slot.
typedef struct learned_header {
    uint32_t magic;
    uint32_t version;
    uint32_t sequence;      ///< grows by one per save; the higher (mod 2^32) is newer
    uint32_t layout;        ///< CRC of the agent's kind and region sizes: same firmware layout
    uint32_t payload_size;  ///< bytes after the header
    uint32_t payload_crc;   ///< CRC-32 of the payload
    uint32_t episodes;      ///< episodes learned when saved
    uint32_t header_crc;    ///< CRC-32 of the fields above
} learned_header_t;

typedef struct learned_store {
    hal_flash_geometry_t geo;
    uint32_t slot_size;          ///< bytes per slot (a whole number of sectors)
    uint32_t sectors_per_slot;
    int32_t newest;              ///< slot of the newest good record, -1 if none
    uint32_t newest_sequence;
    uint32_t saves, save_errors, loads, corrupt_records;
} learned_store_t;

/// Reads the flash geometry and finds the newest good record.
/// Returns FW_OK, FW_ERR_NOSYS (no flash region), or FW_ERR_INVAL (fewer than two sectors).
int learned_store_init(learned_store_t *st);

/// Bytes a save of this agent writes (header plus payload), for checking it fits a slot.
uint32_t learned_store_record_size(const agent_t *ag);

/// Saves what the agent learned. Blocks for the erase and programming (see hal_flash_erase).
/// Returns FW_OK, FW_ERR_NOMEM (the record does not fit a slot), or FW_ERR_IO (the flash failed;
/// the previous record is untouched).
int learned_store_save(learned_store_t *st, const agent_t *ag, uint32_t episodes);

/// Restores the newest good record into an agent initialised with the configuration it was saved
/// from. The agent is changed only when the record is complete and valid.
/// Returns FW_OK, FW_ERR_NOENT (no record), or FW_ERR_CORRUPT (records exist but none is whole
/// and from this layout; the agent is untouched). `episodes` may be NULL.
int learned_store_load(learned_store_t *st, agent_t *ag, uint32_t *episodes);

#ifdef __cplusplus
}
#endif

#endif // ROBOT_LEARNED_STORE_H
