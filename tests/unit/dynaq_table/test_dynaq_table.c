// SPDX-License-Identifier: MIT
// Tests of table-based Dyna-Q's model: what it records and how it samples (Fig. 5).
#include "test_common.h"

#include <string.h>

#include "agent/dynaq_table.h"
#include "fw/fw_base.h"

static dynaq_record_t records_[64];
static uint32_t index_keys_[DYNAQ_INDEX_SLOTS(64)];
static uint32_t index_rec_[DYNAQ_INDEX_SLOTS(64)];

static void setup_table(dynaq_table_t *t)
{
    assert_int_equal(dynaq_init(t, records_, index_keys_, index_rec_, 64, 4), FW_OK);
}

static void empty_table_has_nothing_to_sample(void **state)
{
    (void)state;
    dynaq_table_t t;
    setup_table(&t);
    prng_t r;
    prng_seed(&r, 1);
    agent_state_t s;
    agent_state_t s2;
    uint8_t a;
    float rew;
    bool term;
    assert_false(dynaq_sample(&t, &r, &s, &a, &rew, &s2, &term));
}

static void samples_only_what_was_observed_and_the_latest_outcome(void **state)
{
    (void)state;
    dynaq_table_t t;
    setup_table(&t);
    dynaq_remember(&t, 100, 2, 0.0f, 101, false);
    dynaq_remember(&t, 100, 2, 1.0f, 7, true);  // the same pair again: the latest outcome wins
    prng_t r;
    prng_seed(&r, 2);
    for (int i = 0; i < 50; i++) {
        agent_state_t s;
        agent_state_t s2;
        uint8_t a;
        float rew;
        bool term;
        assert_true(dynaq_sample(&t, &r, &s, &a, &rew, &s2, &term));
        assert_int_equal(s, 100);
        assert_int_equal(a, 2);
        assert_int_equal(s2, 7);
        assert_float_equal(rew, 1.0f, 0.0f);
        assert_true(term);
    }
    assert_int_equal(t.count, 1);
}

// Fig. 5: a uniformly random observed state, then a uniformly random action tried there. State 1
// has three actions tried and state 2 one: each state is drawn half the time, each of state 1's
// actions a sixth.
static void samples_states_then_actions_uniformly(void **state)
{
    (void)state;
    dynaq_table_t t;
    setup_table(&t);
    dynaq_remember(&t, 1, 0, 0.0f, 2, false);
    dynaq_remember(&t, 1, 1, 0.0f, 2, false);
    dynaq_remember(&t, 1, 3, 0.0f, 2, false);
    dynaq_remember(&t, 2, 1, 0.0f, 1, false);
    prng_t r;
    prng_seed(&r, 3);
    uint32_t hits[3][4] = {{0}};
    for (int i = 0; i < 60000; i++) {
        agent_state_t s;
        agent_state_t s2;
        uint8_t a;
        float rew;
        bool term;
        assert_true(dynaq_sample(&t, &r, &s, &a, &rew, &s2, &term));
        hits[s][a]++;
    }
    assert_int_equal(hits[1][2], 0);
    assert_in_range(hits[2][1], 29000, 31000);
    assert_in_range(hits[1][0], 9500, 10500);
    assert_in_range(hits[1][1], 9500, 10500);
    assert_in_range(hits[1][3], 9500, 10500);
}

// The index finds the state's record (or nothing) exactly as a brute-force search of the records.
static void expect_index_consistent_(const dynaq_table_t *t)
{
    uint32_t keys = 0;
    for (uint32_t i = 0; i <= t->index.mask; i++) {
        if (t->index.keys[i] == DYNAQ_EMPTY) {
            continue;
        }
        keys++;
        assert_true(t->index_rec[i] < t->count);
        assert_int_equal(t->records[t->index_rec[i]].state, t->index.keys[i]);
    }
    assert_int_equal(keys, t->count);
}

static uint8_t tried_of_(const dynaq_table_t *t, agent_state_t s)
{
    for (uint32_t i = 0; i < t->count; i++) {
        if (t->records[i].state == s) {
            return t->records[i].tried[0];
        }
    }
    return 0;
}

// A full table forgets the state it stored longest ago (first in, first out) and counts it;
// states that collide in the index stay findable after others leave (keys s * 64 all share
// their low bits before hashing, and the sequence wraps the ring several times).
static void full_table_forgets_the_oldest_state_and_counts(void **state)
{
    (void)state;
    dynaq_table_t t;
    setup_table(&t);
    for (uint32_t s = 0; s < 100; s++) {
        dynaq_remember(&t, s * 7919u, 0, (float)s, 0, false);
    }
    assert_int_equal(t.count, 64);
    assert_int_equal(t.evicted, 36);
    expect_index_consistent_(&t);
    assert_int_equal(tried_of_(&t, 35u * 7919u), 0);     // forgotten
    assert_int_equal(tried_of_(&t, 36u * 7919u), 0x1);   // the oldest kept
    dynaq_remember(&t, 99u * 7919u, 1, 0.0f, 0, false);  // a known state takes a new action
    assert_int_equal(t.evicted, 36);
    assert_int_equal(tried_of_(&t, 99u * 7919u), 0x3);
    for (uint32_t s = 0; s < 1000; s++) {
        dynaq_remember(&t, (s % 300u) * 64u, (uint8_t)(s & 3u), 0.0f, 1, false);
        expect_index_consistent_(&t);
    }
    assert_int_equal(t.count, 64);
    // The last 64 states remembered are the ones the table holds.
    for (uint32_t s = 1000 - 64; s < 1000; s++) {
        assert_true(tried_of_(&t, (s % 300u) * 64u) != 0);
    }
    dynaq_clear(&t);
    assert_int_equal(t.count, 0);
    assert_int_equal(t.evicted, 0);
}

