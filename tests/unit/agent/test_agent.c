// SPDX-License-Identifier: MIT
// Tests of the agent: the Q update arithmetic, action selection, and each algorithm's planning.
#include "test_common.h"

#include <math.h>
#include <string.h>

#include "agent/agent.h"
#include "robot/agent_profiles.h"
#include "fw/fw_base.h"

// A corridor of 16 cells: action 0 moves left, action 1 right; the goal is cell 15.
static const agent_space_t corridor_ = {1, {4}, {0}, 0, 0, 2, 0, 0};

static agent_t agent_;

static agent_config_t config(agent_kind_t kind)
{
    agent_config_t c;
    c.kind = kind;
    c.space = &corridor_;
    c.params = agent_default_params();
    c.storage = &agent_storage_maze;
    c.seed = 1;
    return c;
}

static void init_rejects_bad_configurations(void **state)
{
    (void)state;
    agent_config_t c = config(AGENT_DYNA_QPC);
    c.params.alpha = 0.0f;
    assert_int_equal(agent_init(&agent_, &c), FW_ERR_INVAL);
    c = config(AGENT_DYNA_QPC);
    c.params.epsilon = 1.5f;
    assert_int_equal(agent_init(&agent_, &c), FW_ERR_INVAL);
    c = config(AGENT_DYNA_QPC);
    c.params.tilings = 32;
    assert_int_equal(agent_init(&agent_, &c), FW_ERR_INVAL);
    c = config(AGENT_DYNA_QPC);
    c.storage = NULL;
    assert_int_equal(agent_init(&agent_, &c), FW_ERR_INVAL);
    c = config(AGENT_DYNA_QPC);
    c.params.ablate = 0x40;  // not a part the ablation knows
    assert_int_equal(agent_init(&agent_, &c), FW_ERR_INVAL);
    c = config((agent_kind_t)7);
    assert_int_equal(agent_init(&agent_, &c), FW_ERR_INVAL);
    c = config(AGENT_Q_LEARNING);
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
}

// Eq. (1): Q(s, a) += alpha (r + gamma max_a' Q(s', a') - Q(s, a)).
static void q_update_arithmetic(void **state)
{
    (void)state;
    agent_config_t c = config(AGENT_Q_LEARNING);
    c.params.alpha = 0.5f;
    c.params.gamma = 0.9f;
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    agent_observe(&agent_, 14, 1, 10.0f, 15, true);  // terminal: no bootstrap
    assert_float_equal(agent_q(&agent_, 14, 1), 5.0f, 1e-6f);
    agent_observe(&agent_, 14, 1, 10.0f, 15, true);
    assert_float_equal(agent_q(&agent_, 14, 1), 7.5f, 1e-6f);
    agent_observe(&agent_, 13, 1, -1.0f, 14, false);  // -1 + 0.9 * 7.5 = 5.75, half of it
    assert_float_equal(agent_q(&agent_, 13, 1), 2.875f, 1e-6f);
    agent_observe(&agent_, 13, 0, -1.0f, 12, false);  // Q(12) = 0: -0.5
    assert_float_equal(agent_q(&agent_, 13, 0), -0.5f, 1e-6f);
    assert_int_equal(agent_.stats.real_updates, 4);
    assert_int_equal(agent_updates(&agent_), 4);
    assert_false(agent_plan_step(&agent_));  // Q-learning never plans
}

static void greedy_breaks_ties_low_and_act_breaks_them_randomly(void **state)
{
    (void)state;
    agent_config_t c = config(AGENT_Q_LEARNING);
    c.params.epsilon = 0.0f;
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    assert_int_equal(agent_greedy(&agent_, 5), 0);
    uint32_t picks[2] = {0, 0};
    for (int i = 0; i < 1000; i++) {
        picks[agent_act(&agent_, 5)]++;
    }
    assert_in_range(picks[0], 400, 600);
    agent_observe(&agent_, 5, 1, 1.0f, 6, true);
    assert_int_equal(agent_greedy(&agent_, 5), 1);
    for (int i = 0; i < 100; i++) {
        assert_int_equal(agent_act(&agent_, 5), 1);
    }
}

static void epsilon_explores_at_its_rate(void **state)
{
    (void)state;
    agent_config_t c = config(AGENT_Q_LEARNING);
    c.params.epsilon = 0.2f;
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    agent_observe(&agent_, 5, 1, 1.0f, 6, true);
    uint32_t left = 0;
    for (int i = 0; i < 10000; i++) {
        left += agent_act(&agent_, 5) == 0;
    }
    assert_in_range(left, 900, 1100);  // half of the 20% random picks
}

