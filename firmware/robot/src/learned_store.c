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

// CRC of `len` bytes of flash from `offset`, read in chunks.
static int flash_crc_(uint32_t offset, uint32_t len, uint32_t *crc)
{
    uint8_t buf[STAGE_BYTES];
    uint32_t c = 0;
    while (len > 0u) {
        const uint32_t n = len < STAGE_BYTES ? len : STAGE_BYTES;
        const int err = hal_flash_read(offset, buf, n);
        if (err) {
            return err;
        }
        c = fw_crc32(c, buf, n);
        offset += n;
        len -= n;
    }
    *crc = c;
    return FW_OK;
}

// Reads a slot's header; true if the header and its payload are whole.
static bool slot_record_(learned_store_t *st, uint32_t slot, learned_header_t *h)
{
    const uint32_t base = slot * st->slot_size;
    if (hal_flash_read(base, h, sizeof *h) != FW_OK || !header_valid_(h)) {
        return false;
    }
    uint32_t crc;
    if (h->payload_size > st->slot_size - header_span_(st) ||
        flash_crc_(base + header_span_(st), h->payload_size, &crc) != FW_OK ||
        crc != h->payload_crc) {
        st->corrupt_records++;
        return false;
    }
    return true;
}

static bool newer_(uint32_t a, uint32_t b)
{
    return (int32_t)(a - b) > 0;
}

int learned_store_init(learned_store_t *st)
{
    *st = (learned_store_t){0};
    st->newest = -1;
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
    for (uint32_t slot = 0; slot < 2u; slot++) {
        learned_header_t h;
        if (slot_record_(st, slot, &h) && (st->newest < 0 || newer_(h.sequence, st->newest_sequence))) {
            st->newest = (int32_t)slot;
            st->newest_sequence = h.sequence;
        }
    }
    return FW_OK;
}

uint32_t learned_store_record_size(const agent_t *ag)
{
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

int learned_store_save(learned_store_t *st, const agent_t *ag, uint32_t episodes)
{
    agent_region_t regions[AGENT_MAX_REGIONS];
    uint32_t n, payload;
    learned_header_t h = {0};
    h.layout = layout_of_(ag, regions, &n, &payload);
    if (payload > st->slot_size - header_span_(st)) {
        st->save_errors++;
        return FW_ERR_NOMEM;
    }
    // Into the slot that does not hold the newest good copy.
    const uint32_t slot = st->newest == 0 ? 1u : 0u;
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
    h.sequence = st->newest < 0 ? 1u : st->newest_sequence + 1u;
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
    agent_region_t regions[AGENT_MAX_REGIONS];
    uint32_t n, payload;
    const uint32_t layout = layout_of_(ag, regions, &n, &payload);
    bool any = false;
    int32_t best = -1;
    learned_header_t best_h = {0};
    for (uint32_t slot = 0; slot < 2u; slot++) {
        learned_header_t h;
        if (hal_flash_read(slot * st->slot_size, &h, sizeof h) == FW_OK && h.magic != 0xFFFFFFFFu) {
            any = true;
        }
        if (slot_record_(st, slot, &h) && h.layout == layout && h.payload_size == payload &&
            (best < 0 || newer_(h.sequence, best_h.sequence))) {
            best = (int32_t)slot;
            best_h = h;
        }
    }
    if (best < 0) {
        return any ? FW_ERR_CORRUPT : FW_ERR_NOENT;
    }
    // Verified whole above; now copy it in.
    uint32_t offset = (uint32_t)best * st->slot_size + header_span_(st);
    for (uint32_t r = 0; r < n; r++) {
        const int err = hal_flash_read(offset, regions[r].data, regions[r].size);
        if (err) {
            return FW_ERR_IO;
        }
        offset += regions[r].size;
    }
    agent_learned_restored(ag);
    st->loads++;
    if (episodes != NULL) {
        *episodes = best_h.episodes;
    }
    return FW_OK;
}
