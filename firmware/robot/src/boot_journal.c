// SPDX-License-Identifier: MIT
// dynaqpc robot application: the boot journal (see boot_journal.h).
#include "robot/boot_journal.h"

#include <string.h>

#include "fw/fw_base.h"
#include "fw/fw_crc.h"
#include "hal/hal_flash.h"

#define JOURNAL_KEY 0x4A4E5242u  // "BRNJ": an entry's CRC starts from it, not from a record's bytes

static uint32_t align_up_(uint32_t v, uint32_t a)
{
    return (v + a - 1u) / a * a;
}

static bool align_ok_(const learned_store_t *st)
{
    const uint32_t a = st->geo.write_align;
    return a != 0u && a <= BOOT_JOURNAL_ENTRY_BYTES && BOOT_JOURNAL_ENTRY_BYTES % a == 0u;
}

// Where a journal's entries may start in a slot: `used` bytes from its start, rounded up to an
// entry. False when not one entry fits after them.
static bool fit_(const learned_store_t *st, uint32_t slot, uint32_t used, uint32_t cap, uint32_t *start,
                 uint32_t *end)
{
    const uint32_t first = align_up_(used, BOOT_JOURNAL_ENTRY_BYTES);
    if (first >= st->slot_size || st->slot_size - first < BOOT_JOURNAL_ENTRY_BYTES) {
        return false;
    }
    const uint32_t room = st->slot_size - first;
    *start = slot * st->slot_size + first;
    *end = *start + (room < cap ? room : cap);
    return true;
}

// The journal's space in `slot`: after a whole record's header and payload, BOOT_JOURNAL_BYTES
// at most, inside the slot. False when the slot holds no record or no room.
static bool space_(const learned_store_t *st, uint32_t slot, uint32_t *start, uint32_t *end)
{
    if (!align_ok_(st) || slot > 1u) {
        return false;
    }
    const learned_header_t *h =
        (const learned_header_t *)hal_flash_map(slot * st->slot_size, sizeof(learned_header_t));
    if (h == NULL || h->magic != LEARNED_STORE_MAGIC || h->version != LEARNED_STORE_VERSION ||
        h->payload_size > st->slot_size) {
        return false;
    }
    const uint32_t a = st->geo.write_align;
    const uint32_t used = align_up_((uint32_t)sizeof(learned_header_t), a) + align_up_(h->payload_size, a);
    return fit_(st, slot, used, BOOT_JOURNAL_BYTES, start, end);
}

// The early journal's space (boot_journal.h): slot 1 after its header's place, while flash holds
// no whole record and that place is erased (the slot reads as empty). False otherwise.
static bool early_space_(const learned_store_t *st, uint32_t *start, uint32_t *end)
{
    if (!align_ok_(st) || st->newest >= 0) {
        return false;
    }
    const uint32_t header = align_up_((uint32_t)sizeof(learned_header_t), st->geo.write_align);
    const uint8_t *p = (const uint8_t *)hal_flash_map(st->slot_size, header);
    if (p == NULL) {
        return false;
    }
    for (uint32_t i = 0; i < header; i++) {
        if (p[i] != 0xFFu) {
            return false;  // a damaged record's header: not the store's empty slot
        }
    }
    return fit_(st, 1u, header, BOOT_JOURNAL_EARLY_BYTES, start, end);
}

static uint32_t entry_crc_(const uint32_t w[3])
{
    const uint32_t key = JOURNAL_KEY;
    return fw_crc32(fw_crc32(0u, &key, 4u), w, 12u);
}

static bool erased_(const uint32_t w[4])
{
    return (w[0] & w[1] & w[2] & w[3]) == 0xFFFFFFFFu;
}