// Walk the corridor once, left to right. Only the last step meets a reward; Dyna-QPC's planning
// must carry it back to cell 0 through CMAC-R's predecessors, with no further real step.
static void dyna_qpc_plans_back_through_predecessors(void **state)
{
    (void)state;
    agent_config_t c = config(AGENT_DYNA_QPC);
    c.params.gamma = 0.9f;
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    for (agent_state_t s = 0; s < 15; s++) {
        agent_observe(&agent_, s, 1, s == 14 ? 1.0f : 0.0f, s + 1, s == 14);
    }
    assert_float_equal(agent_q(&agent_, 0, 1), 0.0f, 0.0f);
    const uint32_t done = agent_plan(&agent_, 1000);
    assert_true(done < 1000);  // the queue ran dry
    assert_false(agent_plan_step(&agent_));
    for (agent_state_t s = 0; s < 15; s++) {
        assert_float_equal(agent_q(&agent_, s, 1), powf(0.9f, (float)(14 - s)), 1e-3f);
    }
    assert_true(agent_.stats.planning_updates >= 15);
    assert_int_equal(agent_.alg.dyna_qpc.pq.stats.dropped, 0);
}

// Dyna-Q replays observed transitions at random; enough of them converge the same corridor.
static void dyna_q_replays_observed_transitions(void **state)
{
    (void)state;
    agent_config_t c = config(AGENT_DYNA_Q);
    c.params.gamma = 0.9f;
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    assert_false(agent_plan_step(&agent_));  // nothing observed yet
    for (agent_state_t s = 0; s < 15; s++) {
        agent_observe(&agent_, s, 1, s == 14 ? 1.0f : 0.0f, s + 1, s == 14);
    }
    assert_int_equal(agent_plan(&agent_, 5000), 5000);
    assert_float_equal(agent_q(&agent_, 0, 1), powf(0.9f, 14.0f), 1e-3f);
    assert_float_equal(agent_q(&agent_, 0, 0), 0.0f, 0.0f);  // never tried, never replayed
    assert_int_equal(agent_.stats.planning_updates, 5000);
}

// Without a model nothing is trusted: a queued pair whose prediction is untrained is skipped.
static void dyna_qpc_skips_what_the_model_cannot_predict(void **state)
{
    (void)state;
    agent_config_t c = config(AGENT_DYNA_QPC);
    c.params.min_count = 2;  // one visit is not enough to plan on
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    agent_observe(&agent_, 3, 1, 1.0f, 4, true);
    assert_true(agent_plan_step(&agent_));
    assert_int_equal(agent_.stats.planning_skipped, 1);
    assert_int_equal(agent_.stats.planning_updates, 0);
}

static void same_seed_same_behaviour_and_reset_forgets(void **state)
{
    (void)state;
    uint8_t first[200];
    agent_config_t c = config(AGENT_DYNA_QPC);
    c.params.epsilon = 0.3f;
    for (int pass = 0; pass < 2; pass++) {
        assert_int_equal(agent_init(&agent_, &c), FW_OK);
        agent_state_t s = 0;
        for (int i = 0; i < 200; i++) {
            const uint8_t a = agent_act(&agent_, s);
            const agent_state_t next = a ? (s < 15 ? s + 1 : s) : (s > 0 ? s - 1 : s);
            agent_observe(&agent_, s, a, next == 15 ? 1.0f : 0.0f, next, next == 15);
            agent_plan(&agent_, 5);
            s = next == 15 ? 0 : next;
            if (pass == 0) {
                first[i] = a;
            } else {
                assert_int_equal(a, first[i]);
            }
        }
    }
    agent_reset(&agent_, 1);
    assert_int_equal(agent_updates(&agent_), 0);
    for (agent_state_t s = 0; s < 16; s++) {
        assert_float_equal(agent_q(&agent_, s, 1), 0.0f, 0.0f);
    }
    assert_false(agent_plan_step(&agent_));
}

// agent_plan(n) passes what one planning update found on to the next (the model's answers
// about the predecessors it confirmed): that must plan exactly as n calls of agent_plan_step(),
// which pass nothing on. Two agents with the same seed, one planning each way, on a small robot
// grid whose tables are too small for it (Q rows, CMAC cells and queue all overflow), must act
// alike at every step and end with the same bytes learned and the same counters.
// The Dyna-Q tables' 960 bytes hold 16 records each (DYNAQ_RECORDS_IN).
#define SMALL_(knob) SMALL_##knob
#define SMALL_Q_TYPE value16_t
#define SMALL_Q_STATES 64
#define SMALL_CMAC_CELLS 64
#define SMALL_PQ_CAPACITY 4
#define SMALL_ALGORITHM_BYTES 960
#define SMALL_PLACES 1
#define SMALL_CLASSES 1
#define SMALL_POSITIONS 1
#define SMALL_PAPER_FWD_CELLS 64
#define SMALL_PAPER_INV_CELLS 64
#define SMALL_TRIED_PAIRS 16
typedef AGENT_MEMORY_STRUCT(SMALL_) small_memory_t;
FW_STATIC_ASSERT(DYNAQ_RECORDS_IN(SMALL_ALGORITHM_BYTES, 0) == 16 &&
                     DYNAQ_RECORDS_IN(SMALL_ALGORITHM_BYTES, FW_CFG_MAX_ACTIONS) == 16,
                 small_tables_hold_16_records);
