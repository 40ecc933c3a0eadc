// SPDX-License-Identifier: MIT
// Tests of the two-slot store of what was learned, on the host port's NOR flash, including a
// power cut at every byte offset of a save.
#include "test_common.h"

#include <string.h>

#include "agent/agent.h"
#include "fw/fw_crc.h"
#include "hal_host/hal_host.h"
#include "robot/learned_store.h"

// A small agent, so that a save is a few kilobytes and cutting at every byte stays quick.
enum { Q_STATES = 64, CELLS = 128, PQ_CAP = 32 };
static float q_[Q_STATES * FW_CFG_MAX_ACTIONS];
static uint32_t q_keys_[Q_STATES];
static uint32_t fk_[CELLS], ik_[CELLS];
static uint8_t fc_[CELLS], ic_[CELLS];
static int16_t fw_[CELLS * (FW_CFG_MAX_COMPONENTS + 2)], iw_[CELLS * FW_CFG_MAX_COMPONENTS];
static pq_item_t heap_[PQ_CAP];
static uint32_t pk_[PQ_INDEX_SLOTS(PQ_CAP)], pp_[PQ_INDEX_SLOTS(PQ_CAP)];
static const agent_storage_t storage_ = {
    q_, q_keys_, Q_STATES, {fk_, fc_, fw_, CELLS}, {ik_, ic_, iw_, CELLS}, heap_, pk_, pp_, PQ_CAP,
    NULL, NULL, NULL, 0};
// 4 x 4 x 4 states of 6 bits (hashed: 64 rows for 64 states is dense; use 8 bits to hash).
static const agent_space_t space_ = {3, {3, 3, 2}, {0, 0, 0}, 0, 0, 4};
static agent_t agent_;

static void init_agent_(uint32_t seed)
{
    agent_config_t cfg = {AGENT_DYNA_QPC, &space_, agent_default_params(), &storage_, seed};
    assert_int_equal(agent_init(&agent_, &cfg), FW_OK);
}

