// SPDX-License-Identifier: MIT
// dynaqpc robot application: two-slot, CRC-checked records of what was learned.
#include "robot/learned_store.h"

#include <stdbool.h>
#include <stddef.h>
#include <string.h>

#include "fw/fw_base.h"
#include "fw/fw_crc.h"

// Staging buffer for programming: regions are written through it in write_align units. Large
// enough for any flash's programming unit we know (4 bytes on the STM32F4, 8 or 16 elsewhere).
#define STAGE_BYTES 64u
FW_STATIC_ASSERT(sizeof(learned_header_t) <= STAGE_BYTES, header_fits_stage);

static uint32_t layout_of_(const agent_t *ag, agent_region_t *regions, uint32_t *n_out,
                           uint32_t *payload)
{
    const uint32_t n = agent_learned_regions(ag, regions);
    uint32_t words[2 + AGENT_MAX_REGIONS];
    words[0] = (uint32_t)ag->kind;
    words[1] = n;
    uint32_t total = 0;
    for (uint32_t i = 0; i < n; i++) {
        words[2 + i] = regions[i].size;
        total += regions[i].size;
    }
    *n_out = n;
    *payload = total;
    // The space too: the same table sizes with another state encoding mean other knowledge.
    const uint32_t crc = fw_crc32(0, words, (2u + n) * (uint32_t)sizeof(uint32_t));
    return fw_crc32(crc, ag->space, (uint32_t)sizeof *ag->space);
}

static uint32_t header_crc_(const learned_header_t *h)
{
    return fw_crc32(0, h, (uint32_t)offsetof(learned_header_t, header_crc));
}

static uint32_t align_up_(uint32_t v, uint32_t a)
{
    return (v + a - 1u) / a * a;
}

static uint32_t header_span_(const learned_store_t *st)
{
    return align_up_((uint32_t)sizeof(learned_header_t), st->geo.write_align);
}

static bool header_valid_(const learned_header_t *h)
{
    return h->magic == LEARNED_STORE_MAGIC && h->version == LEARNED_STORE_VERSION &&
           h->header_crc == header_crc_(h);
}

static void load_slot_(learned_store_t *st, agent_t *ag, uint32_t best, uint32_t *episodes);

static bool newer_(uint32_t a, uint32_t b)
{
    return (int32_t)(a - b) > 0;
}

// A slot's header, if it is whole (magic, version, CRC) and its payload fits the slot.
static const learned_header_t *slot_header_(const learned_store_t *st, uint32_t slot)
{
    const learned_header_t *h =
        (const learned_header_t *)hal_flash_map(slot * st->slot_size, sizeof(learned_header_t));
    if (h == NULL || ((uintptr_t)h & 3u) != 0u || !header_valid_(h) ||
        h->payload_size > st->slot_size - header_span_(st)) {
        return NULL;
    }
    return h;
}

static bool slot_erased_(const learned_store_t *st, uint32_t slot)
{
    const uint8_t *p = (const uint8_t *)hal_flash_map(slot * st->slot_size, sizeof(learned_header_t));
    if (p == NULL) {
        return false;
    }
    for (uint32_t i = 0; i < sizeof(learned_header_t); i++) {
        if (p[i] != 0xFFu) {
            return false;
        }
    }
    return true;
}

// The newest whole record of any layout (its payload CRC holds), for the sequence numbers.
static void find_newest_(learned_store_t *st)
{
    st->newest = -1;
    st->newest_sequence = 0;
    for (uint32_t slot = 0; slot < 2u; slot++) {
        const learned_header_t *h = slot_header_(st, slot);
        const uint8_t *payload = h == NULL ? NULL
                                           : (const uint8_t *)hal_flash_map(
                                                 slot * st->slot_size + header_span_(st), h->payload_size);
        if (payload != NULL && fw_crc32(0, payload, h->payload_size) == h->payload_crc &&
            (st->newest < 0 || newer_(h->sequence, st->newest_sequence))) {
            st->newest = (int32_t)slot;
            st->newest_sequence = h->sequence;
        }
    }
}