static small_memory_t memory_a_;
static small_memory_t memory_b_;
static const agent_storage_t storage_a_ = AGENT_STORAGE_OF(memory_a_);
static const agent_storage_t storage_b_ = AGENT_STORAGE_OF(memory_b_);
static agent_t agent_b_;
// x, y (3 bits, tiles 2 wide), heading (2 bits, circular); actions: forward, back, left, right.
static const agent_space_t grid_ = {3, {3, 3, 2}, {1, 1, 0}, 0x4, 0, 4, 0, 0};

static agent_state_t grid_step_(agent_state_t s, uint8_t a, float *reward)
{
    uint32_t c[3];
    space_unpack(&grid_, s, c);
    static const int dx[4] = {1, 0, -1, 0};
    static const int dy[4] = {0, 1, 0, -1};
    const int sign = a == 0 ? 1 : -1;
    if (a >= 2) {
        c[2] = (c[2] + (a == 2 ? 1u : 3u)) & 3u;
    } else {
        const int x = (int)c[0] + sign * dx[c[2]];
        const int y = (int)c[1] + sign * dy[c[2]];
        if (x >= 0 && x < 8 && y >= 0 && y < 8) {
            c[0] = (uint32_t)x;
            c[1] = (uint32_t)y;
        }
    }
    *reward = c[0] == 7 && c[1] == 7 ? 1.0f : -0.01f;
    return space_pack(&grid_, c);
}

static void plan_calls_plan_as_single_steps_would(void **state)
{
    (void)state;
    agent_config_t c = config(AGENT_DYNA_QPC);
    c.space = &grid_;
    c.params.alpha = 0.9f;
    c.params.gamma = 0.9f;
    c.params.plan_alpha = 0.999f;
    c.params.epsilon = 0.2f;
    c.storage = &storage_a_;
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    c.storage = &storage_b_;
    assert_int_equal(agent_init(&agent_b_, &c), FW_OK);
    agent_state_t s = 0;
    for (int i = 0; i < 3000; i++) {
        const uint8_t a = agent_act(&agent_, s);
        assert_int_equal(agent_act(&agent_b_, s), a);
        float r;
        const agent_state_t next = grid_step_(s, a, &r);
        const bool goal = r > 0.0f;
        agent_observe(&agent_, s, a, r, next, goal);
        agent_observe(&agent_b_, s, a, r, next, goal);
        const uint32_t done = agent_plan(&agent_, 5);
        uint32_t steps = 0;
        while (steps < 5 && agent_plan_step(&agent_b_)) {
            steps++;
        }
        assert_int_equal(done, steps);
        s = goal ? 0 : next;
    }
    agent_region_t ra[AGENT_MAX_REGIONS];
    agent_region_t rb[AGENT_MAX_REGIONS];
    const uint32_t n = agent_learned_regions(&agent_, ra);
    assert_int_equal(agent_learned_regions(&agent_b_, rb), n);
    for (uint32_t i = 0; i < n; i++) {
        assert_int_equal(ra[i].size, rb[i].size);
        assert_memory_equal(ra[i].data, rb[i].data, ra[i].size);
    }
    assert_memory_equal(&agent_.stats, &agent_b_.stats, sizeof agent_.stats);
    assert_memory_equal(&agent_.alg.dyna_qpc.pq.stats, &agent_b_.alg.dyna_qpc.pq.stats, sizeof agent_.alg.dyna_qpc.pq.stats);
    assert_int_equal(agent_.alg.dyna_qpc.model.untrusted, agent_b_.alg.dyna_qpc.model.untrusted);
    assert_int_equal(agent_.alg.dyna_qpc.model.rejected, agent_b_.alg.dyna_qpc.model.rejected);
    // The run did what it is meant to cover: full tables, and predecessors found and refused.
    assert_int_equal(agent_.alg.dyna_qpc.model.forward.stats.cells_used, 64);
    assert_true(agent_.alg.dyna_qpc.model.forward.stats.evicted > 0);
    assert_true(agent_.q.dropped > 0);
    assert_true(agent_.q.plan_refused > 0);  // planning found the Q store full, forgot nothing
    assert_true(agent_.alg.dyna_qpc.pq.stats.dropped > 0);
    assert_true(agent_.alg.dyna_qpc.model.rejected > 0);
    assert_true(agent_.stats.planning_updates > 2000);
}

