// SPDX-License-Identifier: MIT
// dynaqpc robot application: what the robot learned, kept in flash across reboots.
//
// The flash region (hal_flash.h) is split into two slots. A save writes a complete record: first
// the payload (the agent's learned tables), then, last, a header carrying a sequence number and
// CRCs. It writes into the slot that does NOT hold the newest good record of the saving agent's
// layout (the agent kind, table sizes and state space): a record of another layout on the same
// flash (another agent was run) is what gets overwritten, never the saving agent's last good
// copy. A power cut at any moment, inside an erase too, leaves either the old record intact (the
// new one's header is not complete) or the new one complete, so a reboot always finds the last
// good copy.
//
// Loading takes the newest record of the agent's layout whose CRCs hold and whose contents pass
// the agent's own checks (agent_learned_check: counts, indices, probe windows, free slots), checked
// where it lies in flash before anything is copied. A record that fails is refused and counted,
// and the older slot is tried; a load that had to pass over a damaged record says so (fell_back).
//
// An accidental wipe can be undone: of two good records of the layout a save overwrites the one
// with fewer episodes (of equals, the older). Learning only adds episodes, so after a
// RESET_LEARNING the saves of the new learning (the firmware counts its episodes from 0 again)
// overwrite each other and the record from before the wipe stays, until the new learning has as
// many episodes or learned_store_restore_previous() brings it back.
#ifndef ROBOT_LEARNED_STORE_H
#define ROBOT_LEARNED_STORE_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/agent.h"
#include "hal/hal_flash.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LEARNED_STORE_MAGIC 0x43505144u  // "DQPC" little-endian
/// 2: Dyna-Q's action masks are byte arrays (FW_CFG_MAX_ACTIONS may exceed 8): a version-1
/// record's bytes mean something else, so it is refused.
#define LEARNED_STORE_VERSION 2u

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

/// What a slot holds, for one agent's layout.
typedef enum learned_slot_state {
    LEARNED_SLOT_EMPTY = 0,    ///< erased
    LEARNED_SLOT_DAMAGED = 1,  ///< not a whole record: an interrupted save, or corruption
    LEARNED_SLOT_FOREIGN = 2,  ///< a whole record of another layout (another agent, build, space)
    LEARNED_SLOT_REFUSED = 3,  ///< a whole record of this layout whose contents fail their checks
    LEARNED_SLOT_GOOD = 4,     ///< a whole record of this layout that can be restored
} learned_slot_state_t;

typedef struct learned_store {
    hal_flash_geometry_t geo;
    uint32_t slot_size;          ///< bytes per slot (a whole number of sectors)
    uint32_t sectors_per_slot;
    int32_t newest;              ///< slot of the newest whole record of any layout, -1 if none
    uint32_t newest_sequence;
    uint32_t saves, save_errors, loads;
    uint32_t corrupt_records;    ///< records a load found damaged (a CRC failed)
    uint32_t refused_records;    ///< records a load refused: CRCs hold, contents fail the checks
    uint32_t fallbacks;          ///< loads that restored a record with a damaged one beside it
    uint32_t foreign_overwritten;///< saves that overwrote another layout's record
    bool fell_back;              ///< the last load passed over a damaged or refused record
    uint8_t foreign_records;     ///< whole records of another layout the loads passed over (saturating)
    int32_t restored_slot;       ///< the slot the last successful load restored, -1 if none
} learned_store_t;

/// Reads the flash geometry and finds the newest good record.
/// Returns FW_OK, FW_ERR_NOSYS (no flash region), or FW_ERR_INVAL (fewer than two sectors).
int learned_store_init(learned_store_t *st);

/// Bytes a save of this agent writes (header plus payload), for checking it fits a slot.
uint32_t learned_store_record_size(const agent_t *ag);

/// What `slot` holds for this agent's layout; `sequence` (may be NULL) receives a whole record's
/// sequence number. Reads only; counts nothing.
learned_slot_state_t learned_store_slot_state(const learned_store_t *st, const agent_t *ag,
                                              uint32_t slot, uint32_t *sequence);

/// Saves what the agent learned, into the slot that does not hold its good record (of two good
/// records, over the one with fewer episodes, of equals the older; with none, into an empty or
/// damaged slot first, else the older). Blocks for the erase and
/// programming (see hal_flash_erase). Returns FW_OK, FW_ERR_NOMEM (the record does not fit a
/// slot), or FW_ERR_IO (the flash failed; the agent's previous good record is untouched).
int learned_store_save(learned_store_t *st, const agent_t *ag, uint32_t episodes);

/// Restores the newest good record into an agent initialised with the configuration it was saved
/// from. Each candidate is checked in flash (CRCs, layout, agent_learned_check) before anything
/// is copied, and the copy cannot fail: the agent is changed only by a record that passed.
/// Returns FW_OK (fell_back tells whether a damaged or refused record was passed over),
/// FW_ERR_NOENT (the region is erased), or FW_ERR_CORRUPT (records exist but none is whole, of
/// this layout and valid; the agent is untouched). `episodes` may be NULL.
int learned_store_load(learned_store_t *st, agent_t *ag, uint32_t *episodes);

/// Restores the previous record: the good record of this layout in the slot that does not hold
/// the newest one (undoes a RESET_LEARNING and the saves after it; see above). Checked in flash
/// as learned_store_load() does. Returns FW_OK (sequence and episodes, either may be NULL, receive
/// the record's), FW_ERR_NOENT (no previous record of this layout), or FW_ERR_CORRUPT (it is
/// damaged or refused; the agent is untouched).
int learned_store_restore_previous(learned_store_t *st, agent_t *ag, uint32_t *sequence, uint32_t *episodes);

/// The sequence number and episodes of the newest whole record in flash (any layout); false when
/// there is none.
bool learned_store_newest(const learned_store_t *st, uint32_t *sequence, uint32_t *episodes);

#ifdef __cplusplus
}
#endif

#endif // ROBOT_LEARNED_STORE_H