int learned_store_init(learned_store_t *st)
{
    FW_ASSERT(st != NULL);
    *st = (learned_store_t){0};
    st->newest = -1;
    st->restored_slot = -1;
    int err = hal_flash_get_geometry(&st->geo);
    if (err) {
        return err;
    }
    if (st->geo.sector_count < 2u || st->geo.sector_size == 0u || st->geo.write_align == 0u ||
        st->geo.write_align > STAGE_BYTES || STAGE_BYTES % st->geo.write_align != 0u) {
        return FW_ERR_INVAL;
    }
    st->sectors_per_slot = st->geo.sector_count / 2u;
    st->slot_size = st->sectors_per_slot * st->geo.sector_size;
    find_newest_(st);
    return FW_OK;
}

learned_slot_state_t learned_store_slot_state(const learned_store_t *st, const agent_t *ag,
                                              uint32_t slot, uint32_t *sequence)
{
    agent_region_t regions[AGENT_MAX_REGIONS];
    uint32_t n, payload;
    const uint32_t layout = layout_of_(ag, regions, &n, &payload);
    const learned_header_t *h = slot_header_(st, slot);
    if (h == NULL) {
        return slot_erased_(st, slot) ? LEARNED_SLOT_EMPTY : LEARNED_SLOT_DAMAGED;
    }
    const uint32_t base = slot * st->slot_size + header_span_(st);
    const uint8_t *bytes = (const uint8_t *)hal_flash_map(base, h->payload_size);
    if (bytes == NULL || fw_crc32(0, bytes, h->payload_size) != h->payload_crc) {
        return LEARNED_SLOT_DAMAGED;
    }
    if (sequence != NULL) {
        *sequence = h->sequence;
    }
    if (h->layout != layout || h->payload_size != payload) {
        return LEARNED_SLOT_FOREIGN;
    }
    // The regions where they lie in flash, checked there by the agent's own tables. Every region
    // is a whole number of words long, so each starts aligned if the slot does.
    const void *image[AGENT_MAX_REGIONS] = {0};
    uint32_t offset = 0;
    for (uint32_t r = 0; r < n; r++) {
        if (((uintptr_t)(bytes + offset) & 3u) != 0u) {
            return LEARNED_SLOT_REFUSED;
        }
        image[r] = bytes + offset;
        offset += regions[r].size;
    }
    return agent_learned_check(ag, image) == FW_OK ? LEARNED_SLOT_GOOD : LEARNED_SLOT_REFUSED;
}

uint32_t learned_store_record_size(const agent_t *ag)
{
    FW_ASSERT(ag != NULL);
    agent_region_t regions[AGENT_MAX_REGIONS];
    uint32_t n, payload;
    (void)layout_of_(ag, regions, &n, &payload);
    return (uint32_t)sizeof(learned_header_t) + payload;
}

// Programs the regions' bytes back to back from `offset`, padding the tail with 0xFF to the
// programming unit.
static int write_payload_(const learned_store_t *st, uint32_t offset, const agent_region_t *regions,
                          uint32_t n)
{
    uint8_t stage[STAGE_BYTES];
    uint32_t fill = 0;
    for (uint32_t r = 0; r < n; r++) {
        const uint8_t *p = (const uint8_t *)regions[r].data;
        uint32_t left = regions[r].size;
        while (left > 0u) {
            const uint32_t take = left < STAGE_BYTES - fill ? left : STAGE_BYTES - fill;
            memcpy(stage + fill, p, take);
            fill += take;
            p += take;
            left -= take;
            if (fill == STAGE_BYTES) {
                const int err = hal_flash_write(offset, stage, STAGE_BYTES);
                if (err) {
                    return err;
                }
                offset += STAGE_BYTES;
                fill = 0;
            }
        }
    }
    if (fill > 0u) {
        const uint32_t padded = align_up_(fill, st->geo.write_align);
        memset(stage + fill, 0xFF, padded - fill);
        return hal_flash_write(offset, stage, padded);
    }
    return FW_OK;
}

