// SPDX-License-Identifier: MIT
// Tests of the boot journal (robot/boot_journal.h) on the host port's NOR flash: the early journal
// a fresh robot keeps before its first save, the journal after a record, and damaged entries.
#include "test_common.h"

#include <string.h>

#include "agent/agent.h"
#include "hal_host/hal_host.h"
#include "robot/boot_journal.h"
#include "robot/learned_digest.h"
#include "robot/learned_store.h"

// A small agent: a save is a few kilobytes.
enum { Q_STATES = 64, CELLS = 64, PQ_CAP = 32, TABLE = 32 };
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
static const agent_storage_t storage_ = {
    .q = q_, .q_value_bytes = sizeof q_[0], .q_keys = q_keys_, .q_states = Q_STATES,
    .dyna_q = {table_, tk_, tr_, TABLE},
    .dyna_qpc = {{fk_, fc_, fw_, CELLS}, {NULL, 0, NULL, 0, NULL, 0}, heap_, pk_, pp_, PQ_CAP, &carry_}};
static const agent_space_t space_ = {3, {3, 3, 2}, {0, 0, 0}, 0, 0, 4, 0, 0};
static agent_t agent_;

enum { SECTOR = 32768u, SLOT = 2u * SECTOR };  // two slots of 64 KB: the early journal's 32 KB fit

static void learn_(uint32_t steps)
{
    uint32_t x = 1, y = 1, h = 0;
    for (uint32_t i = 0; i < steps; i++) {
        const uint32_t comp[3] = {x, y, h};
        const agent_state_t s = space_pack(&space_, comp);
        const uint8_t a = agent_act(&agent_, s);
        x = (x + (a == 0)) & 7u;
        y = (y + (a == 1)) & 7u;
        h = (h + (a == 2)) & 3u;
        const uint32_t c2[3] = {x, y, h};
        agent_observe(&agent_, s, a, -0.01f, space_pack(&space_, c2), false);
    }
}

static int setup_(void **state)
{
    (void)state;
    hal_host_reset();
    assert_int_equal(hal_host_flash_configure(SECTOR, 4, 4), FW_OK);
    agent_config_t cfg = {AGENT_DYNA_QPC, &space_, agent_default_params(), &storage_, 1};
    assert_int_equal(agent_init(&agent_, &cfg), FW_OK);
    return 0;
}

// A boot as the application does it: the store, then the journal and its boot entry.
static bool boot_(learned_store_t *st, boot_journal_t *j, boot_journal_entry_t *last)
{
    assert_int_equal(learned_store_init(st), FW_OK);
    const bool found = boot_journal_open(j, st, last);
    assert_int_equal(boot_journal_append(j, last->episode, 0u, false), FW_OK);
    return found;
}

// Clears a word of flash (programming only clears bits): a corrupted entry.
static void corrupt_(uint32_t offset)
{
    const uint32_t zero = 0u;
    (void)hal_flash_write(offset, &zero, sizeof zero);
}

static bool erased_from_(uint32_t offset, uint32_t end)
{
    const uint8_t *p = (const uint8_t *)hal_flash_map(offset, end - offset);
    for (uint32_t i = 0; i < end - offset; i++) {
        if (p[i] != 0xFFu) {
            return false;
        }
    }
    return true;
}

// A fresh robot, no record: every boot is journaled in slot 1 and counted, and a boot that cut an
// episode finds it running with its steps. The store still reads both slots as empty.
static void test_boots_before_any_save_are_journaled(void **state)
{
    (void)state;
    learned_store_t st;
    boot_journal_t j;
    boot_journal_entry_t last;
    assert_false(boot_(&st, &j, &last));
    assert_true(j.ok);
    assert_true(j.early);
    assert_int_equal(j.boot, 1);
    assert_int_equal(j.next, SLOT + 32u + 16u);  // slot 1, after its header's place and the boot entry
    assert_int_equal(boot_journal_append(&j, 1u, 0u, true), FW_OK);
    for (uint32_t s = 1; s <= 7u; s++) {
        assert_int_equal(boot_journal_append(&j, 1u, s, true), FW_OK);
    }
    // Power cut. The next boot: one more, and the episode it cut.
    assert_true(boot_(&st, &j, &last));
    assert_int_equal(j.boot, 2);
    assert_true(last.running);
    assert_int_equal(last.episode, 1);
    assert_int_equal(last.steps, 7);
    assert_int_equal(last.boot, 1);
    assert_true(boot_(&st, &j, &last));
    assert_int_equal(j.boot, 3);
    assert_false(last.running);
    assert_int_equal(j.damaged, 0);
    // The store sees nothing: no record, both slots empty.
    assert_int_equal(learned_store_load(&st, &agent_, NULL), FW_ERR_NOENT);
    assert_int_equal(learned_store_slot_state(&st, &agent_, 0, NULL), LEARNED_SLOT_EMPTY);
    assert_int_equal(learned_store_slot_state(&st, &agent_, 1, NULL), LEARNED_SLOT_EMPTY);
    assert_true(erased_from_(0, SLOT));  // slot 0 untouched
}

