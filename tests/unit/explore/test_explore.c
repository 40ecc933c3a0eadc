// SPDX-License-Identifier: MIT
// Tests of directed exploration: the tried-pairs table (explore.h) and the agent's bonus modes,
// the bonus on acting and Dyna-Q+'s bonus in planning (Dyna-Q and Dyna-QPC).
#include "test_common.h"

#include <math.h>
#include <string.h>

#include "agent/agent.h"
#include "agent/explore.h"
#include "fw/fw_base.h"
#include "fw/fw_prng.h"
#include "robot/agent_profiles.h"

#define SLOTS 32u
static uint32_t keys_[SLOTS];
static uint32_t at_[SLOTS];
static explore_table_t table_;

static void table_init_(void)
{
    memset(keys_, 0x5A, sizeof keys_);
    memset(at_, 0x5A, sizeof at_);
    assert_int_equal(explore_init(&table_, keys_, at_, SLOTS), FW_OK);
}

static void init_checks_its_storage(void **state)
{
    (void)state;
    assert_int_equal(explore_init(&table_, keys_, at_, 24u), FW_ERR_INVAL);  // not a power of two
    assert_int_equal(explore_init(&table_, NULL, at_, SLOTS), FW_ERR_INVAL);
    assert_int_equal(explore_init(&table_, keys_, NULL, SLOTS), FW_ERR_INVAL);
    table_init_();
    assert_int_equal(table_.used, 0);
}

// tau: the steps since the pair was last tried; a pair never tried counts from step 0.
static void untried_for_counts_steps_since_the_last_try(void **state)
{
    (void)state;
    table_init_();
    assert_int_equal(explore_untried_for(&table_, 7, 100), 100);  // never tried
    explore_tried(&table_, 7, 40);
    assert_int_equal(explore_untried_for(&table_, 7, 100), 60);
    explore_tried(&table_, 7, 90);  // tried again: the stamp moves, no second entry
    assert_int_equal(explore_untried_for(&table_, 7, 100), 10);
    assert_int_equal(explore_untried_for(&table_, 7, 80), 0);  // a clock behind the stamp
    assert_int_equal(explore_untried_for(&table_, 8, 100), 100);
    uint32_t tau = 12345;
    assert_false(explore_last_tried(&table_, 8, 100, &tau));  // never tried: not held
    assert_int_equal(tau, 12345);
    assert_true(explore_last_tried(&table_, 7, 100, &tau));
    assert_int_equal(tau, 10);
    assert_int_equal(table_.used, 1);
    explore_clear(&table_);
    assert_int_equal(explore_untried_for(&table_, 7, 100), 100);
    assert_int_equal(table_.used, 0);
}

// A full table forgets, of the new pair's window, the pair tried longest ago; the others stay.
static void a_full_table_forgets_the_oldest(void **state)
{
    (void)state;
    table_init_();
    for (uint32_t p = 0; p < SLOTS; p++) {
        explore_tried(&table_, p, 100u + p);  // pair 0 oldest
    }
    assert_int_equal(table_.used, SLOTS);
    assert_int_equal(table_.forgotten, 0);
    explore_tried(&table_, 1000, 500);
    assert_int_equal(table_.forgotten, 1);
    assert_int_equal(explore_untried_for(&table_, 1000, 500), 0);
    uint32_t lost = 0;
    uint32_t lost_pair = 0;
    for (uint32_t p = 0; p < SLOTS; p++) {
        if (explore_untried_for(&table_, p, 500) == 500u) {
            lost++;
            lost_pair = p;
        }
    }
    assert_int_equal(lost, 1);
    // The window holds FW_CFG_MAX_PROBE (16) of the 32 pairs: the forgotten one is the oldest
    // of them, older than every pair that stayed in the window.
    for (uint32_t i = 0; i < FW_CFG_MAX_PROBE; i++) {
        const uint32_t slot = (oa_home(&table_.index, 1000) + i) & (SLOTS - 1u);
        if (keys_[slot] != 1000u) {
            assert_true(at_[slot] > 100u + lost_pair);
        }
    }
}

static void sample_draws_held_pairs(void **state)
{
    (void)state;
    table_init_();
    prng_t rng;
    prng_seed(&rng, 3);
    uint32_t pair = 99;
    assert_false(explore_sample(&table_, &rng, &pair));
    explore_tried(&table_, 5, 1);
    explore_tried(&table_, 11, 2);
    uint32_t seen5 = 0, seen11 = 0;
    for (int i = 0; i < 200; i++) {
        assert_true(explore_sample(&table_, &rng, &pair));
        assert_true(pair == 5u || pair == 11u);
        seen5 += pair == 5u;
        seen11 += pair == 11u;
    }
    assert_true(seen5 > 0 && seen11 > 0);
}

