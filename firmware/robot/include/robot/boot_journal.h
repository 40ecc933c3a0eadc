// SPDX-License-Identifier: MIT
// dynaqpc robot application: what the robot was doing when it last lost power, kept in flash.
//
// A short append-only journal in the erased flash right after the newest learned record (its
// slot was erased whole before the record was written, robot/learned_store.h): one 16-byte entry
// at boot (the boot count), at each episode's start and real step (the episode and its steps, so
// far), and at its end. Each entry carries a CRC-32 from its own key; a power cut mid-write, or a
// corrupted entry, leaves an entry that the scan refuses and counts (damaged) and skips: the
// entries before it, the record and the other slot are untouched. A save writes the record into
// the other slot and erases this one's journal only when a later save comes back to it; the
// application appends the current state after every save, so the newest record's slot always
// holds the newest entry, and the boot count is the largest in either slot.
//
// Before any record (a fresh robot, or no whole record left in flash) the journal is the early
// journal: slot 1, from where a record's payload would start, BOOT_JOURNAL_EARLY_BYTES at most.
// Slot 1's header stays erased, so the store reads the slot as empty and nothing of it changes;
// the first save goes to slot 0 (the store's choice when neither slot holds a whole record) and
// the journal follows it there; the second save, into slot 1, erases the early journal. A slot 1
// whose header's place is not erased (a damaged record) holds no early journal: there is none.
// Entries are programmed into erased flash only: the journals erase nothing, so they add no wear
// beyond the saves' own erases.
//
// At boot the newest entry says whether an episode was running and how many steps it had: it is
// reported as interrupted (TLM_EPISODE Interrupted). One read from the other slot's journal (the
// newest record's lost its first entry) is older than the newest record: the application does
// not report a running episode that record counts (it ended and was saved). A journal holds BOOT_JOURNAL_BYTES / 16
// entries per slot (the early one BOOT_JOURNAL_EARLY_BYTES / 16); its last BOOT_JOURNAL_KEEP_BYTES
// (an eighth of that) take no step entries, only boots, starts and ends (an episode cut after that is reported with the steps of
// its last entry), and a full one takes none; every save makes a new one. Programming 16 bytes
// takes ~64 µs on the STM32F4, inside any control period.
// Context: thread. Fixed memory.
#ifndef ROBOT_BOOT_JOURNAL_H
#define ROBOT_BOOT_JOURNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "robot/learned_store.h"

#ifdef __cplusplus
extern "C" {
#endif

#define BOOT_JOURNAL_BYTES 4096u
#define BOOT_JOURNAL_ENTRY_BYTES 16u
#define BOOT_JOURNAL_EARLY_BYTES 32768u  ///< the early journal (no record yet): 2,048 entries
/// The last bytes of a journal (an eighth of its size) take boots, starts and ends, no steps.
#define BOOT_JOURNAL_KEEP_BYTES(early) ((early) ? BOOT_JOURNAL_EARLY_BYTES / 8u : BOOT_JOURNAL_BYTES / 8u)

typedef struct boot_journal_entry {
    uint32_t boot;      ///< the boot count when written
    uint32_t episode;   ///< the episode running, or the last one
    uint32_t steps;     ///< its real steps so far (24 bits)
    bool running;       ///< an episode was running
    /// Read from the other slot's journal: written before the newest record was saved, whose own
    /// journal holds no whole entry (its first was cut mid-write or damaged). What the record
    /// counts happened after it (boot_journal_open()).
    bool before_newest;
} boot_journal_entry_t;

typedef struct boot_journal {
    uint32_t next;      ///< flash offset of the next entry
    uint32_t end;       ///< end of the journal's space
    uint32_t boot;      ///< this boot's count: the largest in flash plus one
    uint16_t appended, full, damaged;  ///< entries written; refused for want of room; found damaged
    bool ok;            ///< there is a journal to append to
    bool early;         ///< it is the early journal (no record in flash)
} boot_journal_t;

/// Finds the journal after the newest record of `st` (without one, the early journal), reads the
/// newest entry into *last (false when there is none; last->before_newest when it is the other
/// slot's, older than the newest record) and sets j->boot to the largest boot count in flash plus
/// one (1 if none).
bool boot_journal_open(boot_journal_t *j, const learned_store_t *st, boot_journal_entry_t *last);

/// After a save: the journal goes on in the newest record's slot (its space is erased).
void boot_journal_follow(boot_journal_t *j, const learned_store_t *st);

/// Appends an entry for this boot. FW_OK, FW_ERR_NOSYS (no journal), FW_ERR_NOMEM (full; for a
/// step entry, running with steps > 0: in the journal's last BOOT_JOURNAL_KEEP_BYTES) or a hal_flash_write error.
int boot_journal_append(boot_journal_t *j, uint32_t episode, uint32_t steps, bool running);

#ifdef __cplusplus
}
#endif

#endif // ROBOT_BOOT_JOURNAL_H
