// SPDX-License-Identifier: MIT
// Fuzz target: what the learned store finds in flash at boot, for all three agents. The first
// byte picks the agent and the mode:
//  - raw: the rest of the input is the flash image (CRCs almost never hold: the framing);
//  - crafted: the agent learns from the input, its record is saved, then the input's patches
//    (offset, byte) change the payload and the CRCs are made to hold again, so the contents
//    reach the tables' own checks; optionally a good record sits in the other slot.
// Oracles: a refused load leaves the agent as it was; a restored agent learns and plans on
// without a sanitizer report or a hang, and what it saves next loads back exactly.
//
// Cost (docs/fuzzing.md "Speed"): learning was most of an input's time (up to 263 steps before
// the save, 64 after the load, each with planning). 8-135 steps before and 32 after reach the
// same edges at the same number of executions (817 against 819, from the committed corpus), at
// twice the rate. The learning core's table loops are built without comparison hooks
// (tests/fuzz/CMakeLists.txt): they were 60 % of the time, and 2.6 times the rate again.
#include <string.h>

#include "agent/agent.h"
#include "fuzz.h"
#include "fw/fw_base.h"
#include "fw/fw_crc.h"
#include "hal/hal_flash.h"
#include "hal_host/hal_host.h"
#include "robot/learned_store.h"

enum { Q_STATES = 64, CELLS = 64, PQ_CAP = 32, TABLE = 32, SECTOR = 4096, SLOT = 2 * SECTOR };
static value16_t q_[Q_STATES * FW_CFG_MAX_ACTIONS];
static uint32_t q_keys_[Q_STATES];
static uint32_t fk_[CELLS];
static uint8_t fc_[CELLS];
static int16_t fw_[CELLS * (FW_CFG_MAX_COMPONENTS + 2)];
static pq_item_t heap_[PQ_CAP];
static uint32_t pk_[PQ_INDEX_SLOTS(PQ_CAP)], pp_[PQ_INDEX_SLOTS(PQ_CAP)];
static dynaq_record_t table_[TABLE];
static uint32_t tk_[DYNAQ_INDEX_SLOTS(TABLE)], tr_[DYNAQ_INDEX_SLOTS(TABLE)];
static agent_plan_carry_t carry_;
static dynaq_record_t mtable_[TABLE];
static uint32_t mk_[DYNAQ_INDEX_SLOTS(TABLE)], mr_[DYNAQ_INDEX_SLOTS(TABLE)];
static uint8_t mcounts_[TABLE * FW_CFG_MAX_ACTIONS];
static const agent_storage_t storage_ = {
    .q = q_, .q_value_bytes = sizeof q_[0], .q_keys = q_keys_, .q_states = Q_STATES,
    .dyna_q = {table_, tk_, tr_, TABLE},
    .dyna_q_majority = {mtable_, mk_, mr_, mcounts_, TABLE},
    .dyna_qpc = {{fk_, fc_, fw_, CELLS}, {NULL, 0, NULL, 0, NULL, 0}, heap_, pk_, pp_, PQ_CAP, &carry_}};
// 8 x 8 x 4 states (8 bits), two of them tiled: hashed Q rows, generalising CMACs.
static const agent_space_t space_ = {3, {3, 3, 2}, {1, 1, 0}, 4, 0, 4, 0, 0};
static agent_t agent_;

static void init_(agent_kind_t kind, uint32_t seed)
{
    const agent_config_t cfg = {kind, &space_, agent_default_params(), &storage_, seed};
    if (agent_init(&agent_, &cfg) != FW_OK) {
        __builtin_trap();
    }
}

static uint32_t fingerprint_(void)
{
    agent_region_t r[AGENT_MAX_REGIONS];
    const uint32_t n = agent_learned_regions(&agent_, r);
    uint32_t crc = 0;
    for (uint32_t i = 0; i < n; i++) {
        crc = fw_crc32(crc, r[i].data, r[i].size);
    }
    return crc;
}

// Experience from a walk the input steers; then planning.
static void learn_(fuzz_in_t *in, uint32_t steps)
{
    agent_state_t s = 0;
    for (uint32_t i = 0; i < steps; i++) {
        const uint8_t a = (uint8_t)(in->left > 0u ? fuzz_u8(in) % 4u : agent_act(&agent_, s));
        const agent_state_t next = (s + 1u + 7u * a + i) & 0xFFu;
        agent_observe(&agent_, s, a, next == 0xFFu ? 1.0f : -0.01f, next, next == 0xFFu);
        (void)agent_plan(&agent_, 4);
        s = next;
    }
}

