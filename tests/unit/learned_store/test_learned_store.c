// SPDX-License-Identifier: MIT
// Tests of the two-slot store of what was learned, on the host port's NOR flash, including a
// power cut at every byte offset of a save.
#include "test_common.h"

#include <string.h>

#include "agent/agent.h"
#include "fw/fw_crc.h"
#include "hal_host/hal_host.h"
#include "robot/learned_digest.h"
#include "robot/learned_store.h"

// A small agent, so that a save is a few kilobytes and cutting at every byte stays quick.
enum { Q_STATES = 64, CELLS = 64, PQ_CAP = 32 };
static value16_t q_[Q_STATES * FW_CFG_MAX_ACTIONS];
static uint32_t q_keys_[Q_STATES];
static uint32_t fk_[CELLS];
static uint8_t fc_[CELLS];
static int16_t fw_[CELLS * (FW_CFG_MAX_COMPONENTS + 2)];
static pq_item_t heap_[PQ_CAP];
static uint32_t pk_[PQ_INDEX_SLOTS(PQ_CAP)], pp_[PQ_INDEX_SLOTS(PQ_CAP)];
enum { TABLE = 32 };
static dynaq_record_t table_[TABLE];
static uint32_t tk_[DYNAQ_INDEX_SLOTS(TABLE)], tr_[DYNAQ_INDEX_SLOTS(TABLE)];
static agent_plan_carry_t carry_;
static const agent_storage_t storage_ = {
    .q = q_, .q_value_bytes = sizeof q_[0], .q_keys = q_keys_, .q_states = Q_STATES,
    .dyna_q = {table_, tk_, tr_, TABLE},
    .dyna_qpc = {{fk_, fc_, fw_, CELLS}, {NULL, 0, NULL, 0, NULL, 0}, heap_, pk_, pp_, PQ_CAP, &carry_}};
// 4 x 4 x 4 states of 6 bits (hashed: 64 rows for 64 states is dense; use 8 bits to hash).
static const agent_space_t space_ = {3, {3, 3, 2}, {0, 0, 0}, 0, 0, 4, 0, 0};
static agent_t agent_;

static agent_kind_t kind_ = AGENT_DYNA_QPC;

