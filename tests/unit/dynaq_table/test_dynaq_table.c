// SPDX-License-Identifier: MIT
// Tests of table-based Dyna-Q's model: what it records and how it samples (Fig. 5).
#include "test_common.h"

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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(empty_table_has_nothing_to_sample),
        cmocka_unit_test(samples_only_what_was_observed_and_the_latest_outcome),
        cmocka_unit_test(samples_states_then_actions_uniformly),
        cmocka_unit_test(full_table_forgets_the_oldest_state_and_counts),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
