// SPDX-License-Identifier: MIT
// Tests of the world model: CMAC-Model forward, the relocatable model's generalisation, the
// predecessor search, and when a prediction is trusted.
#include "test_common.h"

#include <string.h>

#include "agent/model.h"
#include "fw/fw_base.h"

#define CELLS 4096u
static uint32_t fk_[CELLS];
static uint8_t fc_[CELLS];
static int16_t fw_[CELLS * (FW_CFG_MAX_COMPONENTS + 2)];
static const model_cmac_storage_t fwd_ = {fk_, fc_, fw_, CELLS};
// Places: x and heading (9 bits); situations: heading and code (6 bits) x 4 actions; positions: x.
static uint16_t percepts_[512];
static model_class_t classes_[64 * 4];
static int16_t arrivals_[32];
static const model_reloc_storage_t inv_ = {percepts_, 512, classes_, 256, arrivals_, 32};

// x (5 bits), heading (4 bits, circular), a range code (2 bits, predicted as a value).
static const agent_space_t robot_ = {3, {5, 4, 2}, {1, 0, 0}, 0x2, 0x4, 4, 0, 0};
// The same robot whose action effects generalise over x: keyed on heading and code.
static const agent_space_t rel_ = {3, {5, 4, 2}, {0, 0, 0}, 0x2, 0x4, 4, 0x6, 0};
// A corridor: one component, 4 bits, exact tiles.
static const agent_space_t line_ = {1, {4}, {0}, 0, 0, 2, 0, 0};

static agent_state_t robot_state(uint32_t x, uint32_t h, uint32_t r)
{
    const uint32_t c[3] = {x, h, r};
    return space_pack(&robot_, c);
}

// What both models learn a component's change as (space_change): x the difference, the heading
// the shorter way round, the range code its new value.
static void a_change_is_a_difference_a_wrapped_one_or_the_value(void **state)
{
    (void)state;
    assert_int_equal(space_change(&robot_, 0, 10, 12), 2);
    assert_int_equal(space_change(&robot_, 0, 12, 10), -2);
    assert_int_equal(space_change(&robot_, 0, 0, 31), 31);  // x does not wrap
    assert_int_equal(space_change(&robot_, 1, 15, 0), 1);   // turning right from 15 of 16
    assert_int_equal(space_change(&robot_, 1, 0, 15), -1);
    assert_int_equal(space_change(&robot_, 1, 0, 8), -8);   // half way: [-8, 8)
    assert_int_equal(space_change(&robot_, 1, 8, 0), -8);
    assert_int_equal(space_change(&robot_, 1, 0, 7), 7);
    assert_int_equal(space_change(&robot_, 2, 3, 1), 1);    // absolute: the new value
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
    model_pred_t preds[MODEL_MAX_PREDECESSORS];
    assert_int_equal(model_predecessors(&m, s2, preds), 1);
    assert_int_equal(preds[0].state, s);
    assert_int_equal(preds[0].action, 3);
}

// After walking 0 -> 1 -> ... -> 7 with action 1, every state's predecessor is known.
static void inverse_model_finds_predecessors(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &line_, 16, 1.0f, 1, &fwd_, &inv_), FW_OK);
    for (agent_state_t s = 0; s < 7; s++) {
        model_learn(&m, s, 1, s == 6 ? 1.0f : 0.0f, s + 1, s == 6);
    }
    model_pred_t preds[MODEL_MAX_PREDECESSORS];
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
    model_query_t store[MODEL_MAX_PREDECESSORS];
    model_query_t *queries[MODEL_MAX_PREDECESSORS];
    for (uint32_t i = 0; i < MODEL_MAX_PREDECESSORS; i++) {
        queries[i] = &store[i];
    }
    model_pred_t preds[MODEL_MAX_PREDECESSORS];
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
        model_pred_t a[MODEL_MAX_PREDECESSORS];
        model_pred_t b[MODEL_MAX_PREDECESSORS];
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

// A bump (the state does not change) is a predecessor too: its value depends on the state's.
// It does not hide the real predecessor that arrives by the same action.
static void self_loops_are_predecessors_beside_the_real_one(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &line_, 16, 1.0f, 1, &fwd_, &inv_), FW_OK);
    model_learn(&m, 14, 1, 0.0f, 15, false);
    model_learn(&m, 15, 1, -1.0f, 15, false);  // the wall at the end
    model_pred_t preds[MODEL_MAX_PREDECESSORS];
    assert_int_equal(model_predecessors(&m, 15, preds), 2);
    assert_int_equal(preds[0].state, 14);
    assert_int_equal(preds[1].state, 15);
    assert_float_equal(preds[1].reward, -1.0f, 0.01f);
}

// Two states that lead here by the same action are both found (CMAC-R named only the last);
// a candidate the forward model does not lead here is rejected.
static void every_observed_predecessor_is_found(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &line_, 16, 1.0f, 1, &fwd_, &inv_), FW_OK);
    model_learn(&m, 4, 0, 0.0f, 6, false);   // +2
    model_learn(&m, 8, 0, -2.0f, 6, false);  // -2
    model_learn(&m, 9, 0, 0.0f, 10, false);  // +1: makes 5 a candidate for 6, never tried
    model_pred_t preds[MODEL_MAX_PREDECESSORS];
    assert_int_equal(model_predecessors(&m, 6, preds), 2);
    assert_int_equal(preds[0].state, 4);
    assert_int_equal(preds[1].state, 8);
    assert_float_equal(preds[1].reward, -2.0f, 0.01f);
    assert_true(m.rejected > 0);
}

static agent_state_t rel_state(uint32_t x, uint32_t h, uint32_t r)
{
    const uint32_t c[3] = {x, h, r};
    return space_pack(&rel_, c);
}