static void flash_write_(uint32_t offset, const uint8_t *bytes, uint32_t n)
{
    static uint8_t buf[4 * SECTOR];
    memset(buf, 0xFF, sizeof buf);
    memcpy(buf, bytes, n);
    (void)hal_flash_write(offset, buf, (n + 3u) & ~3u);
}

// The record in `slot` with its payload patched and its CRCs made to hold again.
static void patch_record_(uint32_t slot, fuzz_in_t *in)
{
    static uint8_t rec[SLOT];
    if (hal_flash_read(slot * SLOT, rec, SLOT) != FW_OK) {
        __builtin_trap();
    }
    learned_header_t h;
    memcpy(&h, rec, sizeof h);
    uint8_t *payload = rec + 32;  // the header's span with write_align 4
    const uint32_t n_patches = fuzz_u8(in) % 16u + 1u;
    for (uint32_t i = 0; i < n_patches && h.payload_size > 0u; i++) {
        const uint32_t at = fuzz_u16(in) % h.payload_size;
        const uint8_t mode = fuzz_u8(in);
        const uint8_t v = fuzz_u8(in);
        payload[at] = mode & 1u ? v : (uint8_t)(payload[at] ^ v);
        if (mode & 2u) {  // a whole word: keys and counts are words
            const uint32_t w = (at & ~3u) + 4u <= h.payload_size ? (at & ~3u) : 0u;
            const uint32_t word = fuzz_u32(in);
            memcpy(payload + w, &word, 4);
        }
    }
    h.payload_crc = fw_crc32(0, payload, h.payload_size);
    h.header_crc = fw_crc32(0, &h, (uint32_t)offsetof(learned_header_t, header_crc));
    memcpy(rec, &h, sizeof h);
    for (uint32_t s = 0; s < 2u; s++) {
        (void)hal_flash_erase(slot * 2u + s);
    }
    flash_write_(slot * SLOT, rec, 32u + h.payload_size);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_in_t in = {data, size};
    const uint8_t pick = fuzz_u8(&in);
    const agent_kind_t kind = (agent_kind_t)(pick % AGENT_KINDS);
    const bool crafted = (pick / AGENT_KINDS) & 1u;
    const bool good_beside = (pick / (2u * AGENT_KINDS)) & 1u;
    hal_host_reset();
    if (hal_host_flash_configure(SECTOR, 4, 4) != FW_OK) {
        __builtin_trap();
    }
    if (crafted) {
        learned_store_t st;
        (void)learned_store_init(&st);
        init_(kind, 1);
        learn_(&in, 8u + fuzz_u8(&in) % 128u);
        if (good_beside) {
            (void)learned_store_save(&st, &agent_, 1);  // slot 0
        }
        (void)learned_store_save(&st, &agent_, 2);  // slot 0, or 1 beside the good one
        patch_record_(good_beside ? 1u : 0u, &in);
    } else {
        const uint8_t *image;
        const size_t n = fuzz_take(&in, 4u * SECTOR, &image);
        flash_write_(0, image, (uint32_t)n);
    }
    // Boot.
    init_(kind, 7);
    const uint32_t fresh = fingerprint_();
    learned_store_t st;
    if (learned_store_init(&st) != FW_OK) {
        __builtin_trap();
    }
    uint32_t episodes = 0;
    const int err = learned_store_load(&st, &agent_, &episodes);
    if (err != FW_OK && fingerprint_() != fresh) {
        __builtin_trap();  // a refused record changed the agent
    }
    // The robot works on with whatever it restored, and saves.
    fuzz_in_t steer = {data, size};
    learn_(&steer, 32);
    if (learned_store_save(&st, &agent_, episodes + 1u) != FW_OK) {
        __builtin_trap();
    }
    const uint32_t saved = fingerprint_();
    init_(kind, 9);
    learned_store_t again;
    (void)learned_store_init(&again);
    if (learned_store_load(&again, &agent_, NULL) != FW_OK || fingerprint_() != saved) {
        __builtin_trap();  // what was just saved must load back exactly
    }
    return 0;
}