// A robot's space: x (5 bits), heading (4 bits, circular), range code (2 bits, absolute);
// heading and code are the situation.
static const agent_space_t robot_ = {3, {5, 4, 2}, {0, 0, 0}, 0x2, 0x4, 4, 0x6, 0};

static agent_state_t robot_state_(uint32_t x, uint32_t h, uint32_t r)
{
    const uint32_t c[3] = {x, h, r};
    return space_pack(&robot_, c);
}

// An untried move into a place the map has seen with two codes has both as outcomes: planning
// backs up the mean of their values, not either one (and does not refuse the pair).
static void dyna_qpc_backs_up_the_mean_of_a_places_codes(void **state)
{
    (void)state;
    agent_config_t c = config(AGENT_DYNA_QPC);
    c.space = &robot_;
    c.storage = &agent_storage_paper_lab;
    c.params.alpha = 1.0f;
    c.params.gamma = 0.9f;
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    // Action 0 at heading 4 and code 0 moves +1 (3 times: trusted), and (10, 4) shows code 0.
    for (uint32_t x = 1; x <= 3; x++) {
        agent_observe(&agent_, robot_state_(x, 4, 0), 0, -1.0f, robot_state_(x + 1, 4, 0), false);
    }
    agent_observe(&agent_, robot_state_(10, 4, 0), 2, -1.0f, robot_state_(10, 5, 0), false);
    // (11, 4) shows codes 1 and 2; from each, action 1 ends the episode, worth 10 and 2.
    agent_observe(&agent_, robot_state_(11, 4, 1), 1, 10.0f, robot_state_(20, 0, 0), true);
    agent_observe(&agent_, robot_state_(11, 4, 2), 1, 2.0f, robot_state_(20, 0, 0), true);
    (void)agent_plan(&agent_, 10000);
    assert_false(agent_plan_step(&agent_));  // the queue ran dry

    const agent_state_t from = robot_state_(10, 4, 0);
    const float v1 = qstore_max(&agent_.q, robot_state_(11, 4, 1));
    const float v2 = qstore_max(&agent_.q, robot_state_(11, 4, 2));
    assert_true(v1 > v2 + 1.0f);  // the two outcomes are worth clearly different amounts
    const float mean = -1.0f + 0.9f * 0.5f * (v1 + v2);
    assert_float_equal(agent_q(&agent_, from, 0), mean, mean * 0x1p-9f);  // within a value16 step or two
    assert_true(agent_.alg.dyna_qpc.model.generalised > 0u);
}


// A step that may stay where it is (model.h: a stay) is backed up over both outcomes: moving on,
// and staying, each by its share. Action 0 at heading 4 and code 0 moved +1 three times and
// stayed three times: from (10, 4, 0) it reaches (11, 4, 0), worth 10, half the time (128 of
// 255), and stays in (10, 4, 0), worth 50, the other half.
static void dyna_qpc_backs_up_a_stay_by_its_share(void **state)
{
    (void)state;
    for (uint32_t ablate = 0; ablate <= 1u; ablate++) {
        agent_config_t c = config(AGENT_DYNA_QPC);
        c.space = &robot_;
        c.storage = &agent_storage_paper_lab;
        c.params.alpha = 1.0f;
        c.params.gamma = 0.9f;
        c.params.stays = 1u;
        c.params.step_reward = -1.0f;
        c.params.ablate = ablate ? AGENT_ABLATE_STAY : 0u;
        assert_int_equal(agent_init(&agent_, &c), FW_OK);
        for (uint32_t x = 1; x <= 3; x++) {
            agent_observe(&agent_, robot_state_(x, 4, 0), 0, -1.0f, robot_state_(x + 1, 4, 0), false);
            agent_observe(&agent_, robot_state_(x + 4, 4, 0), 0, -1.0f, robot_state_(x + 4, 4, 0), false);
        }
        const agent_state_t from = robot_state_(10, 4, 0), next = robot_state_(11, 4, 0);
        agent_observe(&agent_, from, 3, 50.0f, robot_state_(20, 0, 0), true);
        agent_observe(&agent_, next, 1, 10.0f, robot_state_(20, 0, 0), true);
        (void)agent_plan(&agent_, 10000);
        assert_false(agent_plan_step(&agent_));  // the queue ran dry
        assert_float_equal(qstore_max(&agent_.q, from), 50.0f, 1e-4f);
        assert_float_equal(qstore_max(&agent_.q, next), 10.0f, 1e-4f);
        const float p = ablate ? 0.0f : 128.0f / 255.0f;
        const float expected = -1.0f + 0.9f * ((1.0f - p) * 10.0f + p * 50.0f);
        assert_float_equal(agent_q(&agent_, from, 0), expected, 1e-3f);
    }
}