// Scans one slot's journal: its newest entry, the largest boot count, where the next goes.
static bool scan_(boot_journal_t *j, uint32_t start, uint32_t end, boot_journal_entry_t *last, uint32_t *max_boot,
                  uint32_t *next)
{
    bool found = false;
    uint32_t off = start;
    for (; off + BOOT_JOURNAL_ENTRY_BYTES <= end; off += BOOT_JOURNAL_ENTRY_BYTES) {
        uint32_t w[4];
        if (hal_flash_read(off, w, sizeof w) != FW_OK || erased_(w)) {
            break;
        }
        if (w[3] != entry_crc_(w)) {
            j->damaged++;  // a write a power cut interrupted: the next entry goes after it
            continue;
        }
        *last = (boot_journal_entry_t){w[0], w[1], w[2] & 0xFFFFFFu, (w[2] >> 24) != 0u, false};
        *max_boot = w[0] > *max_boot ? w[0] : *max_boot;
        found = true;
    }
    *next = off;
    return found;
}

bool boot_journal_open(boot_journal_t *j, const learned_store_t *st, boot_journal_entry_t *last)
{
    FW_ASSERT(j != NULL && st != NULL && last != NULL);
    memset(j, 0, sizeof *j);
    memset(last, 0, sizeof *last);
    uint32_t max_boot = 0u;
    bool found = false;
    for (uint32_t slot = 0; slot < 2u; slot++) {
        uint32_t start, end, next;
        boot_journal_entry_t e;
        if (!space_(st, slot, &start, &end)) {
            continue;
        }
        const bool any = scan_(j, start, end, &e, &max_boot, &next);
        // The newest record's slot holds the newest entry; the other's only when it has none.
        if (any && ((int32_t)slot == st->newest || !found)) {
            *last = e;
            last->before_newest = st->newest >= 0 && (int32_t)slot != st->newest;
            found = true;
        }
        if ((int32_t)slot == st->newest) {
            j->ok = true;
            j->next = next;
            j->end = end;
        }
    }
    uint32_t start, end, next;
    if (early_space_(st, &start, &end)) {
        // No whole record: the early journal is the one to append to. Its newest entry is the
        // newest unless a record's journal (of a record no longer whole) has a later boot's: the
        // early journal's entries may be from before that record's save.
        boot_journal_entry_t e;
        if (scan_(j, start, end, &e, &max_boot, &next) && (!found || e.boot > last->boot)) {
            *last = e;
            found = true;
        }
        j->ok = true;
        j->early = true;
        j->next = next;
        j->end = end;
    }
    j->boot = max_boot + 1u;
    return found;
}

void boot_journal_follow(boot_journal_t *j, const learned_store_t *st)
{
    FW_ASSERT(j != NULL && st != NULL);
    uint32_t start, end, next, max_boot = 0u;
    boot_journal_entry_t e;
    j->ok = false;
    j->early = false;
    if (st->newest >= 0 && space_(st, (uint32_t)st->newest, &start, &end)) {
        (void)scan_(j, start, end, &e, &max_boot, &next);
        j->ok = true;
        j->next = next;
        j->end = end;
    }
}

int boot_journal_append(boot_journal_t *j, uint32_t episode, uint32_t steps, bool running)
{
    FW_ASSERT(j != NULL);
    if (!j->ok) {
        return FW_ERR_NOSYS;
    }
    // The last bytes are kept for boots, starts and ends: a long episode's steps do not crowd out
    // the entry that tells the next boot of the episode after it.
    const uint32_t keep = running && steps > 0u ? BOOT_JOURNAL_KEEP_BYTES(j->early) : 0u;
    if (j->next + BOOT_JOURNAL_ENTRY_BYTES + keep > j->end) {
        j->full++;
        return FW_ERR_NOMEM;
    }
    uint32_t w[4] = {j->boot, episode, (steps > 0xFFFFFFu ? 0xFFFFFFu : steps) | (running ? 1u << 24 : 0u), 0u};
    w[3] = entry_crc_(w);
    const int err = hal_flash_write(j->next, w, sizeof w);
    j->next += BOOT_JOURNAL_ENTRY_BYTES;  // a failed write leaves a damaged entry: skip it
    if (err == FW_OK) {
        j->appended++;
    }
    return err;
}
