// SPDX-License-Identifier: MIT
// Tests of the world model: CMAC-Model forward, CMAC-R backward, and when a prediction is trusted.
#include "test_common.h"

#include "agent/model.h"
#include "fw/fw_base.h"

#define CELLS 4096u
static uint32_t fk_[CELLS];
static uint8_t fc_[CELLS];
static int16_t fw_[CELLS * (FW_CFG_MAX_COMPONENTS + 2)];
static uint32_t ik_[CELLS];
static uint8_t ic_[CELLS];
static int16_t iw_[CELLS * FW_CFG_MAX_COMPONENTS];
static const model_cmac_storage_t fwd_ = {fk_, fc_, fw_, CELLS};
static const model_cmac_storage_t inv_ = {ik_, ic_, iw_, CELLS};

// x (5 bits), heading (4 bits, circular), a range code (2 bits, predicted as a value).
static const agent_space_t robot_ = {3, {5, 4, 2}, {1, 0, 0}, 0x2, 0x4, 4};
// A corridor: one component, 4 bits, exact tiles.
static const agent_space_t line_ = {1, {4}, {0}, 0, 0, 2};

static agent_state_t robot_state(uint32_t x, uint32_t h, uint32_t r)
{
    const uint32_t c[3] = {x, h, r};
    return space_pack(&robot_, c);
}

static void learns_and_predicts_a_transition(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &robot_, 16, 1.0f, 1, &fwd_, &inv_), FW_OK);
    const agent_state_t s = robot_state(10, 3, 1);
    const agent_state_t s2 = robot_state(11, 3, 2);
    model_step_t out;
    assert_false(model_predict(&m, s, 0, &out));
    model_learn(&m, s, 0, -1.0f, s2, false);
    assert_true(model_predict(&m, s, 0, &out));
    assert_int_equal(out.next, s2);
    assert_float_equal(out.reward, -1.0f, 0.07f);
    assert_int_equal(out.terminal, 0);
    assert_false(model_predict(&m, s, 1, &out));  // another action is another input

    model_learn(&m, s2, 0, 100.0f, s2, true);
    assert_true(model_predict(&m, s2, 0, &out));
    assert_int_equal(out.terminal, 1);
    assert_float_equal(out.reward, 100.0f, 0.07f);
}

// A heading of 15 turning right becomes 0: the model learns the change +1, not -15.
static void circular_component_wraps(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &robot_, 16, 1.0f, 1, &fwd_, &inv_), FW_OK);
    const agent_state_t s = robot_state(4, 15, 0);
    const agent_state_t s2 = robot_state(4, 0, 0);
    model_learn(&m, s, 3, -1.0f, s2, false);
    model_step_t out;
    assert_true(model_predict(&m, s, 3, &out));
    assert_int_equal(out.next, s2);
    model_pred_t preds[4];
    assert_int_equal(model_predecessors(&m, s2, preds), 1);
    assert_int_equal(preds[0].state, s);
    assert_int_equal(preds[0].action, 3);
}

// CMAC-R: after walking 0 -> 1 -> ... -> 7 with action 1, every state's predecessor is known.
static void inverse_model_finds_predecessors(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &line_, 16, 1.0f, 1, &fwd_, &inv_), FW_OK);
    for (agent_state_t s = 0; s < 7; s++) {
        model_learn(&m, s, 1, s == 6 ? 1.0f : 0.0f, s + 1, s == 6);
    }
    model_pred_t preds[2];
    for (agent_state_t s = 1; s < 7; s++) {
        assert_int_equal(model_predecessors(&m, s, preds), 1);
        assert_int_equal(preds[0].state, s - 1);
        assert_int_equal(preds[0].action, 1);
        assert_float_equal(preds[0].reward, 0.0f, 0.01f);
    }
    assert_int_equal(model_predecessors(&m, 0, preds), 0);
}

// The planner keeps what confirming a predecessor asked: its query, and the forward prediction,
// which leads back to the state asked about. Both must be what fresh questions would answer.
static void predecessors_come_with_their_queries(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &robot_, 16, 1.0f, 1, &fwd_, &inv_), FW_OK);
    const agent_state_t here = robot_state(10, 4, 1);
    model_learn(&m, robot_state(9, 4, 1), 0, -1.0f, here, false);   // forward
    model_learn(&m, robot_state(11, 4, 1), 1, -2.0f, here, false);  // backward
    model_learn(&m, robot_state(10, 3, 1), 2, -3.0f, here, false);  // a turn
    model_learn(&m, robot_state(8, 4, 1), 0, -1.0f, robot_state(9, 4, 1), false);
    model_query_t q;
    model_query_init(&m, here, &q);
    model_query_t store[4];
    model_query_t *const queries[4] = {&store[0], &store[1], &store[2], &store[3]};
    model_pred_t preds[4];
    const uint32_t n = model_query_predecessors(&m, &q, preds, queries);
    assert_int_equal(n, 3);
    for (uint32_t i = 0; i < n; i++) {
        model_query_t fresh;
        model_query_init(&m, preds[i].state, &fresh);
        assert_int_equal(queries[i]->state, preds[i].state);
        assert_memory_equal(queries[i]->comp, fresh.comp, sizeof fresh.comp[0] * robot_.n_components);
        model_step_t step;
        assert_true(model_query_predict(&m, queries[i], preds[i].action, &step));
        assert_int_equal(step.next, here);
        assert_float_equal(step.reward, preds[i].reward, 0.0f);
        assert_int_equal(step.terminal, 0);
        // Asked further, the kept query answers as a fresh one.
        model_pred_t a[4];
        model_pred_t b[4];
        const uint32_t na = model_query_predecessors(&m, queries[i], a, NULL);
        assert_int_equal(model_query_predecessors(&m, &fresh, b, NULL), na);
        for (uint32_t j = 0; j < na; j++) {
            assert_int_equal(a[j].state, b[j].state);
            assert_int_equal(a[j].action, b[j].action);
            assert_float_equal(a[j].reward, b[j].reward, 0.0f);
        }
        assert_true(i != 0 || na == 1);  // (9, 4, 1) has a predecessor of its own
    }
}