// A first visit to a state makes new predictions: its own untried pairs that the relocatable
// model now predicts, and untried pairs elsewhere now predicted to lead into it. The values
// they lead to may never change again, so nothing else would queue them: the real step that
// arrives there does (dyna_qpc.c, queue_new_state_). A state seen before queues nothing more.
static uint32_t pq_key_(agent_state_t s, uint8_t a)
{
    return s * robot_.n_actions + a;
}

static void a_first_visit_queues_what_it_makes_predictable(void **state)
{
    (void)state;
    agent_config_t c = config(AGENT_DYNA_QPC);
    c.space = &robot_;
    c.storage = &agent_storage_paper_lab;
    c.params.alpha = 1.0f;
    c.params.gamma = 0.9f;
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    // Action 0 at heading 4 and code 0 moves +1 (3 times: trusted); the map sees (10, 4) and
    // (12, 4) with code 0, turning there.
    for (uint32_t x = 1; x <= 3; x++) {
        agent_observe(&agent_, robot_state_(x, 4, 0), 0, -1.0f, robot_state_(x + 1, 4, 0), false);
    }
    agent_observe(&agent_, robot_state_(10, 4, 0), 2, -1.0f, robot_state_(10, 5, 0), false);
    agent_observe(&agent_, robot_state_(12, 4, 0), 2, -1.0f, robot_state_(12, 5, 0), false);
    (void)agent_plan(&agent_, 10000);
    assert_int_equal(agent_backlog(&agent_), 0);
    const pqueue_t *pq = &agent_.alg.dyna_qpc.pq;
    const agent_state_t here = robot_state_(11, 4, 0);
    const agent_state_t before = robot_state_(10, 4, 0);
    assert_false(model_has_seen(&agent_.alg.dyna_qpc.model, here));
    assert_true(agent_q(&agent_, before, 0) == 0.0f);  // (11, 4) unseen: not predictable yet

    // The first visit to (11, 4, 0), turning into it.
    agent_observe(&agent_, robot_state_(11, 3, 0), 2, -1.0f, here, false);
    assert_true(pq_priority_of(pq, pq_key_(robot_state_(11, 3, 0), 2)) > 0.0f);  // the real pair
    assert_true(pq_priority_of(pq, pq_key_(here, 0)) > 0.0f);    // its own: it leads to (12, 4)
    assert_true(pq_priority_of(pq, pq_key_(before, 0)) > 0.0f);  // (10, 4, 0) now leads here
    assert_int_equal(agent_backlog(&agent_), 3);
    (void)agent_plan(&agent_, 10000);
    assert_float_equal(agent_q(&agent_, before, 0), -1.0f, 1e-4f);  // here is worth 0: untried
    assert_float_equal(agent_q(&agent_, here, 0), -1.0f, 1e-4f);

    // Arriving again queues the real pair only if it still has something to learn, nothing else.
    agent_observe(&agent_, robot_state_(11, 3, 0), 2, -1.0f, here, false);
    assert_int_equal(agent_backlog(&agent_), 0);
}

// The registry (agent/algorithms.h): every kind has a name, every name its kind, and anything
// else is an error rather than some default algorithm.
static void kinds_and_names_round_trip(void **state)
{
    (void)state;
    assert_int_equal(AGENT_KINDS, 4);
    for (uint32_t k = 0; k < AGENT_KINDS; k++) {
        agent_kind_t back = (agent_kind_t)99;
        const char *name = agent_kind_name((agent_kind_t)k);
        assert_non_null(name);
        assert_int_equal(agent_kind_from_name(name, &back), FW_OK);
        assert_int_equal(back, k);
    }
    assert_string_equal(agent_kind_name(AGENT_DYNA_QPC), "dyna-qpc");
    assert_string_equal(agent_kind_name(AGENT_DYNA_Q_MAJORITY), "dyna-q-majority");
    assert_null(agent_kind_name((agent_kind_t)AGENT_KINDS));
    agent_kind_t kind = AGENT_DYNA_Q;
    assert_int_equal(agent_kind_from_name("dyna-qpcx", &kind), FW_ERR_INVAL);
    assert_int_equal(agent_kind_from_name("", &kind), FW_ERR_INVAL);
    assert_int_equal(agent_kind_from_name(NULL, &kind), FW_ERR_INVAL);
    assert_int_equal(kind, AGENT_DYNA_Q);  // untouched by a failed lookup
}

static const agent_counter_t *counter_(const agent_counter_t *c, uint32_t n, const char *name)
{
    for (uint32_t i = 0; i < n; i++) {
        if (strcmp(c[i].name, name) == 0) {
            return &c[i];
        }
    }
    return NULL;
}