static void bonus_is_kappa_sqrt_tau(void **state)
{
    (void)state;
    assert_float_equal(explore_bonus(0.5f, 0), 0.0f, 0.0f);
    assert_float_equal(explore_bonus(0.5f, 16), 2.0f, 1e-6f);
    assert_float_equal(explore_bonus(0.01f, 10000), 1.0f, 1e-6f);
}

// ---- The agent's modes ---------------------------------------------------------------------

// A corridor of 16 cells: action 0 moves left, action 1 right.
static const agent_space_t corridor_ = {1, {4}, {0}, 0, 0, 2, 0, 0};
static agent_t agent_;

static agent_config_t config_(agent_kind_t kind, uint8_t explore, float kappa)
{
    agent_config_t c;
    c.kind = kind;
    c.space = &corridor_;
    c.params = agent_default_params();
    c.params.explore = explore;
    c.params.kappa = kappa;
    c.params.plan_alpha = 1.0f;
    c.storage = &agent_storage_maze;
    c.seed = 1;
    return c;
}

static void init_checks_the_mode_and_kappa(void **state)
{
    (void)state;
    agent_config_t c = config_(AGENT_DYNA_QPC, AGENT_EXPLORE_MODES, 0.1f);
    assert_int_equal(agent_init(&agent_, &c), FW_ERR_INVAL);
    c = config_(AGENT_DYNA_QPC, AGENT_EXPLORE_PLAN_BONUS, -1.0f);
    assert_int_equal(agent_init(&agent_, &c), FW_ERR_INVAL);
    c = config_(AGENT_DYNA_QPC, AGENT_EXPLORE_ACT_BONUS, AGENT_KAPPA_MAX * 2.0f);
    assert_int_equal(agent_init(&agent_, &c), FW_ERR_INVAL);
    // A bonus mode needs the tried-pairs table; epsilon-greedy does not.
    agent_storage_t st = agent_storage_maze;
    st.tried_keys = NULL;
    st.tried_pairs = 0;
    c = config_(AGENT_DYNA_Q, AGENT_EXPLORE_PLAN_BONUS, 0.1f);
    c.storage = &st;
    assert_int_equal(agent_init(&agent_, &c), FW_ERR_INVAL);
    c = config_(AGENT_DYNA_Q, AGENT_EXPLORE_EGREEDY, 0.0f);
    c.storage = &st;
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
}

// epsilon-greedy keeps no stamps and lists no tried-pairs counters; a bonus mode does both.
static void only_the_bonus_modes_keep_stamps(void **state)
{
    (void)state;
    agent_counter_t out[AGENT_MAX_COUNTERS];
    agent_config_t c = config_(AGENT_DYNA_QPC, AGENT_EXPLORE_EGREEDY, 0.0f);
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    agent_observe(&agent_, 3, 1, -1.0f, 4, false);
    assert_int_equal(agent_.tried.used, 0);
    const uint32_t n = agent_counters(&agent_, out);
    c = config_(AGENT_DYNA_QPC, AGENT_EXPLORE_ACT_BONUS, 0.1f);
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    agent_observe(&agent_, 3, 1, -1.0f, 4, false);
    assert_int_equal(agent_.tried.used, 1);
    assert_int_equal(agent_counters(&agent_, out), n + 2u);
    // The tried-pairs counters come after the algorithm's own, before the aliasing watch's
    // three (agent_counters()).
    const uint32_t t = n - 3u;
    assert_string_equal(out[t].name, "tried_pairs");
    assert_int_equal(out[t].value, 1);
    assert_string_equal(out[t + 1u].name, "tried_forgotten");
    assert_string_equal(out[t + 2u].name, "alias_checked");
    agent_reset(&agent_, 1);
    assert_int_equal(agent_.tried.used, 0);
}

