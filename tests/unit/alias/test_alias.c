// SPDX-License-Identifier: MIT
// Tests of the aliasing watch (alias.h) and of what the agent does with it: counting per cell,
// Space-Saving's replacement, the counters and facts of agent_walk(), and the real step's
// smaller learning rate in a cell whose outcomes keep disagreeing.
#include "test_common.h"

#include <string.h>

#include "agent/agent.h"
#include "agent/alias.h"
#include "fw/fw_base.h"
#include "robot/agent_profiles.h"

// x, y (2 bits each), heading (2 bits, the context) and a code (1 bit, absolute): the cell is
// the low 4 bits.
static const agent_space_t robot_ = {4, {2, 2, 2, 1}, {0}, 0x4u, 0x8u, 4, 0x0Cu, 0};

static agent_state_t state_(uint32_t x, uint32_t y, uint32_t h, uint32_t c)
{
    return x | y << 2 | h << 4 | c << 6;
}

static void counts_per_cell_over_headings_and_codes(void **state)
{
    (void)state;
    alias_watch_t w;
    alias_init(&w);
    const uint32_t cell = space_position_mask(&robot_);
    assert_int_equal(cell, 0x0Fu);
    assert_int_equal(alias_note(&w, state_(1, 2, 0, 0) & cell, false), 0);
    assert_int_equal(alias_note(&w, state_(1, 2, 0, 0) & cell, true), 1);
    assert_int_equal(alias_note(&w, state_(1, 2, 3, 1) & cell, true), 2);  // other heading
    assert_int_equal(alias_note(&w, state_(1, 2, 1, 0) & cell, false), 2);
    assert_int_equal(alias_count(&w, state_(1, 2, 2, 1) & cell), 2);
    assert_int_equal(alias_count(&w, state_(2, 1, 0, 0) & cell), 0);
    assert_int_equal(w.checked, 4);
    assert_int_equal(w.aliased, 2);
    alias_clear(&w);
    assert_int_equal(alias_count(&w, state_(1, 2, 0, 0) & cell), 0);
    assert_int_equal(w.checked, 0);
}

static void a_full_table_replaces_the_smallest_count(void **state)
{
    (void)state;
    alias_watch_t w;
    alias_init(&w);
    for (uint32_t c = 0; c < FW_CFG_ALIAS_CELLS; c++) {
        for (uint32_t k = 0; k <= c; k++) {  // cell c aliases c + 1 times
            (void)alias_note(&w, c, true);
        }
    }
    // A new cell takes the entry of cell 0 (count 1) and inherits it: 2, an upper bound.
    assert_int_equal(alias_note(&w, 200, true), 2);
    assert_int_equal(alias_count(&w, 0), 0);
    assert_int_equal(alias_count(&w, FW_CFG_ALIAS_CELLS - 1u), FW_CFG_ALIAS_CELLS);
    alias_cell_t cells[FW_CFG_ALIAS_CELLS];
    assert_int_equal(alias_cells(&w, cells), FW_CFG_ALIAS_CELLS);
    assert_int_equal(cells[0].cell, FW_CFG_ALIAS_CELLS - 1u);  // most first
    for (uint32_t i = 1; i < FW_CFG_ALIAS_CELLS; i++) {
        assert_true(cells[i - 1].count > cells[i].count ||
                    (cells[i - 1].count == cells[i].count && cells[i - 1].cell < cells[i].cell));
    }
    for (uint32_t k = 0; k < 300; k++) {
        (void)alias_note(&w, 200, true);
    }
    assert_int_equal(alias_count(&w, 200), ALIAS_COUNT_MAX);  // saturates
}

// ---- The agent ---------------------------------------------------------------------------------

// A corridor of 16 cells: action 0 moves left, action 1 right.
static const agent_space_t corridor_ = {1, {4}, {0}, 0, 0, 2, 0, 0};
static agent_t agent_;

static void init_(agent_kind_t kind, uint8_t ablate)
{
    agent_config_t c;
    c.kind = kind;
    c.space = &corridor_;
    c.params = agent_default_params();
    c.params.alpha = 0.9f;
    c.params.gamma = 0.0f;  // the target is the reward: Q moves by alpha times the surprise
    c.params.ablate = ablate;
    c.storage = &agent_storage_maze;
    c.seed = 1;
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
}

typedef struct {
    uint32_t checked, steps, cells, facts;
} seen_t;