// Some experience: a deterministic walk on the 8 x 8 x 4 grid.
static void learn_(uint32_t steps, uint32_t salt)
{
    uint32_t x = 1, y = 1, h = 0;
    for (uint32_t i = 0; i < steps; i++) {
        const uint32_t comp[3] = {x, y, h};
        const agent_state_t s = space_pack(&space_, comp);
        const uint8_t a = agent_act(&agent_, s);
        x = (x + (a == 0) + salt) & 7u;
        y = (y + (a == 1)) & 7u;
        h = (h + (a == 2)) & 3u;
        const uint32_t c2[3] = {x, y, h};
        agent_observe(&agent_, s, a, (x == 7 && y == 7) ? 1.0f : -0.01f, space_pack(&space_, c2),
                      x == 7 && y == 7);
        (void)agent_plan(&agent_, 3);
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

static int setup_(void **state)
{
    (void)state;
    hal_host_reset();
    assert_int_equal(hal_host_flash_configure(4096, 4, 4), FW_OK);  // two slots of 8 KB
    init_agent_(1);
    return 0;
}

static void test_empty_flash_has_no_record(void **state)
{
    (void)state;
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    assert_int_equal(learned_store_load(&st, &agent_, NULL), FW_ERR_NOENT);
}

static void test_save_then_load_gives_back_the_agent(void **state)
{
    (void)state;
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    learn_(300, 0);
    const uint32_t want = fingerprint_();
    const uint32_t rows = agent_.q.rows_used;
    assert_true(learned_store_record_size(&agent_) <= st.slot_size);
    assert_int_equal(learned_store_save(&st, &agent_, 12), FW_OK);
    // Reboot: a fresh agent, a fresh store over the same flash.
    init_agent_(2);
    assert_int_not_equal(fingerprint_(), want);
    learned_store_t st2;
    assert_int_equal(learned_store_init(&st2), FW_OK);
    uint32_t episodes = 0;
    assert_int_equal(learned_store_load(&st2, &agent_, &episodes), FW_OK);
    assert_int_equal(episodes, 12);
    assert_int_equal(fingerprint_(), want);
    assert_int_equal(agent_.q.rows_used, rows);
}

static void test_newest_of_two_wins_and_saves_alternate(void **state)
{
    (void)state;
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    for (uint32_t k = 1; k <= 5; k++) {
        learn_(50, k);
        assert_int_equal(learned_store_save(&st, &agent_, k), FW_OK);
        assert_int_equal(st.newest, (int32_t)((k - 1) % 2));
    }
    const uint32_t want = fingerprint_();
    init_agent_(3);
    learned_store_t st2;
    uint32_t episodes = 0;
    assert_int_equal(learned_store_init(&st2), FW_OK);
    assert_int_equal(learned_store_load(&st2, &agent_, &episodes), FW_OK);
    assert_int_equal(episodes, 5);
    assert_int_equal(fingerprint_(), want);
}

static void test_corrupted_record_falls_back_to_the_other(void **state)
{
    (void)state;
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    learn_(100, 0);
    assert_int_equal(learned_store_save(&st, &agent_, 1), FW_OK);  // slot 0
    const uint32_t first = fingerprint_();
    learn_(100, 1);
    assert_int_equal(learned_store_save(&st, &agent_, 2), FW_OK);  // slot 1
    // A bit flips in slot 1's payload (programming can clear bits): its CRC no longer holds.
    uint8_t byte;
    const uint32_t at = st.slot_size + 200;
    assert_int_equal(hal_flash_read(at, &byte, 1), FW_OK);
    uint8_t word[4];
    assert_int_equal(hal_flash_read(at & ~3u, word, 4), FW_OK);
    // find a set bit to clear in that word
    int cleared = 0;
    for (int i = 0; i < 4 && !cleared; i++) {
        if (word[i] != 0) {
            word[i] &= (uint8_t)(word[i] - 1u);
            cleared = 1;
        }
    }
    if (!cleared) {
        // an all-zero word cannot be damaged by programming: damage the header instead
        assert_int_equal(hal_flash_read(st.slot_size, word, 4), FW_OK);
        word[0] = 0;
        assert_int_equal(hal_flash_write(st.slot_size, word, 4), FW_OK);
    } else {
        assert_int_equal(hal_flash_write(at & ~3u, word, 4), FW_OK);
    }
    init_agent_(4);
    learned_store_t st2;
    uint32_t episodes = 0;
    assert_int_equal(learned_store_init(&st2), FW_OK);
    assert_int_equal(learned_store_load(&st2, &agent_, &episodes), FW_OK);
    assert_int_equal(episodes, 1);
    assert_int_equal(fingerprint_(), first);
}

static void test_record_of_another_layout_is_refused(void **state)
{
    (void)state;
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    learn_(100, 0);
    assert_int_equal(learned_store_save(&st, &agent_, 1), FW_OK);
    // The same tables for Q-learning: another kind, another layout.
    agent_config_t cfg = {AGENT_Q_LEARNING, &space_, agent_default_params(), &storage_, 9};
    assert_int_equal(agent_init(&agent_, &cfg), FW_OK);
    learned_store_t st2;
    assert_int_equal(learned_store_init(&st2), FW_OK);
    assert_int_equal(learned_store_load(&st2, &agent_, NULL), FW_ERR_CORRUPT);
    assert_int_equal(agent_.q.rows_used, 0);  // untouched
}

// The power goes off after k programmed bytes of a save, for every k: a reboot finds the
// previous record whole (or the new one, once its header is complete), never garbage.
static void test_power_cut_at_every_byte_keeps_the_last_good_copy(void **state)
{
    (void)state;
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    learn_(200, 0);
    assert_int_equal(learned_store_save(&st, &agent_, 1), FW_OK);
    const uint32_t old_fp = fingerprint_();
    learn_(200, 1);
    const uint32_t new_fp = fingerprint_();
    assert_int_not_equal(old_fp, new_fp);
    const uint32_t record = learned_store_record_size(&agent_);
    // Keep the agent's bytes to re-create the same save each time.
    static uint8_t snapshot[64 * 1024];
    agent_region_t r[AGENT_MAX_REGIONS];
    const uint32_t n = agent_learned_regions(&agent_, r);
    uint32_t off = 0;
    for (uint32_t i = 0; i < n; i++) {
        assert_true(off + r[i].size <= sizeof snapshot);
        memcpy(snapshot + off, r[i].data, r[i].size);
        off += r[i].size;
    }
    uint32_t old_seen = 0, new_seen = 0;
    for (uint32_t k = 0; k <= record + 64; k++) {
        // Flash holds the old record in slot 0; slot 1 holds whatever the last cut left.
        learned_store_t s1;
        assert_int_equal(learned_store_init(&s1), FW_OK);
        s1.newest = 0;  // the old record is the newest good one: the save goes to slot 1
        s1.newest_sequence = 1;
        hal_host_flash_cut_power_after(k);
        const int err = learned_store_save(&s1, &agent_, 2);
        hal_host_flash_restore_power();
        // Reboot into a fresh agent.
        init_agent_(5);
        learned_store_t s2;
        uint32_t episodes = 0;
        assert_int_equal(learned_store_init(&s2), FW_OK);
        assert_int_equal(learned_store_load(&s2, &agent_, &episodes), FW_OK);
        if (episodes == 1) {
            assert_int_equal(fingerprint_(), old_fp);
            old_seen++;
            assert_int_not_equal(err, FW_OK);
        } else {
            assert_int_equal(episodes, 2);
            assert_int_equal(fingerprint_(), new_fp);
            new_seen++;
        }
        // Back to the agent with the new knowledge, for the next save.
        off = 0;
        for (uint32_t i = 0; i < n; i++) {
            memcpy(r[i].data, snapshot + off, r[i].size);
            off += r[i].size;
        }
        agent_learned_restored(&agent_);
        // Slot 0 must stay the old record: erase slot 1 only if the new one landed there.
    }
    assert_true(old_seen >= record);  // every cut before the header's last byte
    assert_true(new_seen >= 1);       // and the complete saves
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_empty_flash_has_no_record, setup_),
        cmocka_unit_test_setup(test_save_then_load_gives_back_the_agent, setup_),
        cmocka_unit_test_setup(test_newest_of_two_wins_and_saves_alternate, setup_),
        cmocka_unit_test_setup(test_corrupted_record_falls_back_to_the_other, setup_),
        cmocka_unit_test_setup(test_record_of_another_layout_is_refused, setup_),
        cmocka_unit_test_setup(test_power_cut_at_every_byte_keeps_the_last_good_copy, setup_),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