// One accessor lists every algorithm's counters: the Q store's first, then its own.
static void counters_list_the_q_store_then_the_algorithm(void **state)
{
    (void)state;
    agent_counter_t c[AGENT_MAX_COUNTERS];
    agent_config_t cfg = config(AGENT_DYNA_QPC);
    assert_int_equal(agent_init(&agent_, &cfg), FW_OK);
    agent_observe(&agent_, 14, 1, 10.0f, 15, true);
    agent_observe(&agent_, 13, 1, -1.0f, 14, false);
    uint32_t n = agent_counters(&agent_, c);
    assert_string_equal(c[0].name, "q_rows");
    assert_int_equal(c[0].value, agent_.q.rows_used);
    assert_int_equal(c[0].capacity, agent_.q.capacity);
    assert_non_null(counter_(c, n, "cmac_fwd"));
    assert_non_null(counter_(c, n, "percept_places"));
    assert_non_null(counter_(c, n, "arrivals"));
    assert_int_equal(counter_(c, n, "queue")->value, agent_backlog(&agent_));
    assert_true(agent_backlog(&agent_) > 0u);
    assert_null(counter_(c, n, "table"));

    cfg = config(AGENT_DYNA_Q);
    assert_int_equal(agent_init(&agent_, &cfg), FW_OK);
    agent_observe(&agent_, 13, 1, -1.0f, 14, false);
    n = agent_counters(&agent_, c);
    assert_int_equal(counter_(c, n, "table")->value, 1);
    assert_null(counter_(c, n, "cmac_fwd"));
    assert_int_equal(agent_backlog(&agent_), 0);

    cfg = config(AGENT_Q_LEARNING);
    assert_int_equal(agent_init(&agent_, &cfg), FW_OK);
    assert_int_equal(agent_counters(&agent_, c), 3);
    assert_int_equal(agent_stats(&agent_)->real_steps, 0);
}


// ---- Dyna-Q with the majority rule (dyna_q_majority.c) ---------------------------------------

// The kept outcome of (s, a) in a majority agent's table.
static const dynaq_record_t *majority_record_(agent_state_t s)
{
    return dynaq_find(&agent_.alg.dyna_q_majority.table, s);
}

// A minority slip does not replace the outcome most observations agreed on (Dyna-Q would keep
// the slip); as many slips as agreements do, as in CMAC-Model.
static void dyna_q_majority_keeps_the_majority_outcome(void **state)
{
    (void)state;
    agent_config_t c = config(AGENT_DYNA_Q_MAJORITY);
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    for (int i = 0; i < 3; i++) {  // 3 agree: 5 -> 6
        agent_observe(&agent_, 5, 1, 0.0f, 6, false);
    }
    for (int i = 0; i < 2; i++) {  // 2 slip: still 6
        agent_observe(&agent_, 5, 1, -1.0f, 5, false);
        assert_int_equal(majority_record_(5)->next[1], 6);
        assert_true(majority_record_(5)->reward[1] == 0.0f);
    }
    agent_counter_t cnt[AGENT_MAX_COUNTERS];
    uint32_t n = agent_counters(&agent_, cnt);
    assert_int_equal(counter_(cnt, n, "table_kept")->value, 2);
    assert_int_equal(counter_(cnt, n, "table_replaced")->value, 0);
    // Planning replays the kept outcome only: Q(5, 1) learns the move (0 + gamma * Q(6) = 0),
    // never the slip's -1.
    assert_int_equal(agent_plan(&agent_, 200), 200);
    assert_float_equal(agent_q(&agent_, 5, 1), 0.0f, 0.0f);
    // The third slip: as many disagreed (3) as agreed (3): the slip is the outcome now.
    agent_observe(&agent_, 5, 1, -1.0f, 5, false);
    assert_int_equal(majority_record_(5)->next[1], 5);
    assert_true(majority_record_(5)->reward[1] == -1.0f);
    n = agent_counters(&agent_, cnt);
    assert_int_equal(counter_(cnt, n, "table_replaced")->value, 1);
    // A different end of episode, or a reward more than 0.5 away, is a disagreement too.
    for (int i = 0; i < 3; i++) {
        agent_observe(&agent_, 9, 1, 0.0f, 10, false);
    }
    agent_observe(&agent_, 9, 1, 0.0f, 10, true);
    agent_observe(&agent_, 9, 1, 0.9f, 10, false);
    assert_false(dynaq_bit(majority_record_(9)->terminal, 1));
    assert_true(majority_record_(9)->reward[1] == 0.0f);
    agent_observe(&agent_, 9, 1, 0.4f, 10, false);  // agrees: its reward is the latest
    assert_true(majority_record_(9)->reward[1] == 0.4f);

    // Dyna-Q keeps the last outcome.
    c = config(AGENT_DYNA_Q);
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    for (int i = 0; i < 3; i++) {
        agent_observe(&agent_, 5, 1, 0.0f, 6, false);
    }
    agent_observe(&agent_, 5, 1, -1.0f, 5, false);
    assert_int_equal(dynaq_find(&agent_.alg.dyna_q.table, 5)->next[1], 5);
}