static void init_agent_(uint32_t seed)
{
    agent_config_t cfg = {kind_, &space_, agent_default_params(), &storage_, seed};
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

static int setup_(void **state)
{
    (void)state;
    kind_ = AGENT_DYNA_QPC;
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
    const uint32_t want = learned_digest(&agent_);
    const uint32_t rows = agent_.q.rows_used;
    assert_true(learned_store_record_size(&agent_) <= st.slot_size);
    assert_int_equal(learned_store_save(&st, &agent_, 12), FW_OK);
    // Reboot: a fresh agent, a fresh store over the same flash.
    init_agent_(2);
    assert_int_not_equal(learned_digest(&agent_), want);
    learned_store_t st2;
    assert_int_equal(learned_store_init(&st2), FW_OK);
    uint32_t episodes = 0;
    assert_int_equal(learned_store_load(&st2, &agent_, &episodes), FW_OK);
    assert_int_equal(episodes, 12);
    assert_int_equal(learned_digest(&agent_), want);
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
    const uint32_t want = learned_digest(&agent_);
    init_agent_(3);
    learned_store_t st2;
    uint32_t episodes = 0;
    assert_int_equal(learned_store_init(&st2), FW_OK);
    assert_int_equal(learned_store_load(&st2, &agent_, &episodes), FW_OK);
    assert_int_equal(episodes, 5);
    assert_int_equal(learned_digest(&agent_), want);
}

// The data loss (#24): learning saved, then RESET_LEARNING and saves of the new learning
// (the firmware counts episodes from 0 again). The record from before the wipe stays in flash
// through any number of such saves, survives a reboot, and restore_previous brings it back; the
// next save after the restore keeps it too.
static void test_reset_then_saves_keep_the_previous_record(void **state)
{
    (void)state;
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    uint32_t seq = 0, episodes = 0;
    assert_int_equal(learned_store_restore_previous(&st, &agent_, &seq, &episodes), FW_ERR_NOENT);
    for (uint32_t k = 156; k <= 157; k++) {  // two saves: both slots hold this learning
        learn_(60, k);
        assert_int_equal(learned_store_save(&st, &agent_, k), FW_OK);
    }
    const uint32_t learned = learned_digest(&agent_);
    const uint32_t learned_seq = st.newest_sequence;
    agent_reset(&agent_, 1);  // RESET_LEARNING
    const uint32_t wiped = learned_digest(&agent_);
    for (uint32_t k = 0; k <= 5; k++) {  // saves of the new learning, from episode 0
        learn_(k == 0 ? 0 : 10, k);
        assert_int_equal(learned_store_save(&st, &agent_, k), FW_OK);
        assert_true(st.newest_sequence > learned_seq);
    }
    const uint32_t relearned = learned_digest(&agent_);
    // Reboot: the newest record (the new learning) is what boots, the previous is kept.
    init_agent_(9);
    learned_store_t st2;
    assert_int_equal(learned_store_init(&st2), FW_OK);
    assert_int_equal(learned_store_load(&st2, &agent_, &episodes), FW_OK);
    assert_int_equal(episodes, 5);
    assert_int_equal(learned_digest(&agent_), relearned);
    assert_int_not_equal(relearned, wiped);
    assert_int_equal(learned_store_restore_previous(&st2, &agent_, &seq, &episodes), FW_OK);
    assert_int_equal(episodes, 157);
    assert_int_equal(seq, learned_seq);
    assert_int_equal(learned_digest(&agent_), learned);
    // Learning goes on from the restored record; its saves overwrite the wiped learning's.
    assert_int_equal(learned_store_save(&st2, &agent_, 158), FW_OK);
    assert_int_equal(learned_store_restore_previous(&st2, &agent_, &seq, &episodes), FW_OK);
    assert_int_equal(episodes, 157);
    assert_int_equal(learned_digest(&agent_), learned);
    // Without a wipe, saves alternate as before: the previous is the save before the last.
    learn_(20, 3);
    assert_int_equal(learned_store_save(&st2, &agent_, 159), FW_OK);
    assert_int_equal(learned_store_restore_previous(&st2, &agent_, &seq, &episodes), FW_OK);
    assert_int_equal(episodes, 158);
}

// A previous record that is damaged is refused, and the agent is left as it was.
static void test_restore_previous_refuses_a_damaged_record(void **state)
{
    (void)state;
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    learn_(60, 1);
    assert_int_equal(learned_store_save(&st, &agent_, 1), FW_OK);
    const int32_t first = st.newest;
    learn_(60, 2);
    assert_int_equal(learned_store_save(&st, &agent_, 2), FW_OK);
    const uint32_t now = learned_digest(&agent_);
    // The first record's magic cleared (programming can clear bits): no longer a whole record.
    const uint8_t zero[4] = {0, 0, 0, 0};
    assert_int_equal(hal_flash_write((uint32_t)first * st.slot_size, zero, 4), FW_OK);
    uint32_t seq = 0, episodes = 0;
    assert_int_equal(learned_store_restore_previous(&st, &agent_, &seq, &episodes), FW_ERR_CORRUPT);
    assert_int_equal(learned_digest(&agent_), now);
    uint32_t s2 = 0, e2 = 0;
    assert_true(learned_store_newest(&st, &s2, &e2));
    assert_int_equal(e2, 2);
}

static void test_corrupted_record_falls_back_to_the_other(void **state)
{
    (void)state;
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    learn_(100, 0);
    assert_int_equal(learned_store_save(&st, &agent_, 1), FW_OK);  // slot 0
    const uint32_t first = learned_digest(&agent_);
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
    assert_int_equal(learned_digest(&agent_), first);
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

// ---- Power cuts ---------------------------------------------------------------------------------

// The agent's learned bytes, to re-create the same save after each cut.
static uint8_t snapshot_[64 * 1024];

static void snapshot_take_(void)
{
    agent_region_t r[AGENT_MAX_REGIONS];
    const uint32_t n = agent_learned_regions(&agent_, r);
    uint32_t off = 0;
    for (uint32_t i = 0; i < n; i++) {
        assert_true(off + r[i].size <= sizeof snapshot_);
        memcpy(snapshot_ + off, r[i].data, r[i].size);
        off += r[i].size;
    }
}

static void snapshot_put_(void)
{
    agent_region_t r[AGENT_MAX_REGIONS];
    const uint32_t n = agent_learned_regions(&agent_, r);
    uint32_t off = 0;
    for (uint32_t i = 0; i < n; i++) {
        memcpy(r[i].data, snapshot_ + off, r[i].size);
        off += r[i].size;
    }
    agent_learned_restored(&agent_);
}

// Another agent kind's record over the same space, saved on the same flash.
static void save_foreign_(uint32_t episodes)
{
    const agent_kind_t mine = kind_;
    kind_ = mine == AGENT_Q_LEARNING ? AGENT_DYNA_Q : AGENT_Q_LEARNING;
    init_agent_(77);
    learn_(80, 3);
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    assert_int_equal(learned_store_save(&st, &agent_, episodes), FW_OK);
    kind_ = mine;
}

enum { FLASH_BYTES = 4 * 4096, SLOT_BYTES = 2 * 4096 };
static uint8_t flash_copy_[FLASH_BYTES];

static void flash_keep_(void)
{
    assert_int_equal(hal_flash_read(0, flash_copy_, FLASH_BYTES), FW_OK);
}

static void flash_put_back_(void)
{
    for (uint32_t s = 0; s < 4u; s++) {
        assert_int_equal(hal_flash_erase(s), FW_OK);
    }
    assert_int_equal(hal_flash_write(0, flash_copy_, FLASH_BYTES), FW_OK);
}

static void slot_unchanged_(uint32_t slot)
{
    static uint8_t now[SLOT_BYTES];
    assert_int_equal(hal_flash_read(slot * SLOT_BYTES, now, SLOT_BYTES), FW_OK);
    assert_memory_equal(now, flash_copy_ + slot * SLOT_BYTES, SLOT_BYTES);
}

// The flash as a scenario leaves it: the agent's good record (episodes 1) in `good_slot`, the
// other slot holding `other`: 0 nothing, 1 an older record of the agent's own (episodes 0: fewer,
// as learning goes; an older record with more episodes is one from before a RESET_LEARNING, kept
// by the next saves instead: test_reset_then_saves_keep_the_previous_record), 2 another agent's
// record saved after it (what made a save erase the only good copy).
// Returns the good record's fingerprint; the flash is kept in flash_copy_.
static uint32_t prepare_(uint32_t good_slot, int other)
{
    hal_host_flash_restore_power();
    assert_int_equal(hal_host_flash_configure(4096, 4, 4), FW_OK);
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    init_agent_(1);
    learn_(60, 5);
    const uint32_t older = (good_slot == 1u ? 1u : 0u) + (other == 1 && good_slot == 0u ? 2u : 0u);
    for (uint32_t i = 0; i < older; i++) {
        assert_int_equal(learned_store_save(&st, &agent_, 0), FW_OK);
    }
    init_agent_(1);
    learn_(200, 0);
    const uint32_t fp = learned_digest(&agent_);
    assert_int_equal(learned_store_save(&st, &agent_, 1), FW_OK);
    assert_int_equal(st.newest, (int32_t)good_slot);
    if (other == 0 && good_slot == 1u) {
        assert_int_equal(hal_flash_erase(0), FW_OK);
        assert_int_equal(hal_flash_erase(1), FW_OK);
    } else if (other == 2) {
        save_foreign_(50);
        init_agent_(1);  // our agent again, knowing what its good record holds
        learn_(200, 0);
        assert_int_equal(learned_digest(&agent_), fp);
    }
    flash_keep_();
    return fp;
}

// After a cut: a reboot must find the agent's last good copy (episodes 1), or the new record
// (episodes 2) when the save completed its header.
static void reboot_expect_(uint32_t old_fp, uint32_t new_fp, int err, uint32_t *old_seen,
                           uint32_t *new_seen)
{
    init_agent_(5);
    learned_store_t s2;
    uint32_t episodes = 0;
    assert_int_equal(learned_store_init(&s2), FW_OK);
    assert_int_equal(learned_store_load(&s2, &agent_, &episodes), FW_OK);
    if (episodes == 1) {
        assert_int_equal(learned_digest(&agent_), old_fp);
        assert_int_not_equal(err, FW_OK);
        (*old_seen)++;
    } else {
        assert_int_equal(episodes, 2);
        assert_int_equal(learned_digest(&agent_), new_fp);
        (*new_seen)++;
    }
}

// One save with the agent's new knowledge over the scenario's flash, cut by `cut` (which arms
// an injector), then a reboot.
static void cut_save_(uint32_t good_slot, uint32_t old_fp, uint32_t new_fp, uint32_t *old_seen,
                      uint32_t *new_seen, void (*arm)(uint32_t, uint32_t), uint32_t p1, uint32_t p2)
{
    flash_put_back_();
    init_agent_(1);
    snapshot_put_();
    learned_store_t s1;
    assert_int_equal(learned_store_init(&s1), FW_OK);
    arm(p1, p2);
    const int err = learned_store_save(&s1, &agent_, 2);
    hal_host_flash_restore_power();
    slot_unchanged_(good_slot);
    reboot_expect_(old_fp, new_fp, err, old_seen, new_seen);
}

static void arm_bytes_(uint32_t bytes, uint32_t unused)
{
    (void)unused;
    hal_host_flash_cut_power_after(bytes);
}

// The power goes off after k programmed bytes of a save, for every k, and inside each erase at
// several points; the slot choice is the store's own. Whatever the slot order and whatever the
// other slot holds (nothing, an older copy, another agent's newer record), a reboot finds the
// last good copy, and that copy's slot is never touched.
static void power_cuts_(agent_kind_t kind)
{
    kind_ = kind;
    for (uint32_t good_slot = 0; good_slot < 2u; good_slot++) {
        for (int other = 0; other < 3; other++) {
            const uint32_t old_fp = prepare_(good_slot, other);
            learn_(150, 1);
            const uint32_t new_fp = learned_digest(&agent_);
            assert_int_not_equal(old_fp, new_fp);
            snapshot_take_();
            const uint32_t record = learned_store_record_size(&agent_);
            uint32_t old_seen = 0, new_seen = 0;
            // Every byte; with an older copy beside (the slot choice as before the fix) every 7th.
            const uint32_t stride = other == 1 ? 7u : 1u;
            for (uint32_t k = 0; k <= record + 64; k += stride) {
                cut_save_(good_slot, old_fp, new_fp, &old_seen, &new_seen, arm_bytes_, k, 0);
            }
            assert_true(old_seen >= (record - 32u) / stride);  // every cut before the header's end
            assert_true(new_seen >= 1u);
            // Inside an erase: the slot's first or second sector, cut at several points.
            static const uint32_t at[] = {0, 1, 31, 32, 33, 2048, 4095, 4096};
            for (uint32_t e = 0; e < 2u; e++) {
                for (uint32_t i = 0; i < sizeof at / sizeof at[0]; i++) {
                    const uint32_t before = new_seen;
                    cut_save_(good_slot, old_fp, new_fp, &old_seen, &new_seen,
                              hal_host_flash_cut_power_in_erase, e, at[i]);
                    assert_int_equal(new_seen, before);
                }
            }
        }
    }
}

static void test_power_cut_at_every_byte_keeps_the_last_good_copy(void **state)
{
    (void)state;
    power_cuts_(AGENT_DYNA_QPC);
}

static void test_power_cuts_dyna_q(void **state)
{
    (void)state;
    power_cuts_(AGENT_DYNA_Q);
}

static void test_power_cuts_q_learning(void **state)
{
    (void)state;
    power_cuts_(AGENT_Q_LEARNING);
}

// The bug this fixes: the newest record on the flash is another agent's, so a save that chose
// "the slot without the newest record" erased this agent's only copy.
static void test_save_keeps_own_copy_beside_a_foreign_record(void **state)
{
    (void)state;
    learn_(100, 0);
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    assert_int_equal(learned_store_save(&st, &agent_, 1), FW_OK);  // slot 0
    save_foreign_(7);                                                // slot 1, newer
    kind_ = AGENT_DYNA_QPC;
    init_agent_(2);
    learned_store_t s2;
    assert_int_equal(learned_store_init(&s2), FW_OK);
    assert_int_equal(s2.newest, 1);
    assert_int_equal(learned_store_load(&s2, &agent_, NULL), FW_OK);
    assert_int_equal(s2.restored_slot, 0);
    assert_int_equal(s2.foreign_records, 1);  // passed over, counted: the boot reports it
    assert_int_equal(s2.refused_records + s2.corrupt_records, 0);
    learn_(10, 1);
    assert_int_equal(learned_store_save(&s2, &agent_, 2), FW_OK);
    assert_int_equal(s2.newest, 1);  // over the foreign record, not over our copy
    assert_int_equal(s2.foreign_overwritten, 1);
    assert_int_equal(learned_store_slot_state(&s2, &agent_, 0, NULL), LEARNED_SLOT_GOOD);
}

// ---- Records whose CRCs hold and whose contents are bad -----------------------------------------

typedef void (*spoil_fn)(void);

static uint32_t fresh_fp_;

// Saves the agent after `spoil` damaged its tables (the save's CRCs then cover the bad bytes),
// into slot `slot` with a good record (episodes 1) in the other slot or nothing there.
static void spoiled_record_is_refused_(agent_kind_t kind, spoil_fn spoil, bool with_good)
{
    hal_host_flash_restore_power();
    assert_int_equal(hal_host_flash_configure(4096, 4, 4), FW_OK);
    kind_ = kind;
    init_agent_(1);
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    learn_(40, 0);
    const uint32_t good_fp = learned_digest(&agent_);
    if (with_good) {
        assert_int_equal(learned_store_save(&st, &agent_, 1), FW_OK);
    }
    spoil();
    assert_int_equal(learned_store_save(&st, &agent_, 2), FW_OK);
    // Reboot: the record is refused where it lies; the agent is untouched.
    init_agent_(3);
    fresh_fp_ = learned_digest(&agent_);
    learned_store_t s2;
    uint32_t episodes = 0;
    assert_int_equal(learned_store_init(&s2), FW_OK);
    const int err = learned_store_load(&s2, &agent_, &episodes);
    assert_int_equal(s2.refused_records, 1);
    if (with_good) {
        assert_int_equal(err, FW_OK);
        assert_int_equal(episodes, 1);
        assert_true(s2.fell_back);
        assert_int_equal(s2.fallbacks, 1);
        assert_int_equal(learned_digest(&agent_), good_fp);
        // The next save goes over the refused record, never over the only good copy.
        assert_int_equal(learned_store_save(&s2, &agent_, 3), FW_OK);
        assert_int_equal(learned_store_slot_state(&s2, &agent_, 0, NULL), LEARNED_SLOT_GOOD);
        assert_int_equal(learned_store_slot_state(&s2, &agent_, 1, NULL), LEARNED_SLOT_GOOD);
    } else {
        assert_int_equal(err, FW_ERR_CORRUPT);
        assert_int_equal(learned_digest(&agent_), fresh_fp_);
    }
    // The agent works on: a few steps and plans do not crash (ASan) or hang.
    learn_(20, 2);
}

static void run_spoils_(agent_kind_t kind, const spoil_fn *spoils, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++) {
        spoiled_record_is_refused_(kind, spoils[i], false);
        spoiled_record_is_refused_(kind, spoils[i], true);
    }
}

// Q store (hashed: 64 rows for 256 states).
static uint32_t used_row_(uint32_t nth)
{
    for (uint32_t i = 0; i < Q_STATES; i++) {
        if (q_keys_[i] != QSTORE_EMPTY && nth-- == 0u) {
            return i;
        }
    }
    fail();
    return 0;
}
static uint32_t empty_row_(void)
{
    for (uint32_t i = 0; i < Q_STATES; i++) {
        if (q_keys_[i] == QSTORE_EMPTY) {
            return i;
        }
    }
    fail();
    return 0;
}
static void q_nan_(void) { q_[used_row_(0) * 4 + 1] = 0xfe00u; }  // exponent 63
static void q_inf_(void) { q_[3] = 0x7e01u; }                     // exponent 63
static void q_key_out_of_range_(void) { q_keys_[used_row_(0)] = 1u << 20; }
static void q_key_top_bit_(void) { q_keys_[used_row_(0)] = 0x80000001u; }
static void q_duplicate_key_(void) { q_keys_[used_row_(1)] = q_keys_[used_row_(0)]; }
static void q_empty_row_with_values_(void) { q_[empty_row_() * 4] = value16_from_float(0.5f); }
static void q_key_far_from_home_(void)
{
    // A key moved half the table away from where it was: outside its probe window.
    const uint32_t from = used_row_(0);
    const uint32_t to = (from + Q_STATES / 2u) % Q_STATES;
    q_keys_[to] = q_keys_[from];
    q_keys_[from] = QSTORE_EMPTY;
    memcpy(&q_[to * 4], &q_[from * 4], 4 * sizeof(value16_t));
    memset(&q_[from * 4], 0, 4 * sizeof(value16_t));
}

static const spoil_fn q_spoils_[] = {q_nan_,          q_inf_,           q_key_out_of_range_,
                                     q_key_top_bit_, q_duplicate_key_, q_empty_row_with_values_,
                                     q_key_far_from_home_};

static void test_bad_q_store_is_refused_for_every_agent(void **state)
{
    (void)state;
    const agent_kind_t kinds[] = {AGENT_Q_LEARNING, AGENT_DYNA_Q, AGENT_DYNA_QPC};
    for (uint32_t k = 0; k < 3u; k++) {
        run_spoils_(kinds[k], q_spoils_, sizeof q_spoils_ / sizeof q_spoils_[0]);
    }
}

// CMAC-Model and CMAC-R.
static uint32_t used_cell_(const uint32_t *keys, uint32_t nth)
{
    for (uint32_t i = 0; i < CELLS; i++) {
        if (keys[i] != CMAC_EMPTY && nth-- == 0u) {
            return i;
        }
    }
    fail();
    return 0;
}
static uint32_t empty_cell_(const uint32_t *keys)
{
    for (uint32_t i = 0; i < CELLS; i++) {
        if (keys[i] == CMAC_EMPTY) {
            return i;
        }
    }
    fail();
    return 0;
}
static void c_empty_with_count_(void) { fc_[empty_cell_(fk_)] = 3; }
static void c_empty_with_weight_(void) { fw_[empty_cell_(fk_) * 5 + 1] = -9; }
static void c_untrained_cell_(void) { fc_[used_cell_(fk_, 2)] = 0; }
static void c_key_top_bit_(void) { fk_[used_cell_(fk_, 0)] |= 0x80000000u; }
static void c_duplicate_(void) { fk_[used_cell_(fk_, 1)] = fk_[used_cell_(fk_, 0)]; }
static void c_displaced_(void)
{
    const uint32_t from = used_cell_(fk_, 0);
    const uint32_t to = (from + CELLS / 2u) % CELLS;
    fk_[to] = fk_[from];
    fc_[to] = fc_[from];
    fk_[from] = CMAC_EMPTY;
    fc_[from] = 0;
    memset(&fw_[from * 5], 0, 5 * sizeof(int16_t));
}
static const spoil_fn cmac_spoils_[] = {c_empty_with_count_, c_empty_with_weight_, c_untrained_cell_,
                                        c_key_top_bit_,      c_duplicate_,         c_displaced_};

static void test_bad_cmac_is_refused(void **state)
{
    (void)state;
    run_spoils_(AGENT_DYNA_QPC, cmac_spoils_, sizeof cmac_spoils_ / sizeof cmac_spoils_[0]);
}

// Dyna-Q's transition table: what crashed or hung the firmware.
static uint32_t used_index_(uint32_t nth)
{
    for (uint32_t i = 0; i < DYNAQ_INDEX_SLOTS(TABLE); i++) {
        if (tk_[i] != DYNAQ_EMPTY && nth-- == 0u) {
            return i;
        }
    }
    fail();
    return 0;
}
static void t_count_past_capacity_(void)
{
    // More indexed states than records (each new state's record then lies past the array).
    for (uint32_t i = 0, s = 200; i < DYNAQ_INDEX_SLOTS(TABLE) && s < 256u; i++) {
        if (tk_[i] == DYNAQ_EMPTY && (i % 8u) != 0u) {
            tk_[i] = s++;
            tr_[i] = 0;
        }
    }
}
static void t_full_index_(void)
{
    for (uint32_t i = 0; i < DYNAQ_INDEX_SLOTS(TABLE); i++) {
        if (tk_[i] == DYNAQ_EMPTY) {
            tk_[i] = 255u;
            tr_[i] = 0;
        }
    }
}
static void t_record_past_count_(void) { tr_[used_index_(0)] = TABLE + 5u; }
static void t_record_of_other_state_(void) { table_[tr_[used_index_(0)]].state ^= 1u; }
static void t_nothing_tried_(void) { memset(table_[0].tried, 0, sizeof table_[0].tried); }
static void t_action_past_n_(void) { table_[0].tried[0] |= 0x80u; }
static void t_terminal_untried_(void)
{
    for (uint32_t a = 0; a < 4u; a++) {
        if (!dynaq_bit(table_[0].tried, a)) {
            table_[0].terminal[0] |= (uint8_t)(1u << a);
            return;
        }
    }
    table_[0].terminal[0] |= 0x10u;
}
static uint32_t tried_action_(void)
{
    for (uint32_t a = 0; a < 4u; a++) {
        if (dynaq_bit(table_[0].tried, a)) {
            return a;
        }
    }
    fail();
    return 0;
}
static void t_next_out_of_range_(void) { table_[0].next[tried_action_()] = 1u << 12; }
static void t_reward_nan_(void) { table_[0].reward[tried_action_()] = 0.0f / 0.0f; }
static void t_duplicate_state_(void)
{
    // Two slots naming the same state, through two records.
    const uint32_t a = used_index_(0), b = used_index_(1);
    tk_[b] = tk_[a];
    table_[tr_[b]].state = tk_[a];
}
static void t_key_past_a_gap_(void)
{
    // A key moved past an empty slot after its home: a search stops at the gap.
    const uint32_t from = used_index_(0);
    uint32_t to = (from + 1u) % DYNAQ_INDEX_SLOTS(TABLE);
    while (tk_[to] != DYNAQ_EMPTY) {
        to = (to + 1u) % DYNAQ_INDEX_SLOTS(TABLE);
    }
    to = (to + 1u) % DYNAQ_INDEX_SLOTS(TABLE);
    while (tk_[to] != DYNAQ_EMPTY) {
        to = (to + 1u) % DYNAQ_INDEX_SLOTS(TABLE);
    }
    tk_[to] = tk_[from];
    tr_[to] = tr_[from];
    tk_[from] = DYNAQ_EMPTY;
}
static const spoil_fn table_spoils_[] = {
    t_count_past_capacity_, t_full_index_,       t_record_past_count_, t_record_of_other_state_,
    t_nothing_tried_,       t_action_past_n_,    t_terminal_untried_,  t_next_out_of_range_,
    t_reward_nan_,          t_duplicate_state_,  t_key_past_a_gap_};

static void test_bad_dyna_q_table_is_refused(void **state)
{
    (void)state;
    run_spoils_(AGENT_DYNA_Q, table_spoils_, sizeof table_spoils_ / sizeof table_spoils_[0]);
}

// The newest record damaged (a CRC fails): the older one is restored and the load says so.
static void test_fallback_is_reported(void **state)
{
    (void)state;
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    learn_(100, 0);
    assert_int_equal(learned_store_save(&st, &agent_, 1), FW_OK);
    const uint32_t first = learned_digest(&agent_);
    assert_int_equal(learned_store_save(&st, &agent_, 2), FW_OK);  // slot 1
    const uint8_t zero[4] = {0, 0, 0, 0};
    assert_int_equal(hal_flash_write(st.slot_size + 8u, zero, 4), FW_OK);  // the sequence
    init_agent_(4);
    learned_store_t s2;
    uint32_t episodes = 0;
    assert_int_equal(learned_store_init(&s2), FW_OK);
    assert_int_equal(learned_store_load(&s2, &agent_, &episodes), FW_OK);
    assert_int_equal(episodes, 1);
    assert_true(s2.fell_back);
    assert_int_equal(s2.corrupt_records, 1);
    assert_int_equal(learned_digest(&agent_), first);
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
        cmocka_unit_test_setup(test_power_cuts_dyna_q, setup_),
        cmocka_unit_test_setup(test_power_cuts_q_learning, setup_),
        cmocka_unit_test_setup(test_save_keeps_own_copy_beside_a_foreign_record, setup_),
        cmocka_unit_test_setup(test_bad_q_store_is_refused_for_every_agent, setup_),
        cmocka_unit_test_setup(test_bad_cmac_is_refused, setup_),
        cmocka_unit_test_setup(test_bad_dyna_q_table_is_refused, setup_),
        cmocka_unit_test_setup(test_fallback_is_reported, setup_),
        cmocka_unit_test_setup(test_reset_then_saves_keep_the_previous_record, setup_),
        cmocka_unit_test_setup(test_restore_previous_refuses_a_damaged_record, setup_),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