static dynaq_record_t records2_[64];
static uint32_t index_keys2_[DYNAQ_INDEX_SLOTS(64)];
static uint32_t index_rec2_[DYNAQ_INDEX_SLOTS(64)];

// The table's own save regions, checked and restored into a second table over other arrays,
// give the same records, each found through the index; a record number past the count or a state
// moved off its probe path is refused.
static void saved_regions_check_and_restore_themselves(void **state)
{
    (void)state;
    dynaq_table_t t;
    dynaq_table_t back;
    setup_table(&t);
    for (uint32_t s = 0; s < 100; s++) {  // the oldest states leave: the index shifts back
        dynaq_remember(&t, s * 64u, (uint8_t)(s & 3u), (float)s, s + 1u, false);
    }
    agent_region_t r[DYNAQ_REGIONS];
    assert_int_equal(dynaq_regions(&t, r), DYNAQ_REGIONS);
    assert_int_equal(r[0].size, 64 * sizeof(dynaq_record_t));
    assert_int_equal(r[1].size, DYNAQ_INDEX_SLOTS(64) * sizeof(uint32_t));
    assert_int_equal(r[2].size, DYNAQ_INDEX_SLOTS(64) * sizeof(uint32_t));
    const void *image[DYNAQ_REGIONS] = {r[0].data, r[1].data, r[2].data};
    assert_int_equal(dynaq_check(&t, image, 18), FW_OK);

    assert_int_equal(dynaq_init(&back, records2_, index_keys2_, index_rec2_, 64, 4), FW_OK);
    agent_region_t rb[DYNAQ_REGIONS];
    assert_int_equal(dynaq_regions(&back, rb), DYNAQ_REGIONS);
    for (uint32_t i = 0; i < DYNAQ_REGIONS; i++) {
        memcpy(rb[i].data, r[i].data, r[i].size);
    }
    dynaq_restored(&back);
    assert_int_equal(back.count, t.count);
    expect_index_consistent_(&back);
    for (uint32_t s = 100 - 64; s < 100; s++) {
        assert_int_equal(tried_of_(&back, s * 64u), 1u << (s & 3u));
    }

    const void *bad[DYNAQ_REGIONS] = {records2_, index_keys2_, index_rec2_};
    uint32_t slot = 0;
    while (index_keys2_[slot] == DYNAQ_EMPTY) {
        slot++;
    }
    const uint32_t rec = index_rec2_[slot];
    index_rec2_[slot] = 64;  // no such record
    assert_int_equal(dynaq_check(&t, bad, 18), FW_ERR_CORRUPT);
    index_rec2_[slot] = rec;
    assert_int_equal(dynaq_check(&t, bad, 18), FW_OK);
    // A state moved to the empty slot just before its home: no search from its home finds it.
    uint32_t moved = 0;
    uint32_t before = 0;
    for (; moved <= back.index.mask; moved++) {
        if (index_keys2_[moved] != DYNAQ_EMPTY) {
            before = (oa_home(&back.index, index_keys2_[moved]) + back.index.mask) & back.index.mask;
            if (index_keys2_[before] == DYNAQ_EMPTY) {
                break;
            }
        }
    }
    assert_true(moved <= back.index.mask);  // half the slots are empty: there is one
    index_keys2_[before] = index_keys2_[moved];
    index_rec2_[before] = index_rec2_[moved];
    index_keys2_[moved] = DYNAQ_EMPTY;
    assert_int_equal(dynaq_check(&t, bad, 18), FW_ERR_CORRUPT);
}

// The index's slots: the power of two at least twice the records, for every capacity (the
// smear once left gaps: 1,311 records gave 4,032 slots, which the index refused).
static void index_slots_are_the_power_of_two_at_least_twice_the_records(void **state)
{
    (void)state;
    assert_int_equal(DYNAQ_INDEX_SLOTS(1311), 4096);
    assert_int_equal(DYNAQ_INDEX_SLOTS(1024), 2048);
    assert_int_equal(DYNAQ_INDEX_SLOTS(1025), 4096);
    for (uint32_t cap = 1; cap <= 70000u; cap++) {
        const uint32_t slots = DYNAQ_INDEX_SLOTS(cap);
        assert_true((slots & (slots - 1u)) == 0u && slots >= 2u * cap && slots < 4u * cap);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(empty_table_has_nothing_to_sample),
        cmocka_unit_test(samples_only_what_was_observed_and_the_latest_outcome),
        cmocka_unit_test(samples_states_then_actions_uniformly),
        cmocka_unit_test(full_table_forgets_the_oldest_state_and_counts),
        cmocka_unit_test(saved_regions_check_and_restore_themselves),
        cmocka_unit_test(index_slots_are_the_power_of_two_at_least_twice_the_records),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