// The first save goes to slot 0 and leaves the early journal; the journal follows the record and
// the count goes on; a power cut in the first save leaves the early journal whole; the second save
// erases it, and the count still goes on.
static void test_the_journal_follows_the_first_saves(void **state)
{
    (void)state;
    learned_store_t st;
    boot_journal_t j;
    boot_journal_entry_t last;
    (void)boot_(&st, &j, &last);
    (void)boot_(&st, &j, &last);
    assert_int_equal(boot_journal_append(&j, 1u, 0u, true), FW_OK);
    assert_int_equal(boot_journal_append(&j, 1u, 3u, true), FW_OK);
    learn_(100);
    // A cut half way through the first save.
    hal_host_flash_cut_power_after(1000u);
    assert_int_not_equal(learned_store_save(&st, &agent_, 1u), FW_OK);
    hal_host_flash_restore_power();
    assert_true(boot_(&st, &j, &last));
    assert_true(j.early);
    assert_int_equal(j.boot, 3);
    assert_true(last.running);
    assert_int_equal(last.steps, 3);
    assert_int_equal(learned_store_load(&st, &agent_, NULL), FW_ERR_NOENT);  // slot 0: no header yet
    // The save again, whole: into slot 0; the journal follows.
    assert_int_equal(learned_store_save(&st, &agent_, 1u), FW_OK);
    assert_int_equal(st.newest, 0);
    boot_journal_follow(&j, &st);
    assert_true(j.ok);
    assert_false(j.early);
    assert_true(j.next < SLOT);
    assert_int_equal(boot_journal_append(&j, 1u, 3u, false), FW_OK);
    assert_false(erased_from_(SLOT + 32u, SLOT + 48u));  // the early journal is still there
    assert_true(boot_(&st, &j, &last));
    assert_int_equal(j.boot, 4);
    assert_false(last.running);
    assert_int_equal(learned_store_load(&st, &agent_, NULL), FW_OK);
    // The second save erases slot 1 and the early journal with it; the count goes on.
    assert_int_equal(boot_journal_append(&j, 2u, 0u, true), FW_OK);
    assert_int_equal(learned_store_save(&st, &agent_, 2u), FW_OK);
    assert_int_equal(st.newest, 1);
    boot_journal_follow(&j, &st);
    assert_int_equal(boot_journal_append(&j, 2u, 5u, false), FW_OK);
    assert_true(boot_(&st, &j, &last));
    assert_int_equal(j.boot, 5);
    assert_false(j.early);
    assert_int_equal(last.episode, 2);
    assert_int_equal(learned_store_load(&st, &agent_, NULL), FW_OK);
}