// The slot a save writes: never over the agent's newest good copy. Without one: an empty or damaged
// slot before a refused record, before another layout's record, and of two alike the older.
// state[] gets both slots' states, *whole whether flash holds any whole record, *top the highest
// sequence number in flash.
static uint32_t slot_to_write_(const learned_store_t *st, const agent_t *ag, learned_slot_state_t state[2],
                               bool *whole, uint32_t *top)
{
    uint32_t seq[2] = {0, 0};
    *whole = false;
    *top = 0;
    for (uint32_t i = 0; i < 2u; i++) {
        state[i] = learned_store_slot_state(st, ag, i, &seq[i]);
        if (state[i] >= LEARNED_SLOT_FOREIGN) {
            *top = !*whole || newer_(seq[i], *top) ? seq[i] : *top;
            *whole = true;
        }
    }
    uint32_t slot;
    if (state[0] == LEARNED_SLOT_GOOD || state[1] == LEARNED_SLOT_GOOD) {
        const bool both = state[0] == LEARNED_SLOT_GOOD && state[1] == LEARNED_SLOT_GOOD;
        uint32_t keep = state[0] == LEARNED_SLOT_GOOD ? 0u : 1u;
        if (both) {
            // Of two good records keep the one with more episodes, of equals the newer: learning
            // only adds episodes, so the one with fewer started over (RESET_LEARNING) and the
            // record from before the wipe stays until learning passes it or it is restored.
            const uint32_t e0 = slot_header_(st, 0)->episodes;
            const uint32_t e1 = slot_header_(st, 1)->episodes;
            keep = e0 != e1 ? (e1 > e0 ? 1u : 0u) : (newer_(seq[1], seq[0]) ? 1u : 0u);
        }
        slot = 1u - keep;
    } else {
        static const uint8_t rank[] = {0u, 0u, 2u, 1u, 3u};  // by learned_slot_state_t
        if (rank[state[0]] != rank[state[1]]) {
            slot = rank[state[1]] < rank[state[0]] ? 1u : 0u;
        } else {
            slot = state[0] >= LEARNED_SLOT_FOREIGN && newer_(seq[0], seq[1]) ? 1u : 0u;
        }
    }
    return slot;
}

int learned_store_save(learned_store_t *st, const agent_t *ag, uint32_t episodes)
{
    FW_ASSERT(st != NULL && ag != NULL);
    agent_region_t regions[AGENT_MAX_REGIONS];
    uint32_t n, payload;
    learned_header_t h = {0};
    h.layout = layout_of_(ag, regions, &n, &payload);
    if (payload > st->slot_size - header_span_(st)) {
        st->save_errors++;
        return FW_ERR_NOMEM;
    }
    learned_slot_state_t state[2];
    bool whole = false;
    uint32_t top = 0;  // the highest sequence number in flash
    const uint32_t slot = slot_to_write_(st, ag, state, &whole, &top);
    if (state[slot] == LEARNED_SLOT_FOREIGN) {
        st->foreign_overwritten++;
    }
    const uint32_t base = slot * st->slot_size;
    int err = FW_OK;
    for (uint32_t s = 0; s < st->sectors_per_slot && !err; s++) {
        err = hal_flash_erase(slot * st->sectors_per_slot + s);
    }
    if (!err) {
        err = write_payload_(st, base + header_span_(st), regions, n);
    }
    if (err) {
        st->save_errors++;
        return FW_ERR_IO;
    }
    uint32_t crc = 0;
    for (uint32_t r = 0; r < n; r++) {
        crc = fw_crc32(crc, regions[r].data, regions[r].size);
    }
    h.magic = LEARNED_STORE_MAGIC;
    h.version = LEARNED_STORE_VERSION;
    h.sequence = whole ? top + 1u : 1u;
    h.payload_size = payload;
    h.payload_crc = crc;
    h.episodes = episodes;
    h.header_crc = header_crc_(&h);
    // The header last: until it is whole, the old record is the newest good one.
    uint8_t stage[STAGE_BYTES];
    memset(stage, 0xFF, sizeof stage);
    memcpy(stage, &h, sizeof h);
    err = hal_flash_write(base, stage, header_span_(st));
    if (err) {
        st->save_errors++;
        return FW_ERR_IO;
    }
    st->newest = (int32_t)slot;
    st->newest_sequence = h.sequence;
    st->saves++;
    return FW_OK;
}