static int take_(void *data, const agent_fact_t *f)
{
    seen_t *s = data;
    if (f->kind == AGENT_FACT_ALIAS) {
        s->facts++;
    } else if (strcmp(f->u.counter.name, "alias_checked") == 0) {
        s->checked = f->u.counter.value;
    } else if (strcmp(f->u.counter.name, "alias_steps") == 0) {
        s->steps = f->u.counter.value;
    } else if (strcmp(f->u.counter.name, "alias_cells") == 0) {
        s->cells = f->u.counter.value;
    }
    return 0;
}

// The same pair leads to 2 then 3: the second step aliases. Every algorithm with a model of its
// experience counts it; Q-learning, which keeps none, lists no aliasing counters.
static void every_model_counts_a_pair_whose_outcomes_differ(void **state)
{
    (void)state;
    const agent_kind_t kinds[] = {AGENT_DYNA_Q, AGENT_DYNA_Q_MAJORITY, AGENT_DYNA_QPC};
    for (uint32_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++) {
        init_(kinds[i], 0);
        agent_observe(&agent_, 1, 1, 0.0f, 2, false);
        agent_observe(&agent_, 1, 1, 0.0f, 2, false);
        agent_observe(&agent_, 1, 1, 0.0f, 3, false);
        seen_t s = {0};
        assert_int_equal(agent_walk(&agent_, AGENT_FACT_COUNTER | AGENT_FACT_ALIAS, take_, &s), 0);
        assert_int_equal(s.checked, 2);
        assert_int_equal(s.steps, 1);
        assert_int_equal(s.cells, 1);
        assert_int_equal(s.facts, 1);
        assert_int_equal(agent_aliasing(&agent_, 1), 1);
        agent_reset(&agent_, 2);
        assert_int_equal(agent_aliasing(&agent_, 1), 0);
    }
    init_(AGENT_Q_LEARNING, 0);
    agent_observe(&agent_, 1, 1, 0.0f, 2, false);
    agent_observe(&agent_, 1, 1, 0.0f, 3, false);
    seen_t s = {0};
    assert_int_equal(agent_walk(&agent_, AGENT_FACT_COUNTER | AGENT_FACT_ALIAS, take_, &s), 0);
    assert_int_equal(s.checked + s.steps + s.cells + s.facts, 0);
    assert_int_equal(agent_aliasing(&agent_, 1), 0);
}

// A pair that usually earns 1 once earns -10 (a bump it usually misses): at alpha 0.9 that one
// outcome overwrites the value; in a cell that aliased, the step learns at alpha / (1 + k).
static void an_aliased_cell_learns_each_real_step_more_slowly(void **state)
{
    (void)state;
    float q[2];
    for (uint32_t ablate = 0; ablate < 2u; ablate++) {
        init_(AGENT_DYNA_Q_MAJORITY, ablate ? AGENT_ABLATE_ALIAS : 0u);
        for (int i = 0; i < 5; i++) {
            agent_observe(&agent_, 5, 1, 1.0f, 6, false);
        }
        assert_float_equal(agent_q(&agent_, 5, 1), 1.0f, 1e-4f);
        agent_observe(&agent_, 5, 1, -10.0f, 6, false);  // aliases: k = 1, alpha 0.45
        q[ablate] = agent_q(&agent_, 5, 1);
    }
    assert_float_equal(q[1], 1.0f + 0.9f * (-11.0f), 1e-4f);
    assert_float_equal(q[0], 1.0f + 0.45f * (-11.0f), 1e-4f);
    // The rate bottoms out at alpha / 8.
    init_(AGENT_DYNA_Q_MAJORITY, 0u);
    for (int i = 0; i < 20; i++) {
        agent_observe(&agent_, 5, 1, (i % 2) ? -10.0f : 1.0f, 6, false);
    }
    const float before = agent_q(&agent_, 5, 1);
    agent_observe(&agent_, 5, 1, 1.0f, 7, false);
    assert_float_equal(agent_q(&agent_, 5, 1), before + 0.9f / 8.0f * (1.0f - before), 1e-4f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(counts_per_cell_over_headings_and_codes),
        cmocka_unit_test(a_full_table_replaces_the_smallest_count),
        cmocka_unit_test(every_model_counts_a_pair_whose_outcomes_differ),
        cmocka_unit_test(an_aliased_cell_learns_each_real_step_more_slowly),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