// A bump (the state does not change) is not taught to CMAC-R: it must not hide the real
// predecessor that arrives by the same action.
static void self_loops_do_not_overwrite_predecessors(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &line_, 16, 1.0f, 1, &fwd_, &inv_), FW_OK);
    model_learn(&m, 14, 1, 0.0f, 15, false);
    model_learn(&m, 15, 1, -1.0f, 15, false);  // the wall at the end
    model_pred_t preds[2];
    assert_int_equal(model_predecessors(&m, 15, preds), 1);
    assert_int_equal(preds[0].state, 14);
}

// When two states lead here by the same action, CMAC-R averages them into a state that leads
// nowhere; CMAC-Model does not confirm it and it is rejected.
static void unconfirmed_predecessors_are_rejected(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &line_, 16, 0.5f, 1, &fwd_, &inv_), FW_OK);
    for (int i = 0; i < 8; i++) {
        model_learn(&m, 4, 0, 0.0f, 6, false);  // +2
        model_learn(&m, 8, 0, 0.0f, 6, false);  // -2
    }
    model_pred_t preds[2];
    assert_int_equal(model_predecessors(&m, 6, preds), 0);
    assert_true(m.rejected > 0);
}

// A prediction that leaves the state's range is not trusted. Tiles two values wide: state 1's
// change of -1 spills half into state 0 through their shared cell, and 0 - 1 is off the map.
static void out_of_range_predictions_are_untrusted(void **state)
{
    (void)state;
    static const agent_space_t wide = {1, {4}, {1}, 0, 0, 2};
    world_model_t m;
    assert_int_equal(model_init(&m, &wide, 2, 1.0f, 1, &fwd_, &inv_), FW_OK);
    model_step_t out;
    model_learn(&m, 0, 0, 0.0f, 0, false);  // a bump at the wall: no change
    assert_true(model_predict(&m, 0, 0, &out));
    assert_int_equal(out.next, 0);
    for (int i = 0; i < 10; i++) {
        model_learn(&m, 1, 0, 0.0f, 0, false);
    }
    const uint32_t before = m.untrusted;
    assert_false(model_predict(&m, 0, 0, &out));
    assert_int_equal(m.untrusted, before + 1);
    assert_true(model_predict(&m, 1, 0, &out));
    assert_int_equal(out.next, 0);
}

static void min_count_requires_repeated_training(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &line_, 16, 1.0f, 3, &fwd_, &inv_), FW_OK);
    model_step_t out;
    model_learn(&m, 3, 1, 0.0f, 4, false);
    model_learn(&m, 3, 1, 0.0f, 4, false);
    assert_false(model_predict(&m, 3, 1, &out));
    model_learn(&m, 3, 1, 0.0f, 4, false);
    assert_true(model_predict(&m, 3, 1, &out));
    model_clear(&m);
    assert_false(model_predict(&m, 3, 1, &out));
}

static void init_rejects_bad_arguments(void **state)
{
    (void)state;
    world_model_t m;
    const agent_space_t bad = {0, {1, 1, 1, 1}, {0}, 0, 0, 4};
    assert_int_equal(model_init(&m, &bad, 16, 1.0f, 1, &fwd_, &inv_), FW_ERR_INVAL);
    assert_int_equal(model_init(&m, &line_, 16, 1.0f, 0, &fwd_, &inv_), FW_ERR_INVAL);
    assert_int_equal(model_init(&m, &line_, 3, 1.0f, 1, &fwd_, &inv_), FW_ERR_INVAL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(learns_and_predicts_a_transition),
        cmocka_unit_test(circular_component_wraps),
        cmocka_unit_test(inverse_model_finds_predecessors),
        cmocka_unit_test(predecessors_come_with_their_queries),
        cmocka_unit_test(self_loops_do_not_overwrite_predecessors),
        cmocka_unit_test(unconfirmed_predecessors_are_rejected),
        cmocka_unit_test(out_of_range_predictions_are_untrusted),
        cmocka_unit_test(min_count_requires_repeated_training),
        cmocka_unit_test(init_rejects_bad_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