// The relocatable model: driving forward with heading 4 and a clear code moved +1 three times;
// a place never driven from is predicted the same, with the code the map saw where it leads.
static void untried_pairs_are_predicted_by_their_situation(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &rel_, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    model_learn(&m, rel_state(20, 4, 2), 2, -1.0f, rel_state(20, 5, 3), false);  // (20, 4) shows 2
    model_step_t out;
    assert_false(model_predict(&m, rel_state(19, 4, 0), 0, &out));  // never seen
    for (uint32_t x = 1; x <= 3; x++) {
        model_learn(&m, rel_state(x, 4, 0), 0, -1.0f, rel_state(x + 1, 4, 0), false);
    }
    const uint32_t before = m.generalised;
    assert_true(model_predict(&m, rel_state(19, 4, 0), 0, &out));
    assert_int_equal(out.next, rel_state(20, 4, 2));
    assert_float_equal(out.reward, -1.0f, 0.01f);
    assert_int_equal(out.terminal, 0);
    assert_int_equal(m.generalised, before + 1);
    // Another situation (code 1) is another class: nothing known.
    assert_false(model_predict(&m, rel_state(19, 4, 1), 0, &out));
    // Where the map has never been, nothing is predicted.
    assert_false(model_predict(&m, rel_state(10, 4, 0), 0, &out));
    // A generalised pair is a predecessor: (19, 4, 0) leads to (20, 4, 2) by action 0, once the
    // map knows what (19, 4) shows.
    model_learn(&m, rel_state(19, 4, 0), 2, -1.0f, rel_state(19, 5, 0), false);
    model_pred_t preds[MODEL_MAX_PREDECESSORS];
    const uint32_t n = model_predecessors(&m, rel_state(20, 4, 2), preds);
    bool found = false;
    for (uint32_t i = 0; i < n; i++) {
        found = found || (preds[i].state == rel_state(19, 4, 0) && preds[i].action == 0);
    }
    assert_true(found);
}

// A situation not yet trusted (a heading never driven in with this code) falls back on what
// the action did at the same code in any heading: a bump facing one way predicts a bump facing
// another. Once the situation itself is trusted, its own outcome is the one used.
static void untried_headings_fall_back_on_the_percept(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &rel_, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    assert_int_equal(m.n_percept_classes, 4u * 4u);  // 2 code bits, 4 actions
    model_step_t out;
    assert_false(model_predict(&m, rel_state(10, 9, 1), 0, &out));
    for (uint32_t x = 1; x <= MODEL_PERCEPT_MIN_COUNT; x++) {
        assert_false(model_predict(&m, rel_state(10, 9, 1), 0, &out));
        model_learn(&m, rel_state(x, 4, 1), 0, -100.0f, rel_state(x, 4, 1), false);
    }
    const uint32_t before = m.generalised;
    assert_true(model_predict(&m, rel_state(10, 9, 1), 0, &out));
    assert_int_equal(out.next, rel_state(10, 9, 1));  // going nowhere, it keeps its code
    assert_true(out.reward == -100.0f);
    assert_int_equal(out.terminal, 0);
    assert_int_equal(m.generalised, before + 1);
    // Another code is another percept: nothing known.
    assert_false(model_predict(&m, rel_state(10, 9, 0), 0, &out));
    // Heading 9 with code 1 seen moving +1 three times: the situation's own outcome wins.
    model_learn(&m, rel_state(11, 2, 1), 2, -1.0f, rel_state(11, 9, 1), false);  // (11, 9) shows 1
    for (uint32_t x = 20; x <= 22; x++) {
        model_learn(&m, rel_state(x, 9, 1), 0, -1.0f, rel_state(x + 1, 9, 1), false);
    }
    assert_true(model_predict(&m, rel_state(10, 9, 1), 0, &out));
    assert_int_equal(out.next, rel_state(11, 9, 1));
    assert_true(out.reward == -1.0f);
}

// The same robot with its components in another order: the code first, then x, then the
// heading. Its situation (code and heading) is no longer one run of adjacent bits, so the model
// packs it component by component (select_() in model.c) instead of with one shift and mask.
static const agent_space_t rel_swapped_ = {3, {2, 5, 4}, {0, 0, 0}, 0x4, 0x1, 4, 0x5, 0};

static agent_state_t swapped_state(uint32_t x, uint32_t h, uint32_t r)
{
    const uint32_t c[3] = {r, x, h};
    return space_pack(&rel_swapped_, c);
}

typedef agent_state_t (*state_of_fn)(uint32_t x, uint32_t h, uint32_t r);

