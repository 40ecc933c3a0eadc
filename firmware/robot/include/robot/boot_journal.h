// SPDX-License-Identifier: MIT
// dynaqpc robot application: what the robot was doing when it last lost power, kept in flash.
//
// A short append-only journal in the erased flash right after the newest learned record (its
// slot was erased whole before the record was written, robot/learned_store.h): one 16-byte entry
// at boot (the boot count), at each episode's start and real step (the episode and its steps, so
// far), and at its end. Each entry carries a CRC-32; a power cut mid-write leaves a damaged entry
// that the scan skips. A save writes the record into the other slot and erases this one's journal
// only when a later save comes back to it; the application appends the current state after every
// save, so the newest record's slot always holds the newest entry, and the boot count is the
// largest in either slot.
//
// At boot the newest entry says whether an episode was running and how many steps it had: it is
// reported as interrupted (TLM_EPISODE Interrupted). Without a learned record in flash (a fresh
// robot, persistence off) there is no journal: the boot count stays 0 until the first save.
// A journal holds BOOT_JOURNAL_BYTES / 16 entries per slot; a full one takes no more step entries
// (an episode cut after that is reported with the steps of its last entry), and every save makes
// a new one. Programming 16 bytes takes ~64 µs on the STM32F4, inside any control period.
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

typedef struct boot_journal_entry {
    uint32_t boot;      ///< the boot count when written
    uint32_t episode;   ///< the episode running, or the last one
    uint32_t steps;     ///< its real steps so far (24 bits)
    bool running;       ///< an episode was running
} boot_journal_entry_t;

typedef struct boot_journal {
    uint32_t next;      ///< flash offset of the next entry
    uint32_t end;       ///< end of the journal's space
    uint32_t boot;      ///< this boot's count: the largest in flash plus one
    uint16_t appended, full, damaged;  ///< entries written; refused for want of room; found damaged
    bool ok;            ///< there is a journal to append to
} boot_journal_t;

/// Finds the journal after the newest record of `st`, reads the newest entry into *last (false
/// when there is none) and sets j->boot to the largest boot count in flash plus one (1 if none).
bool boot_journal_open(boot_journal_t *j, const learned_store_t *st, boot_journal_entry_t *last);

/// After a save: the journal goes on in the newest record's slot (its space is erased).
void boot_journal_follow(boot_journal_t *j, const learned_store_t *st);

/// Appends an entry for this boot. FW_OK, FW_ERR_NOSYS (no journal), FW_ERR_NOMEM (full) or a
/// hal_flash_write error.
int boot_journal_append(boot_journal_t *j, uint32_t episode, uint32_t steps, bool running);

#ifdef __cplusplus
}
#endif

#endif // ROBOT_BOOT_JOURNAL_H