// The bonus on acting: with epsilon 0 the robot takes the pair untried longest unless a value
// outweighs the bonus; epsilon-greedy takes the better value.
static void act_bonus_prefers_what_was_not_tried(void **state)
{
    (void)state;
    agent_config_t c = config_(AGENT_Q_LEARNING, AGENT_EXPLORE_ACT_BONUS, 0.5f);
    c.params.epsilon = 0.0f;
    c.params.alpha = 1.0f;
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    agent_observe(&agent_, 5, 1, 1.0f, 15, true);  // Q(5, 1) = 1, tried at step 1
    // Step 1: tau(5, 0) = 1 (never tried: since step 0), tau(5, 1) = 0: 0 + 0.5 < 1 + 0.
    assert_int_equal(agent_act(&agent_, 5), 1);
    for (int i = 0; i < 15; i++) {  // 15 more steps elsewhere: now 16
        agent_observe(&agent_, 10, 0, 0.0f, 15, true);
    }
    // tau(5, 0) = 16 (bonus 2), tau(5, 1) = 15 (bonus 1.94): 1 + 1.94 wins.
    assert_int_equal(agent_act(&agent_, 5), 1);
    c.params.kappa = 10.0f;  // bonus 40 against 1 + 38.73: the untried action
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    agent_observe(&agent_, 5, 1, 1.0f, 15, true);
    for (int i = 0; i < 15; i++) {
        agent_observe(&agent_, 10, 0, 0.0f, 15, true);
    }
    assert_int_equal(agent_act(&agent_, 5), 0);
    c.params.explore = AGENT_EXPLORE_EGREEDY;
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    agent_observe(&agent_, 5, 1, 1.0f, 15, true);
    for (int i = 0; i < 15; i++) {
        agent_observe(&agent_, 10, 0, 0.0f, 15, true);
    }
    assert_int_equal(agent_act(&agent_, 5), 1);
}

// Dyna-Q+: a replayed pair's target carries kappa sqrt(tau); acting and real updates do not.
static void dyna_q_plan_bonus_adds_kappa_sqrt_tau(void **state)
{
    (void)state;
    for (uint8_t mode = AGENT_EXPLORE_EGREEDY; mode <= AGENT_EXPLORE_PLAN_BONUS; mode++) {
        agent_config_t c = config_(AGENT_DYNA_Q, mode, 0.25f);
        assert_int_equal(agent_init(&agent_, &c), FW_OK);
        agent_observe(&agent_, 3, 1, 1.0f, 15, true);  // tried at step 1
        for (int i = 0; i < 16; i++) {
            agent_observe(&agent_, 10, 0, 0.0f, 15, true);  // step 17: tau(3, 1) = 16
        }
        agent_plan(&agent_, 200);
        const float expect = mode == AGENT_EXPLORE_PLAN_BONUS ? 1.0f + 0.25f * 4.0f : 1.0f;
        assert_float_equal(agent_q(&agent_, 3, 1), expect, 1e-5f);
        assert_float_equal(agent_q(&agent_, 10, 0), 0.0f, 1e-6f);  // just tried: tau 0
    }
}

// Dyna-Q+ with prioritized sweeping: a pair tried once and never again is re-examined as its
// bonus grows (refresh_bonus_ in dyna_qpc.c), planned with the bonus, and the bonus reaches its
// predecessor; without the bonus the same run leaves it at its reward.
static void dyna_qpc_plan_bonus_reaches_pairs_untried_for_long(void **state)
{
    (void)state;
    float got[2];
    for (uint8_t mode = AGENT_EXPLORE_EGREEDY; mode <= AGENT_EXPLORE_PLAN_BONUS; mode++) {
        agent_config_t c = config_(AGENT_DYNA_QPC, mode, 0.25f);
        c.params.gamma = 0.5f;
        assert_int_equal(agent_init(&agent_, &c), FW_OK);
        agent_observe(&agent_, 3, 1, 1.0f, 15, true);  // tried at step 1
        agent_plan(&agent_, 1000);
        for (int i = 0; i < 63; i++) {  // step 64: tau(3, 1) = 63
            agent_observe(&agent_, 10, 0, 0.0f, 15, true);
            agent_plan(&agent_, 1000);
        }
        got[mode] = agent_q(&agent_, 3, 1);
    }
    assert_float_equal(got[0], 1.0f, 0.01f);
    // The last refresh saw tau between about 50 and 63: a bonus of 1.75 to 2.
    assert_true(got[1] > 1.0f + 0.25f * sqrtf(40.0f));
    assert_true(got[1] < 1.0f + 0.25f * sqrtf(64.0f) + 0.01f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(init_checks_its_storage),
        cmocka_unit_test(untried_for_counts_steps_since_the_last_try),
        cmocka_unit_test(a_full_table_forgets_the_oldest),
        cmocka_unit_test(sample_draws_held_pairs),
        cmocka_unit_test(bonus_is_kappa_sqrt_tau),
        cmocka_unit_test(init_checks_the_mode_and_kappa),
        cmocka_unit_test(only_the_bonus_modes_keep_stamps),
        cmocka_unit_test(act_bonus_prefers_what_was_not_tried),
        cmocka_unit_test(dyna_q_plan_bonus_adds_kappa_sqrt_tau),
        cmocka_unit_test(dyna_qpc_plan_bonus_reaches_pairs_untried_for_long),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