static uint32_t layout_run_(const agent_space_t *sp, state_of_fn st, model_step_t *out,
                            model_pred_t *preds)
{
    world_model_t m;
    assert_int_equal(model_init(&m, sp, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    model_learn(&m, st(20, 4, 2), 2, -1.0f, st(20, 5, 3), false);
    for (uint32_t x = 1; x <= 3; x++) {
        model_learn(&m, st(x, 4, 0), 0, -1.0f, st(x + 1, 4, 0), false);
    }
    model_learn(&m, st(19, 4, 0), 2, -1.0f, st(19, 5, 0), false);
    model_learn(&m, st(7, 4, 0), 3, -100.0f, st(7, 4, 0), false);
    assert_true(model_predict(&m, st(19, 4, 0), 0, out));
    return model_predecessors(&m, st(20, 4, 2), preds);
}

static void the_order_of_components_does_not_matter(void **state)
{
    (void)state;
    model_step_t a;
    model_step_t b;
    model_pred_t pa[MODEL_MAX_PREDECESSORS];
    model_pred_t pb[MODEL_MAX_PREDECESSORS];
    const uint32_t na = layout_run_(&rel_, rel_state, &a, pa);
    const uint32_t nb = layout_run_(&rel_swapped_, swapped_state, &b, pb);
    assert_int_equal(a.next, rel_state(20, 4, 2));
    assert_int_equal(b.next, swapped_state(20, 4, 2));
    assert_true(a.reward == b.reward && a.terminal == b.terminal);
    assert_true(na > 0u);
    assert_int_equal(na, nb);
    for (uint32_t i = 0; i < na; i++) {
        uint32_t c[3];
        space_unpack(&rel_, pa[i].state, c);
        assert_int_equal(pb[i].state, swapped_state(c[0], c[1], c[2]));
        assert_int_equal(pb[i].action, pa[i].action);
        assert_true(pb[i].reward == pa[i].reward);
    }
}

// The gates: a place never seen is not predictable, one seen with two codes has two outcomes; a
// situation's outcome is the
// majority of its observations, trusted once seen MODEL_CLASS_MIN_COUNT (3) times.
static void generalisation_is_gated_by_confidence(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &rel_, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    for (uint32_t x = 1; x <= 4; x++) {
        model_learn(&m, rel_state(x, 4, 0), 0, -1.0f, rel_state(x + 1, 4, 0), false);
    }
    model_step_t out;
    assert_false(model_predict(&m, rel_state(5, 4, 0), 0, &out));  // (6, 4) never seen
    model_learn(&m, rel_state(6, 4, 1), 2, -1.0f, rel_state(6, 5, 1), false);
    assert_true(model_predict(&m, rel_state(5, 4, 0), 0, &out));
    assert_int_equal(out.next, rel_state(6, 4, 1));
    model_learn(&m, rel_state(6, 4, 3), 2, -1.0f, rel_state(6, 5, 1), false);  // (6, 4) also 3
    // Two outcomes now, equally likely: code 1 (the first) and code 3.
    assert_true(model_predict(&m, rel_state(5, 4, 0), 0, &out));
    assert_int_equal(out.next, rel_state(6, 4, 1));
    assert_int_equal(out.others, 1u << 3);
    agent_state_t outcomes[MODEL_MAX_PERCEPTS];
    assert_int_equal(model_step_outcomes(&m, &out, outcomes), 2);
    assert_int_equal(outcomes[0], rel_state(6, 4, 1));
    assert_int_equal(outcomes[1], rel_state(6, 4, 3));
    // Each outcome has (5, 4) as a predecessor by action 0, the other outcome named with it.
    for (uint32_t k = 0; k < 2; k++) {
        model_pred_t pred[MODEL_MAX_PREDECESSORS];
        const uint32_t n = model_predecessors(&m, outcomes[k], pred);
        uint32_t found = 0;
        for (uint32_t i = 0; i < n; i++) {
            if (pred[i].state == rel_state(5, 4, 0) && pred[i].action == 0u) {
                found++;
                assert_int_equal(pred[i].others, k == 0u ? 1u << 3 : 1u << 1);
            }
        }
        assert_int_equal(found, 1);
    }
    // Contradicted (a bump), the usual outcome stays while it has the majority: 4 agreed, and
    // up to 4 disagree...
    model_learn(&m, rel_state(11, 4, 0), 2, -1.0f, rel_state(11, 5, 0), false);
    for (uint32_t i = 0; i < 4; i++) {
        model_learn(&m, rel_state(9, 4, 0), 0, -100.0f, rel_state(9, 4, 0), false);
        assert_true(model_predict(&m, rel_state(10, 4, 0), 0, &out));
        assert_int_equal(out.next, rel_state(11, 4, 0));
    }
    // ...the fifth replaces it with the bump. The situation has seen it once only; its
    // percept's outcome (the same observations, so the same bump) stands in.
    model_learn(&m, rel_state(9, 4, 0), 0, -100.0f, rel_state(9, 4, 0), false);
    assert_true(model_predict(&m, rel_state(10, 4, 0), 0, &out));
    assert_int_equal(out.next, rel_state(10, 4, 0));
    assert_true(out.reward == -100.0f);
}

// A situation's own outcome is used once seen MODEL_CLASS_MIN_COUNT (3) times; before, the
// percept's majority outcome over every heading stands in, even where the situation disagrees.
static void a_situation_is_trusted_after_three_observations(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &rel_, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    for (uint32_t x = 1; x <= 6; x++) {  // facing 8 with code 0, action 0 goes nowhere
        model_learn(&m, rel_state(x, 8, 0), 0, -1.0f, rel_state(x, 8, 0), false);
    }
    model_learn(&m, rel_state(21, 2, 0), 2, -1.0f, rel_state(21, 4, 0), false);  // (21, 4) shows 0
    model_step_t out;
    for (uint32_t x = 1; x <= MODEL_CLASS_MIN_COUNT; x++) {
        assert_true(model_predict(&m, rel_state(20, 4, 0), 0, &out));
        assert_int_equal(out.next, rel_state(20, 4, 0));  // the percept's: going nowhere
        model_learn(&m, rel_state(x, 4, 0), 0, -1.0f, rel_state(x + 1, 4, 0), false);
    }
    assert_true(model_predict(&m, rel_state(20, 4, 0), 0, &out));
    assert_int_equal(out.next, rel_state(21, 4, 0));  // the situation's: one ahead
}

// A tried pair keeps the outcome most of its observations agreed on: one that contradicts it
// counts against it, and replaces it only once the contradictions outnumber the agreements.
static void tried_pairs_keep_their_majority_outcome(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &rel_, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    const agent_state_t s = rel_state(3, 4, 0);
    for (uint32_t i = 0; i < 3; i++) {  // 3 agree: moves on
        model_learn(&m, s, 0, -1.0f, rel_state(4, 4, 0), false);
    }
    model_step_t out;
    for (uint32_t i = 0; i < 2; i++) {  // 2 slip: the move is still the outcome
        model_learn(&m, s, 0, -100.0f, s, false);
        assert_true(model_predict(&m, s, 0, &out));
        assert_int_equal(out.next, rel_state(4, 4, 0));
        assert_true(out.reward == -1.0f);
    }
    assert_int_equal(m.forward.stats.contradicted, 2);
    // The third contradiction finds the move's margin at 1 (3 agreed, 2 disagreed) and replaces it.
    model_learn(&m, s, 0, -100.0f, s, false);
    assert_true(model_predict(&m, s, 0, &out));
    assert_int_equal(out.next, s);
    assert_true(out.reward == -100.0f);
}

// Where an episode ended is a fact of the position: arriving there from anywhere ends it.
static void terminal_arrivals_are_predicted_by_position(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &rel_, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    for (uint32_t x = 10; x <= 12; x++) {  // backward with heading 4: -1
        model_learn(&m, rel_state(x, 4, 0), 1, -1.0f, rel_state(x - 1, 4, 0), false);
    }
    model_learn(&m, rel_state(5, 4, 0), 0, 100.0f, rel_state(6, 4, 0), true);  // the goal at x 6
    model_step_t out;
    assert_true(model_predict(&m, rel_state(7, 4, 0), 1, &out));
    assert_int_equal(out.next, rel_state(6, 4, 0));
    assert_int_equal(out.terminal, 1);
    assert_float_equal(out.reward, 100.0f, 0.01f);
}

// A prediction that leaves the state's range is not trusted. Tiles two values wide: state 1's
// change of -1 spills half into state 0 through their shared cell, and 0 - 1 is off the map.
static void out_of_range_predictions_are_untrusted(void **state)
{
    (void)state;
    static const agent_space_t wide = {1, {4}, {1}, 0, 0, 2, 0, 0};
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

// model_clear (RESET_LEARNING, and every model_init) leaves every table as a fresh model has it,
// however it was filled: no percept, no class, no arrival, no delta, no CMAC cell.
static void clear_empties_every_table(void **state)
{
    (void)state;
    memset(percepts_, 0xA5, sizeof percepts_);
    memset(classes_, 0xA5, sizeof classes_);
    memset(arrivals_, 0xA5, sizeof arrivals_);
    memset(fk_, 0xA5, sizeof fk_);
    memset(fc_, 0xA5, sizeof fc_);
    memset(fw_, 0xA5, sizeof fw_);
    world_model_t m;
    assert_int_equal(model_init(&m, &rel_, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    for (uint32_t round = 0; round < 2u; round++) {
        for (uint32_t i = 0; i < 400u; i++) {
            const uint32_t x = (i * 7u) % 32u, h = (i * 5u) % 16u, r = i % 4u;
            model_learn(&m, rel_state(x, h, r), (uint8_t)(i % 4u), i % 3u ? -1.0f : 5.0f,
                        rel_state((x + 1u) % 32u, (h + i) % 16u, (r + 1u) % 4u), i % 17u == 0u);
        }
        uint32_t cells = 0, seen = 0, arrived = 0;
        for (uint32_t i = 0; i < CELLS; i++) {
            cells += fc_[i] != 0u;
        }
        for (uint32_t i = 0; i < m.places; i++) {
            seen += percepts_[i] != 0u;
        }
        for (uint32_t i = 0; i < m.positions; i++) {
            arrived += arrivals_[i] != MODEL_NO_ARRIVAL;
        }
        assert_true(cells > 0u && seen > 0u && arrived > 0u);  // there is something to clear
        model_clear(&m);
        for (uint32_t i = 0; i < m.places; i++) {
            assert_int_equal(percepts_[i], 0);
        }
        for (uint32_t i = 0; i < m.n_classes; i++) {
            const model_class_t c = classes_[i];
            assert_int_equal(c.reward, 0);
            assert_int_equal(c.count, 0);
            assert_int_equal(c.miss, 0);
            for (uint32_t k = 0; k < FW_CFG_MAX_COMPONENTS; k++) {
                assert_int_equal(c.delta[k], 0);
            }
        }
        for (uint32_t i = 0; i < m.positions; i++) {
            assert_int_equal(arrivals_[i], MODEL_NO_ARRIVAL);
        }
        const uint8_t *d = (const uint8_t *)m.deltas;
        for (uint32_t i = 0; i < sizeof m.deltas; i++) {
            assert_int_equal(d[i], 0);
        }
        for (uint32_t i = 0; i < m.n_percept_classes; i++) {
            assert_int_equal(m.percept_classes[i].count, 0);
            assert_int_equal(m.percept_classes[i].miss, 0);
        }
        for (uint32_t i = 0; i < CELLS; i++) {
            assert_int_equal(fk_[i], OA_EMPTY);
            assert_int_equal(fc_[i], 0);
        }
        for (uint32_t i = 0; i < CELLS * m.forward.cfg.n_outputs; i++) {  // the outputs in use
            assert_int_equal(fw_[i], 0);
        }
        assert_int_equal(m.untrusted + m.rejected + m.generalised, 0);
        model_step_t out;
        assert_false(model_predict(&m, rel_state(1, 4, 0), 0, &out));
    }
}


// ---- Pins: what a mutation of model.c changed without a test failing

// The percept map answers whether a state was seen: both ends of every learned step, each with
// the percept seen there; not the same place with another percept, not a place never visited.
// A space without absolute components has no map and has seen nothing.
static void the_map_knows_which_states_were_seen(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &rel_, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    assert_false(model_has_seen(&m, rel_state(3, 4, 1)));
    model_learn(&m, rel_state(3, 4, 1), 0, -1.0f, rel_state(4, 4, 2), false);
    assert_true(model_has_seen(&m, rel_state(3, 4, 1)));
    assert_true(model_has_seen(&m, rel_state(4, 4, 2)));
    assert_false(model_has_seen(&m, rel_state(3, 4, 2)));  // the place, another percept
    assert_false(model_has_seen(&m, rel_state(4, 4, 1)));
    assert_false(model_has_seen(&m, rel_state(5, 4, 1)));  // another x
    assert_false(model_has_seen(&m, rel_state(3, 5, 1)));  // another heading
    model_learn(&m, rel_state(4, 4, 2), 2, -1.0f, rel_state(4, 5, 2), true);  // terminal too
    assert_true(model_has_seen(&m, rel_state(4, 5, 2)));
    model_clear(&m);
    assert_false(model_has_seen(&m, rel_state(3, 4, 1)));

    const model_reloc_storage_t none = {NULL, 0, NULL, 0, NULL, 0};
    assert_int_equal(model_init(&m, &line_, 16, 1.0f, 1, &fwd_, &none), FW_OK);
    model_learn(&m, 3, 1, 0.0f, 4, false);
    assert_false(model_has_seen(&m, 3));
    assert_false(model_has_seen(&m, 4));
}

// Whether a step ended the episode is learned as such, never read from its reward: a terminal
// bump worth -100, a terminal step worth 0 and a +100 step that goes on are each predicted as
// they happened, by CMAC-Model for the pairs tried and through the arrivals for the pairs the
// relocatable model predicts; a step that goes on is a predecessor, one that ends is not.
static void the_end_of_an_episode_is_not_read_from_its_reward(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &rel_, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    const agent_state_t bump = rel_state(3, 4, 0);
    model_learn(&m, bump, 0, -100.0f, bump, true);
    model_learn(&m, rel_state(5, 4, 0), 0, 0.0f, rel_state(6, 4, 0), true);
    model_learn(&m, rel_state(8, 4, 0), 0, 100.0f, rel_state(9, 4, 0), false);
    model_step_t out;
    assert_true(model_predict(&m, bump, 0, &out));
    assert_int_equal(out.next, bump);
    assert_int_equal(out.terminal, 1);
    assert_true(out.reward == -100.0f);
    assert_true(model_predict(&m, rel_state(5, 4, 0), 0, &out));
    assert_int_equal(out.next, rel_state(6, 4, 0));
    assert_int_equal(out.terminal, 1);
    assert_true(out.reward == 0.0f);
    assert_true(model_predict(&m, rel_state(8, 4, 0), 0, &out));
    assert_int_equal(out.next, rel_state(9, 4, 0));
    assert_int_equal(out.terminal, 0);
    assert_true(out.reward == 100.0f);
    // Seen again the same way, each keeps its outcome (an observation agrees with it).
    for (uint32_t i = 0; i < 2; i++) {
        model_learn(&m, rel_state(5, 4, 0), 0, 0.0f, rel_state(6, 4, 0), true);
        model_learn(&m, rel_state(8, 4, 0), 0, 100.0f, rel_state(9, 4, 0), false);
    }
    assert_int_equal(m.forward.stats.contradicted, 0);
    assert_true(model_predict(&m, rel_state(5, 4, 0), 0, &out));
    assert_int_equal(out.terminal, 1);
    assert_true(model_predict(&m, rel_state(8, 4, 0), 0, &out));
    assert_int_equal(out.terminal, 0);
    // The +100 step that goes on leads to 9 and is its predecessor; the 0 that ended is not 6's.
    model_pred_t preds[MODEL_MAX_PREDECESSORS];
    uint32_t n = model_predecessors(&m, rel_state(9, 4, 0), preds);
    bool found = false;
    for (uint32_t i = 0; i < n; i++) {
        found = found || (preds[i].state == rel_state(8, 4, 0) && preds[i].action == 0u &&
                          preds[i].reward == 100.0f);
    }
    assert_true(found);
    n = model_predecessors(&m, rel_state(6, 4, 0), preds);
    for (uint32_t i = 0; i < n; i++) {
        assert_false(preds[i].state == rel_state(5, 4, 0) && preds[i].action == 0u);
    }
    // Untried pairs: backward at heading 4 moves -1 (3 times: trusted). Arriving at x 6 ended an
    // episode with 0: terminal, worth 0. Arriving at x 9 did not end one, though worth +100 once:
    // not terminal, the situation's reward.
    for (uint32_t x = 20; x <= 22; x++) {
        model_learn(&m, rel_state(x, 4, 0), 1, -1.0f, rel_state(x - 1, 4, 0), false);
    }
    assert_true(model_predict(&m, rel_state(7, 4, 0), 1, &out));
    assert_int_equal(out.next, rel_state(6, 4, 0));
    assert_int_equal(out.terminal, 1);
    assert_true(out.reward == 0.0f);
    assert_true(model_predict(&m, rel_state(10, 4, 0), 1, &out));
    assert_int_equal(out.next, rel_state(9, 4, 0));
    assert_int_equal(out.terminal, 0);
    assert_true(out.reward == -1.0f);
}

// A circular component's change is learned the short way round across its whole range (an
// 8-bit heading: 255 -> 0 is +1, which fits a change and a CMAC weight; -255 fits neither), and
// a component that is not circular never wraps: a jump of +11 in 4 bits stays +11.
static const agent_space_t wrap_ = {3, {4, 8, 4}, {0, 0, 0}, 0x2, 0, 4, 0, 0};

static agent_state_t wrap_state(uint32_t x, uint32_t h, uint32_t y)
{
    const uint32_t c[3] = {x, h, y};
    return space_pack(&wrap_, c);
}

static void only_circular_components_wrap(void **state)
{
    (void)state;
    world_model_t m;
    const model_reloc_storage_t none = {NULL, 0, NULL, 0, NULL, 0};
    assert_int_equal(model_init(&m, &wrap_, 16, 1.0f, 1, &fwd_, &none), FW_OK);
    const struct {
        agent_state_t from;
        uint8_t a;
        agent_state_t to;
    } steps[] = {
        {wrap_state(3, 255, 5), 2, wrap_state(3, 0, 5)},   // turning right past 255
        {wrap_state(6, 0, 5), 3, wrap_state(6, 255, 5)},   // turning left past 0
        {wrap_state(1, 7, 2), 0, wrap_state(12, 7, 2)},    // x +11
        {wrap_state(14, 7, 2), 1, wrap_state(2, 7, 2)},    // x -12
        {wrap_state(1, 9, 2), 0, wrap_state(1, 9, 13)},    // y +11
        {wrap_state(1, 9, 15), 1, wrap_state(1, 9, 3)},    // y -12
    };
    const uint32_t n_steps = (uint32_t)(sizeof steps / sizeof steps[0]);
    for (uint32_t i = 0; i < n_steps; i++) {
        model_learn(&m, steps[i].from, steps[i].a, -1.0f, steps[i].to, false);
    }
    for (uint32_t i = 0; i < n_steps; i++) {
        model_step_t out;
        assert_true(model_predict(&m, steps[i].from, steps[i].a, &out));
        assert_int_equal(out.next, steps[i].to);
        assert_true(out.reward == -1.0f);
        model_pred_t preds[MODEL_MAX_PREDECESSORS];
        const uint32_t n = model_predecessors(&m, steps[i].to, preds);
        bool found = false;
        for (uint32_t j = 0; j < n; j++) {
            found = found || (preds[j].state == steps[i].from && preds[j].action == steps[i].a);
        }
        assert_true(found);
    }
}

// Components need not be adjacent: the code split in two, with x between its halves and the
// heading last, makes the places (x, heading), the situations (code, heading) and the percepts
// (the two halves) each a selection of components that are not next to each other, packed
// component by component (select_() and the model_select_t packing in model.c). The same walk
// learned in this layout and in rel_ (where every selection is one run of bits) must predict
// the same for every state and action, name the same predecessors, and see the same states.
static const agent_space_t split_ = {4, {2, 5, 1, 4}, {0, 0, 0, 0}, 0x8, 0x5, 4, 0xD, 0};
// rel_ with a 3-bit code, its twin.
static const agent_space_t rel3_ = {3, {5, 4, 3}, {0, 0, 0}, 0x2, 0x4, 4, 0x6, 0};

static agent_state_t split_of_(agent_state_t rel3)
{
    uint32_t c[3];
    space_unpack(&rel3_, rel3, c);
    const uint32_t s[4] = {c[2] & 3u, c[0], c[2] >> 2, c[1]};
    return space_pack(&split_, s);
}

static uint16_t rel3_percepts_[512];
static model_class_t rel3_classes_[128 * 4];
static int16_t rel3_arrivals_[32];
static const model_reloc_storage_t rel3_inv_ = {rel3_percepts_, 512, rel3_classes_, 512,
                                                rel3_arrivals_, 32};
static uint16_t split_percepts_[512];
static model_class_t split_classes_[128 * 4];
static int16_t split_arrivals_[32];
static const model_reloc_storage_t split_inv_ = {split_percepts_, 512, split_classes_, 512,
                                                 split_arrivals_, 32};
#define SPLIT_CELLS 4096u
static uint32_t sk_[SPLIT_CELLS];
static uint8_t sc_[SPLIT_CELLS];
static int16_t sw_[SPLIT_CELLS * (FW_CFG_MAX_COMPONENTS + 2)];
static const model_cmac_storage_t split_fwd_ = {sk_, sc_, sw_, SPLIT_CELLS};

// The walk: x 0..31 along the heading's sign, turns of one heading, a code that depends on the
// place (two codes at every seventh x), a slip now and then, the goal at x 25.
static uint32_t walk_code_(uint32_t x, uint32_t h, uint32_t t)
{
    const uint32_t code = ((x / 4u) + 3u * (h / 4u)) & 7u;
    return x % 7u == 3u && (t & 1u) ? (code ^ 5u) : code;
}

static void walk_(world_model_t *rel, world_model_t *split)
{
    uint32_t rng = 12345u;
    uint32_t x = 2, h = 0, code = walk_code_(2, 0, 0);
    for (uint32_t t = 0; t < 1500u; t++) {
        rng = rng * 1103515245u + 12345u;
        const uint32_t pick = (rng >> 16) % 10u;
        const uint8_t a = (uint8_t)(pick < 5u ? 0u : pick < 7u ? 1u : pick < 9u ? 2u : 3u);
        const bool slip = (rng >> 8) % 11u == 0u;
        uint32_t nx = x, nh = h;
        float r = -1.0f;
        if (a >= 2u) {
            nh = (h + (a == 2u ? 1u : 15u)) & 15u;
        } else if (!slip) {
            const int32_t step = (a == 0u) == (h < 8u) ? 1 : -1;
            const int32_t to = (int32_t)x + step;
            if (to < 0 || to > 31) {
                r = -100.0f;  // a bump
            } else {
                nx = (uint32_t)to;
            }
        }
        const uint32_t ncode = walk_code_(nx, nh, t);
        const bool goal = nx == 25u && nx != x;
        if (goal) {
            r = 100.0f;
        }
        const uint32_t c[3] = {x, h, code};
        const uint32_t nc[3] = {nx, nh, ncode};
        const agent_state_t s = space_pack(&rel3_, c);
        const agent_state_t sn = space_pack(&rel3_, nc);
        const bool a1 = model_learn(rel, s, a, r, sn, goal);
        const bool a2 = model_learn(split, split_of_(s), a, r, split_of_(sn), goal);
        assert_int_equal(a1, a2);
        if (goal) {
            x = (rng >> 4) % 20u;
            h = (rng >> 12) & 15u;
            code = walk_code_(x, h, t);
        } else {
            x = nx;
            h = nh;
            code = ncode;
        }
    }
}

static void components_need_not_be_adjacent(void **state)
{
    (void)state;
    static world_model_t rel;
    static world_model_t split;
    assert_int_equal(model_init(&rel, &rel3_, 1, 1.0f, 1, &fwd_, &rel3_inv_), FW_OK);
    assert_int_equal(model_init(&split, &split_, 1, 1.0f, 1, &split_fwd_, &split_inv_), FW_OK);
    assert_false(split.place_of.adjacent);
    assert_false(split.situation_of.adjacent);
    assert_false(split.percept_of.adjacent);
    walk_(&rel, &split);
    assert_int_equal(rel.forward.stats.evicted, 0);
    assert_int_equal(split.forward.stats.evicted, 0);
    uint32_t predicted = 0, several = 0, with_preds = 0, seen = 0;
    for (agent_state_t s = 0; s < (1u << 12); s++) {
        const agent_state_t t = split_of_(s);
        assert_int_equal(model_has_seen(&rel, s), model_has_seen(&split, t));
        seen += model_has_seen(&rel, s);
        for (uint8_t a = 0; a < 4u; a++) {
            model_step_t p;
            model_step_t q;
            const bool ok = model_predict(&rel, s, a, &p);
            assert_int_equal(model_predict(&split, t, a, &q), ok);
            if (!ok) {
                continue;
            }
            predicted++;
            assert_int_equal(q.next, split_of_(p.next));
            assert_true(q.reward == p.reward);
            assert_int_equal(q.terminal, p.terminal);
            assert_int_equal(q.others, p.others);  // percept values: the same index in both
            agent_state_t op[MODEL_MAX_PERCEPTS];
            agent_state_t oq[MODEL_MAX_PERCEPTS];
            const uint32_t n = model_step_outcomes(&rel, &p, op);
            assert_int_equal(model_step_outcomes(&split, &q, oq), n);
            for (uint32_t i = 0; i < n; i++) {
                assert_int_equal(oq[i], split_of_(op[i]));
            }
            several += n > 1u;
        }
        model_pred_t pp[MODEL_MAX_PREDECESSORS];
        model_pred_t pq[MODEL_MAX_PREDECESSORS];
        const uint32_t n = model_predecessors(&rel, s, pp);
        assert_int_equal(model_predecessors(&split, t, pq), n);
        for (uint32_t i = 0; i < n; i++) {
            assert_int_equal(pq[i].state, split_of_(pp[i].state));
            assert_int_equal(pq[i].action, pp[i].action);
            assert_int_equal(pq[i].others, pp[i].others);
            assert_true(pq[i].reward == pp[i].reward);
            with_preds += pp[i].others != 0u;
        }
    }
    assert_int_equal(rel.generalised, split.generalised);
    assert_int_equal(rel.rejected, split.rejected);
    assert_int_equal(rel.untrusted, split.untrusted);
    // The walk covered what it is meant to: many predictions, generalised ones, places with
    // several codes as outcomes and as predecessors.
    assert_true(seen > 100u);
    assert_true(predicted > 500u);
    assert_true(rel.generalised > 100u);
    assert_true(several > 10u);
    assert_true(with_preds > 10u);
}

// Stays (model.h): with the ordinary step's reward known, a step that changed nothing and earned
// it is counted beside the situation's move, never against it. Heading 4, code 0, action 0 moved
// +1 three times and stayed three times: the move is the outcome, staying half the time.
static void stays_are_counted_beside_their_move(void **state)
{
    (void)state;
    world_model_t with, without;
    assert_int_equal(model_init(&with, &rel_, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    model_set_stay_reward(&with, -1.0f);
    for (uint32_t x = 1; x <= 3; x++) {
        model_learn(&with, rel_state(x, 4, 0), 0, -1.0f, rel_state(x + 1, 4, 0), false);
        model_learn(&with, rel_state(x + 10, 4, 0), 0, -1.0f, rel_state(x + 10, 4, 0), false);
    }
    model_learn(&with, rel_state(20, 2, 0), 2, -1.0f, rel_state(20, 4, 0), false);  // (20, 4) shows 0
    model_step_t out;
    assert_true(model_predict(&with, rel_state(19, 4, 0), 0, &out));  // untried: generalised
    assert_int_equal(out.next, rel_state(20, 4, 0));
    assert_int_equal(out.stay, 128);  // 3 of 6, of 255, rounded
    assert_true(out.reward == -1.0f);
    // A tried move carries its situation's share; so does its predecessor.
    assert_true(model_predict(&with, rel_state(2, 4, 0), 0, &out));
    assert_int_equal(out.next, rel_state(3, 4, 0));
    assert_int_equal(out.stay, 128);
    model_learn(&with, rel_state(19, 4, 0), 2, -1.0f, rel_state(19, 6, 0), false);  // (19, 4) seen
    model_pred_t preds[MODEL_MAX_PREDECESSORS];
    const uint32_t n = model_predecessors(&with, rel_state(20, 4, 0), preds);
    bool found = false;
    for (uint32_t i = 0; i < n; i++) {
        if (preds[i].state == rel_state(19, 4, 0) && preds[i].action == 0) {
            found = true;
            assert_int_equal(preds[i].stay, 128);
        }
    }
    assert_true(found);

    // Without the step's reward every outcome is one: three moves and three changes of nothing
    // leave the situation's first outcome contested, and no prediction carries a share.
    assert_int_equal(model_init(&without, &rel_, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    for (uint32_t x = 1; x <= 3; x++) {
        model_learn(&without, rel_state(x, 4, 0), 0, -1.0f, rel_state(x + 1, 4, 0), false);
        model_learn(&without, rel_state(x + 10, 4, 0), 0, -1.0f, rel_state(x + 10, 4, 0), false);
    }
    model_learn(&without, rel_state(20, 2, 0), 2, -1.0f, rel_state(20, 4, 0), false);
    assert_true(model_predict(&without, rel_state(19, 4, 0), 0, &out));
    assert_int_equal(out.next, rel_state(20, 4, 0));
    assert_int_equal(out.stay, 0);
}

// A tried pair: a stay of its move leaves the move as its outcome (it was contradicted before);
// a move where only stays had been seen replaces them at once, and they become its stays.
static void a_tried_move_keeps_its_outcome_through_stays(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &rel_, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    model_set_stay_reward(&m, -1.0f);
    const agent_state_t s = rel_state(3, 4, 0), ahead = rel_state(4, 4, 0);
    model_learn(&m, s, 0, -1.0f, ahead, false);
    model_step_t out;
    for (uint32_t i = 0; i < 4; i++) {
        model_learn(&m, s, 0, -1.0f, s, false);
        assert_true(model_predict(&m, s, 0, &out));
        assert_int_equal(out.next, ahead);
    }
    assert_int_equal(m.forward.stats.contradicted, 0);
    assert_int_equal(out.stay, (4u * 255u + 2u) / 5u);

    const agent_state_t t = rel_state(8, 0, 0), east = rel_state(9, 0, 0);
    for (uint32_t i = 0; i < 3; i++) {
        model_learn(&m, t, 0, -1.0f, t, false);
    }
    assert_true(model_predict(&m, t, 0, &out));
    assert_int_equal(out.next, t);  // nothing else seen: staying is all it does
    assert_int_equal(out.stay, 0);
    model_learn(&m, t, 0, -1.0f, east, false);
    assert_true(model_predict(&m, t, 0, &out));
    assert_int_equal(out.next, east);
    assert_int_equal(out.stay, (3u * 255u + 2u) / 4u);
}

// A change of nothing with another reward (a bump: -100) is an outcome, not a stay: it counts
// against a move as before, and replaces it once the contradictions outnumber the agreements.
static void a_bump_is_not_a_stay(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &rel_, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    model_set_stay_reward(&m, -1.0f);
    const agent_state_t s = rel_state(3, 4, 0);
    for (uint32_t i = 0; i < 3; i++) {
        model_learn(&m, s, 0, -1.0f, rel_state(4, 4, 0), false);
    }
    model_step_t out;
    for (uint32_t i = 0; i < 2; i++) {
        model_learn(&m, s, 0, -100.0f, s, false);
    }
    assert_int_equal(m.forward.stats.contradicted, 2);
    model_learn(&m, s, 0, -100.0f, s, false);
    assert_true(model_predict(&m, s, 0, &out));
    assert_int_equal(out.next, s);
    assert_true(out.reward == -100.0f);
    assert_int_equal(out.stay, 0);
}

// A tried pair that only ever stayed, in a situation whose move is known, is predicted as that
// move (the same step, not finished there), with the situation's share of stays.
static void a_pair_that_only_stayed_is_its_situations_move(void **state)
{
    (void)state;
    world_model_t m;
    assert_int_equal(model_init(&m, &rel_, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    model_set_stay_reward(&m, -1.0f);
    for (uint32_t x = 1; x <= 3; x++) {
        model_learn(&m, rel_state(x, 4, 0), 0, -1.0f, rel_state(x + 1, 4, 0), false);
    }
    model_learn(&m, rel_state(21, 2, 0), 2, -1.0f, rel_state(21, 4, 0), false);  // (21, 4) shows 0
    const agent_state_t s = rel_state(20, 4, 0);
    model_learn(&m, s, 0, -1.0f, s, false);
    model_step_t out;
    assert_true(model_predict(&m, s, 0, &out));
    assert_int_equal(out.next, rel_state(21, 4, 0));
    assert_int_equal(out.stay, (1u * 255u + 2u) / 4u);
    // With stays off (the ablation), the same observations predict going nowhere.
    world_model_t off;
    assert_int_equal(model_init(&off, &rel_, 1, 1.0f, 1, &fwd_, &inv_), FW_OK);
    model_set_stay_reward(&off, -1.0f);
    off.ablate = MODEL_ABLATE_STAY;
    for (uint32_t x = 1; x <= 3; x++) {
        model_learn(&off, rel_state(x, 4, 0), 0, -1.0f, rel_state(x + 1, 4, 0), false);
    }
    model_learn(&off, rel_state(21, 2, 0), 2, -1.0f, rel_state(21, 4, 0), false);
    model_learn(&off, s, 0, -1.0f, s, false);
    assert_true(model_predict(&off, s, 0, &out));
    assert_int_equal(out.next, s);
    assert_int_equal(out.stay, 0);
}

static void init_rejects_bad_arguments(void **state)
{
    (void)state;
    world_model_t m;
    const agent_space_t bad = {0, {1, 1, 1, 1}, {0}, 0, 0, 4, 0, 0};
    assert_int_equal(model_init(&m, &bad, 16, 1.0f, 1, &fwd_, &inv_), FW_ERR_INVAL);
    assert_int_equal(model_init(&m, &line_, 16, 1.0f, 0, &fwd_, &inv_), FW_ERR_INVAL);
    assert_int_equal(model_init(&m, &line_, 3, 1.0f, 1, &fwd_, &inv_), FW_ERR_INVAL);
    const model_reloc_storage_t small = {percepts_, 256, classes_, 256, arrivals_, 32};
    assert_int_equal(model_init(&m, &robot_, 16, 1.0f, 1, &fwd_, &small), FW_ERR_INVAL);
    const model_reloc_storage_t none = {NULL, 0, NULL, 0, NULL, 0};
    assert_int_equal(model_init(&m, &line_, 16, 1.0f, 1, &fwd_, &none), FW_OK);
    assert_int_equal(model_init(&m, &rel_, 16, 1.0f, 1, &fwd_, &none), FW_ERR_INVAL);
}

// Aligned 90-degree turns over 16 headings (turn_step_bits 2). With room for every place the
// percept map keeps them all, a start's heading between turns too; with a quarter of the room
// it keeps the headings turns reach, and a place between them is not mapped (not seen, no
// percept recorded), while moves and predecessors along the turns' headings work as before.
static uint16_t quarter_[128 + 1];
static void percept_map_keeps_the_headings_turns_reach(void **state)
{
    (void)state;
    static const agent_space_t turned = {3, {5, 4, 2}, {0, 0, 0}, 0x2, 0x4, 4, 0x6, 2};
    const uint32_t from[3] = {3, 4, 0}, to[3] = {4, 4, 1}, off[3] = {7, 1, 2}, off2[3] = {8, 1, 3};
    const agent_state_t s = space_pack(&turned, from), s2 = space_pack(&turned, to);
    const agent_state_t t = space_pack(&turned, off), t2 = space_pack(&turned, off2);
    world_model_t m;

    assert_int_equal(model_init(&m, &turned, 16, 1.0f, 1, &fwd_, &inv_), FW_OK);  // 512 places
    assert_int_equal(m.places, 512);
    model_learn(&m, t, 0, -1.0f, t2, false);
    assert_true(model_has_seen(&m, t));  // every heading mapped

    const model_reloc_storage_t quarter = {quarter_, 128, classes_, 256, arrivals_, 32};
    quarter_[128] = 0xBEEFu;
    assert_int_equal(model_init(&m, &turned, 16, 1.0f, 1, &fwd_, &quarter), FW_OK);
    assert_int_equal(m.places, 128);
    model_learn(&m, s, 0, -1.0f, s2, false);
    assert_true(model_has_seen(&m, s));
    assert_true(model_has_seen(&m, s2));
    model_learn(&m, t, 0, -1.0f, t2, false);
    assert_false(model_has_seen(&m, t));  // between turns: not mapped
    assert_false(model_has_seen(&m, t2));
    assert_int_equal(quarter_[128], 0xBEEFu);  // nothing written past the map
    model_pred_t preds[MODEL_MAX_PREDECESSORS];
    const uint32_t n = model_predecessors(&m, s2, preds);
    assert_true(n >= 1u);
    assert_int_equal(preds[0].state, s);
    assert_int_equal(preds[0].action, 0);

    const model_reloc_storage_t too_small = {quarter_, 64, classes_, 256, arrivals_, 32};
    assert_int_equal(model_init(&m, &turned, 16, 1.0f, 1, &fwd_, &too_small), FW_ERR_INVAL);
    static const agent_space_t unaligned = {3, {5, 4, 2}, {0, 0, 0}, 0x2, 0x4, 4, 0x6, 0};
    assert_int_equal(model_init(&m, &unaligned, 16, 1.0f, 1, &fwd_, &quarter), FW_ERR_INVAL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_change_is_a_difference_a_wrapped_one_or_the_value),
        cmocka_unit_test(learns_and_predicts_a_transition),
        cmocka_unit_test(circular_component_wraps),
        cmocka_unit_test(inverse_model_finds_predecessors),
        cmocka_unit_test(predecessors_come_with_their_queries),
        cmocka_unit_test(self_loops_are_predecessors_beside_the_real_one),
        cmocka_unit_test(every_observed_predecessor_is_found),
        cmocka_unit_test(untried_pairs_are_predicted_by_their_situation),
        cmocka_unit_test(untried_headings_fall_back_on_the_percept),
        cmocka_unit_test(the_order_of_components_does_not_matter),
        cmocka_unit_test(generalisation_is_gated_by_confidence),
        cmocka_unit_test(a_situation_is_trusted_after_three_observations),
        cmocka_unit_test(tried_pairs_keep_their_majority_outcome),
        cmocka_unit_test(terminal_arrivals_are_predicted_by_position),
        cmocka_unit_test(out_of_range_predictions_are_untrusted),
        cmocka_unit_test(min_count_requires_repeated_training),
        cmocka_unit_test(clear_empties_every_table),
        cmocka_unit_test(init_rejects_bad_arguments),
        cmocka_unit_test(the_map_knows_which_states_were_seen),
        cmocka_unit_test(the_end_of_an_episode_is_not_read_from_its_reward),
        cmocka_unit_test(only_circular_components_wrap),
        cmocka_unit_test(components_need_not_be_adjacent),
        cmocka_unit_test(stays_are_counted_beside_their_move),
        cmocka_unit_test(a_tried_move_keeps_its_outcome_through_stays),
        cmocka_unit_test(a_bump_is_not_a_stay),
        cmocka_unit_test(a_pair_that_only_stayed_is_its_situations_move),
        cmocka_unit_test(percept_map_keeps_the_headings_turns_reach),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