int learned_store_load(learned_store_t *st, agent_t *ag, uint32_t *episodes)
{
    FW_ASSERT(st != NULL && ag != NULL);
    learned_slot_state_t state[2];
    uint32_t seq[2] = {0, 0};
    for (uint32_t i = 0; i < 2u; i++) {
        state[i] = learned_store_slot_state(st, ag, i, &seq[i]);
        st->corrupt_records += state[i] == LEARNED_SLOT_DAMAGED ? 1u : 0u;
        st->refused_records += state[i] == LEARNED_SLOT_REFUSED ? 1u : 0u;
        st->foreign_records += state[i] == LEARNED_SLOT_FOREIGN && st->foreign_records < 255u ? 1u : 0u;
    }
    st->fell_back = false;
    int32_t best = -1;
    for (uint32_t i = 0; i < 2u; i++) {
        if (state[i] == LEARNED_SLOT_GOOD && (best < 0 || newer_(seq[i], seq[best]))) {
            best = (int32_t)i;
        }
    }
    if (best < 0) {
        return state[0] == LEARNED_SLOT_EMPTY && state[1] == LEARNED_SLOT_EMPTY ? FW_ERR_NOENT
                                                                              : FW_ERR_CORRUPT;
    }
    const learned_slot_state_t other = state[1 - best];
    if (other == LEARNED_SLOT_DAMAGED || other == LEARNED_SLOT_REFUSED) {
        st->fell_back = true;  // perhaps the newer record; anyway something was lost
        st->fallbacks++;
    }
    load_slot_(st, ag, (uint32_t)best, episodes);
    return FW_OK;
}

int learned_store_restore_previous(learned_store_t *st, agent_t *ag, uint32_t *sequence, uint32_t *episodes)
{
    FW_ASSERT(st != NULL && ag != NULL);
    learned_slot_state_t state[2];
    uint32_t seq[2] = {0, 0};
    for (uint32_t i = 0; i < 2u; i++) {
        state[i] = learned_store_slot_state(st, ag, i, &seq[i]);
    }
    // The newest whole record of this layout (good or not) is the current one; the other slot
    // holds the previous.
    int32_t newest = -1;
    for (uint32_t i = 0; i < 2u; i++) {
        if ((state[i] == LEARNED_SLOT_GOOD || state[i] == LEARNED_SLOT_REFUSED) &&
            (newest < 0 || newer_(seq[i], seq[newest]))) {
            newest = (int32_t)i;
        }
    }
    if (newest < 0) {
        return FW_ERR_NOENT;
    }
    const uint32_t prev = 1u - (uint32_t)newest;
    if (state[prev] == LEARNED_SLOT_REFUSED || state[prev] == LEARNED_SLOT_DAMAGED) {
        return FW_ERR_CORRUPT;
    }
    if (state[prev] != LEARNED_SLOT_GOOD) {
        return FW_ERR_NOENT;
    }
    load_slot_(st, ag, prev, episodes);
    if (sequence != NULL) {
        *sequence = seq[prev];
    }
    return FW_OK;
}

bool learned_store_newest(const learned_store_t *st, uint32_t *sequence, uint32_t *episodes)
{
    FW_ASSERT(st != NULL);
    const learned_header_t *h = st->newest < 0 ? NULL : slot_header_(st, (uint32_t)st->newest);
    if (h == NULL) {
        return false;
    }
    *sequence = h->sequence;
    *episodes = h->episodes;
    return true;
}

// Copies a slot that learned_store_slot_state() found GOOD into the agent.
static void load_slot_(learned_store_t *st, agent_t *ag, uint32_t best, uint32_t *episodes)
{
    agent_region_t regions[AGENT_MAX_REGIONS];
    uint32_t n, payload;
    (void)layout_of_(ag, regions, &n, &payload);
    // Checked in place by the caller; the copy is from memory and cannot fail half way.
    const uint32_t base = best * st->slot_size;
    const learned_header_t *h = (const learned_header_t *)hal_flash_map(base, sizeof *h);
    const uint8_t *bytes = (const uint8_t *)hal_flash_map(base + header_span_(st), payload);
    uint32_t offset = 0;
    for (uint32_t r = 0; r < n; r++) {
        memcpy(regions[r].data, bytes + offset, regions[r].size);
        offset += regions[r].size;
    }
    agent_learned_restored(ag);
    st->loads++;
    st->restored_slot = (int32_t)best;
    if (episodes != NULL) {
        *episodes = h->episodes;
    }
}