// A corrupted entry is refused and counted; the entries before it, the next boot's count and the
// record are not lost, in the early journal and in a record's.
static void test_a_corrupted_entry_is_refused_and_loses_nothing_else(void **state)
{
    (void)state;
    learned_store_t st;
    boot_journal_t j;
    boot_journal_entry_t last;
    (void)boot_(&st, &j, &last);
    assert_int_equal(boot_journal_append(&j, 1u, 0u, true), FW_OK);
    assert_int_equal(boot_journal_append(&j, 1u, 4u, true), FW_OK);
    const uint32_t bad = j.next;
    assert_int_equal(boot_journal_append(&j, 1u, 5u, true), FW_OK);
    corrupt_(bad + 4u);  // the newest entry's episode word
    assert_true(boot_(&st, &j, &last));
    assert_int_equal(j.damaged, 1);
    assert_int_equal(j.boot, 2);
    assert_true(last.running);
    assert_int_equal(last.steps, 4);  // the entry before it
    assert_int_equal(j.next, bad + 32u);  // after the boot entry that went after the damaged one
    assert_int_equal(learned_store_load(&st, &agent_, NULL), FW_ERR_NOENT);
    // A record, then a corrupted entry in its journal: the record loads whole.
    learn_(100);
    const uint32_t want = learned_digest(&agent_);
    assert_int_equal(learned_store_save(&st, &agent_, 1u), FW_OK);
    boot_journal_follow(&j, &st);
    assert_int_equal(boot_journal_append(&j, 1u, 0u, false), FW_OK);
    const uint32_t bad2 = j.next;
    assert_int_equal(boot_journal_append(&j, 2u, 0u, true), FW_OK);
    corrupt_(bad2 + 12u);  // the newest entry's CRC
    assert_true(boot_(&st, &j, &last));
    assert_int_equal(j.damaged, 1);
    assert_int_equal(j.boot, 3);
    assert_int_equal(last.episode, 1);  // the entry before it
    assert_false(last.running);
    agent_config_t cfg = {AGENT_DYNA_QPC, &space_, agent_default_params(), &storage_, 2};
    assert_int_equal(agent_init(&agent_, &cfg), FW_OK);
    assert_int_equal(learned_store_load(&st, &agent_, NULL), FW_OK);
    assert_false(st.fell_back);
    assert_int_equal(learned_digest(&agent_), want);
}

// Slot 1 with something where a header goes (a damaged record) holds no early journal: nothing is
// written into it, and the boot says so (no journal) instead of writing over it.
static void test_no_early_journal_over_a_damaged_slot(void **state)
{
    (void)state;
    corrupt_(SLOT);
    learned_store_t st;
    boot_journal_t j;
    boot_journal_entry_t last;
    assert_int_equal(learned_store_init(&st), FW_OK);
    assert_false(boot_journal_open(&j, &st, &last));
    assert_false(j.ok);
    assert_int_equal(j.boot, 1);
    assert_int_equal(boot_journal_append(&j, 0u, 0u, false), FW_ERR_NOSYS);
    assert_true(erased_from_(SLOT + 4u, 2u * SLOT));
}

// Bounded: the early journal holds BOOT_JOURNAL_EARLY_BYTES; its last eighth takes boots, starts and
// ends but no steps; full, it takes nothing, and nothing is written past it.
static void test_the_early_journal_is_bounded(void **state)
{
    (void)state;
    learned_store_t st;
    boot_journal_t j;
    boot_journal_entry_t last;
    (void)boot_(&st, &j, &last);
    assert_int_equal(j.end - (SLOT + 32u), BOOT_JOURNAL_EARLY_BYTES);
    uint32_t steps = 0;
    while (boot_journal_append(&j, 1u, steps + 1u, true) == FW_OK) {
        steps++;
    }
    assert_int_equal(j.full, 1);
    assert_int_equal(j.end - j.next, BOOT_JOURNAL_EARLY_BYTES / 8u);
    uint32_t boots = 0;
    while (boot_journal_append(&j, 1u, 0u, false) == FW_OK) {
        boots++;
    }
    assert_int_equal(boots, BOOT_JOURNAL_EARLY_BYTES / 8u / BOOT_JOURNAL_ENTRY_BYTES);
    assert_int_equal(j.next, j.end);
    assert_true(erased_from_(j.end, 2u * SLOT));
    assert_true(boot_journal_open(&j, &st, &last));
    assert_int_equal(last.episode, 1);
    assert_false(last.running);
    assert_int_equal(boot_journal_append(&j, 1u, 0u, false), FW_ERR_NOMEM);
    assert_int_equal(steps, BOOT_JOURNAL_EARLY_BYTES * 7u / 8u / BOOT_JOURNAL_ENTRY_BYTES - 1u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_boots_before_any_save_are_journaled, setup_),
        cmocka_unit_test_setup(test_the_journal_follows_the_first_saves, setup_),
        cmocka_unit_test_setup(test_a_corrupted_entry_is_refused_and_loses_nothing_else, setup_),
        cmocka_unit_test_setup(test_no_early_journal_over_a_damaged_slot, setup_),
        cmocka_unit_test_setup(test_the_early_journal_is_bounded, setup_),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