// The rule is Dyna-QPC's: fed the same observations of one pair (three outcomes, at random), the
// majority table keeps what CMAC-Model predicts after every one.
static void dyna_q_majority_keeps_what_cmac_model_keeps(void **state)
{
    (void)state;
    agent_config_t c = config(AGENT_DYNA_Q_MAJORITY);
    c.storage = &storage_a_;
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    c = config(AGENT_DYNA_QPC);
    c.storage = &storage_b_;
    assert_int_equal(agent_init(&agent_b_, &c), FW_OK);
    prng_t rng;
    prng_seed(&rng, 7);
    uint32_t replaced = 0;
    agent_state_t last = 0;
    for (int i = 0; i < 300; i++) {
        const uint32_t pick = prng_below(&rng, 10);
        const agent_state_t next = pick < 5u ? 6u : pick < 8u ? 4u : 9u;
        const float r = pick < 5u ? -1.0f : pick < 8u ? -3.0f : 10.0f;
        const bool terminal = pick >= 8u;
        agent_observe(&agent_, 5, 1, r, next, terminal);
        agent_observe(&agent_b_, 5, 1, r, next, terminal);
        model_step_t kept;
        assert_true(model_predict(&agent_b_.alg.dyna_qpc.model, 5, 1, &kept));
        const dynaq_record_t *rec = majority_record_(5);
        assert_int_equal(rec->next[1], kept.next);
        assert_int_equal(dynaq_bit(rec->terminal, 1), kept.terminal);
        assert_float_equal(rec->reward[1], kept.reward, 0.05f);
        replaced += rec->next[1] != last;
        last = rec->next[1];
    }
    assert_true(replaced > 5u);  // the kept outcome changed hands, more than once
}

// Where no observation ever disagrees, Dyna-Q with the majority rule is Dyna-Q: with the same
// seed on a deterministic grid (tables too small, so states are forgotten too), both act alike
// at every step and learn the same Q values.
static void dyna_q_majority_replays_as_dyna_q(void **state)
{
    (void)state;
    agent_config_t c = config(AGENT_DYNA_Q_MAJORITY);
    c.space = &grid_;
    c.params.epsilon = 0.2f;
    c.params.gamma = 0.9f;
    c.storage = &storage_a_;
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    c.kind = AGENT_DYNA_Q;
    c.storage = &storage_b_;
    assert_int_equal(agent_init(&agent_b_, &c), FW_OK);
    agent_state_t s = 0;
    for (int i = 0; i < 3000; i++) {
        const uint8_t a = agent_act(&agent_, s);
        assert_int_equal(agent_act(&agent_b_, s), a);
        float r;
        const agent_state_t next = grid_step_(s, a, &r);
        const bool goal = r > 0.0f;
        agent_observe(&agent_, s, a, r, next, goal);
        agent_observe(&agent_b_, s, a, r, next, goal);
        assert_int_equal(agent_plan(&agent_, 5), agent_plan(&agent_b_, 5));
        s = goal ? 0 : next;
    }
    agent_region_t ra[AGENT_MAX_REGIONS];
    agent_region_t rb[AGENT_MAX_REGIONS];
    assert_int_equal(agent_learned_regions(&agent_, ra), 2u + DYNAQ_REGIONS + 1u);
    assert_int_equal(agent_learned_regions(&agent_b_, rb), 2u + DYNAQ_REGIONS);
    for (uint32_t i = 0; i < 2u + DYNAQ_REGIONS; i++) {  // Q store and table, byte for byte
        assert_int_equal(ra[i].size, rb[i].size);
        assert_memory_equal(ra[i].data, rb[i].data, ra[i].size);
    }
    assert_memory_equal(&agent_.stats, &agent_b_.stats, sizeof agent_.stats);
    assert_true(agent_.alg.dyna_q_majority.table.evicted > 0u);
    assert_int_equal(agent_.alg.dyna_q_majority.kept + agent_.alg.dyna_q_majority.replaced, 0);
    assert_true(agent_.stats.planning_updates > 1000u);
}


// What it learned, counts included, is saved and restored: an agent restored from the bytes
// keeps the same outcomes with the same margins (a slip that the original would keep out, the
// restored one keeps out too).
static void dyna_q_majority_restores_its_counts(void **state)
{
    (void)state;
    static uint8_t saved[AGENT_MAX_REGIONS][32768];
    agent_config_t c = config(AGENT_DYNA_Q_MAJORITY);
    c.storage = &storage_a_;
    assert_int_equal(agent_init(&agent_, &c), FW_OK);
    for (int i = 0; i < 2; i++) {
        agent_observe(&agent_, 5, 1, 0.0f, 6, false);
    }
    agent_observe(&agent_, 7, 0, -1.0f, 6, true);
    agent_region_t r[AGENT_MAX_REGIONS];
    const uint32_t n = agent_learned_regions(&agent_, r);
    const void *image[AGENT_MAX_REGIONS];
    for (uint32_t i = 0; i < n; i++) {
        assert_true(r[i].size <= sizeof saved[i]);
        memcpy(saved[i], r[i].data, r[i].size);
        image[i] = saved[i];
    }
    memset(&memory_b_, 0, sizeof memory_b_);  // nothing but the image to learn the counts from
    c.storage = &storage_b_;
    assert_int_equal(agent_init(&agent_b_, &c), FW_OK);
    agent_region_t rb[AGENT_MAX_REGIONS];
    assert_int_equal(agent_learned_regions(&agent_b_, rb), n);
    assert_int_equal(agent_learned_check(&agent_b_, image), FW_OK);
    for (uint32_t i = 0; i < n; i++) {
        assert_int_equal(rb[i].size, r[i].size);
        memcpy(rb[i].data, saved[i], r[i].size);
    }
    agent_learned_restored(&agent_b_);
    assert_int_equal(agent_b_.alg.dyna_q_majority.table.count, 2);
    agent_observe(&agent_b_, 5, 1, -1.0f, 5, false);  // a slip against a margin of 2: kept out
    assert_int_equal(dynaq_find(&agent_b_.alg.dyna_q_majority.table, 5)->next[1], 6);
    agent_observe(&agent_b_, 5, 1, -1.0f, 5, false);  // now as many disagreed: replaced
    assert_int_equal(dynaq_find(&agent_b_.alg.dyna_q_majority.table, 5)->next[1], 5);
}

static jmp_buf assert_jump_;
static void assert_caught_(const char *file, int line)
{
    (void)file;
    (void)line;
    longjmp(assert_jump_, 1);
}

// A state or action outside the space is a caller's programming error (the dense Q store
// would index past its end): FW_ASSERT stops it.
static bool asserts_(void (*call)(void))
{
    fw_assert_handler_t old = fw_assert_set_handler(assert_caught_);
    bool fired = false;
    if (setjmp(assert_jump_) == 0) {
        call();
    } else {
        fired = true;
    }
    (void)fw_assert_set_handler(old);
    return fired;
}
static void q_of_bad_action_(void) { (void)agent_q(&agent_, 3, 2); }
static void q_of_bad_state_(void) { (void)agent_q(&agent_, 16, 0); }
static void observe_bad_next_(void) { agent_observe(&agent_, 3, 1, 0.0f, 99, false); }
static void greedy_bad_state_(void) { (void)agent_greedy(&agent_, 1u << 20); }
static void q_of_good_pair_(void) { (void)agent_q(&agent_, 15, 1); }

static void preconditions_are_asserted(void **state)
{
    (void)state;
    agent_config_t cfg = config(AGENT_DYNA_QPC);
    assert_int_equal(agent_init(&agent_, &cfg), FW_OK);
    assert_true(asserts_(q_of_bad_action_));
    assert_true(asserts_(q_of_bad_state_));
    assert_true(asserts_(observe_bad_next_));
    assert_true(asserts_(greedy_bad_state_));
    assert_false(asserts_(q_of_good_pair_));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(init_rejects_bad_configurations),
        cmocka_unit_test(q_update_arithmetic),
        cmocka_unit_test(greedy_breaks_ties_low_and_act_breaks_them_randomly),
        cmocka_unit_test(epsilon_explores_at_its_rate),
        cmocka_unit_test(dyna_qpc_plans_back_through_predecessors),
        cmocka_unit_test(dyna_q_replays_observed_transitions),
        cmocka_unit_test(dyna_qpc_skips_what_the_model_cannot_predict),
        cmocka_unit_test(same_seed_same_behaviour_and_reset_forgets),
        cmocka_unit_test(plan_calls_plan_as_single_steps_would),
        cmocka_unit_test(dyna_qpc_backs_up_the_mean_of_a_places_codes),
        cmocka_unit_test(dyna_qpc_backs_up_a_stay_by_its_share),
        cmocka_unit_test(kinds_and_names_round_trip),
        cmocka_unit_test(counters_list_the_q_store_then_the_algorithm),
        cmocka_unit_test(preconditions_are_asserted),
        cmocka_unit_test(a_first_visit_queues_what_it_makes_predictable),
        cmocka_unit_test(dyna_q_majority_keeps_the_majority_outcome),
        cmocka_unit_test(dyna_q_majority_keeps_what_cmac_model_keeps),
        cmocka_unit_test(dyna_q_majority_replays_as_dyna_q),
        cmocka_unit_test(dyna_q_majority_restores_its_counts),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
