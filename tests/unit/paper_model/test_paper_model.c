// SPDX-License-Identifier: MIT
// Tests of the paper's model (paper_model.h: CMAC-Model and CMAC-R over wide tiles) and of
// Dyna-QPC planning through it (`model paper`).
#include "test_common.h"

#include <string.h>

#include "agent/agent.h"
#include "agent/paper_model.h"
#include "fw/fw_base.h"

#define CELLS 4096u
static uint32_t fk_[CELLS], ik_[CELLS];
static uint8_t fc_[CELLS], ic_[CELLS];
static int16_t fw_[CELLS * (FW_CFG_MAX_COMPONENTS + 2)], iw_[CELLS * (FW_CFG_MAX_COMPONENTS + 1)];
static const paper_model_storage_t st_ = {{fk_, fc_, fw_, CELLS}, {ik_, ic_, iw_, CELLS}};

// A floor: x and y (5 bits each), 4 actions. No heading, no sensor: the tests move along x.
static const agent_space_t floor_ = {2, {5, 5}, {0, 0}, 0, 0, 4, 0, 0};
// A robot: x (4 bits), heading (4 bits, circular), a range code (2 bits, predicted as a value).
static const agent_space_t robot_ = {3, {4, 4, 2}, {0, 0, 0}, 0x2, 0x4, 4, 0, 0};

static const uint8_t exact_[FW_CFG_MAX_COMPONENTS] = {0, 0, 0, 0};
static const uint8_t wide_[FW_CFG_MAX_COMPONENTS] = {1, 1, 0, 0};  // x and y 2 cells wide

static agent_state_t at_(uint32_t x, uint32_t y)
{
    const uint32_t c[2] = {x, y};
    return space_pack(&floor_, c);
}

static agent_state_t robot_at_(uint32_t x, uint32_t h, uint32_t r)
{
    const uint32_t c[3] = {x, h, r};
    return space_pack(&robot_, c);
}

// Action 0 moves one cell along x everywhere in the square 8..14 x 8..14 except at (11, 11),
// which is never tried.
static void train_the_square_(paper_model_t *m)
{
    for (uint32_t y = 8; y <= 14; y++) {
        for (uint32_t x = 8; x <= 14; x++) {
            if (x != 11u || y != 11u) {
                (void)paper_model_learn(m, at_(x, y), 0, -1.0f, at_(x + 1u, y), true);
            }
        }
    }
}

// The untried pair shares every tile with tried neighbours: CMAC-Model predicts it by
// generalisation. With exact tiles nothing of it was ever trained, and the trust gate refuses it.
static void generalises_to_an_untried_pair_by_overlapping_tiles(void **state)
{
    (void)state;
    paper_model_t m;
    model_step_t out;
    assert_int_equal(paper_model_init(&m, &floor_, wide_, 16, 0.999f, 1, &st_), FW_OK);
    train_the_square_(&m);
    assert_true(paper_model_predict(&m, at_(11, 11), 0, &out));
    assert_int_equal(out.next, at_(12, 11));
    assert_float_equal(out.reward, -1.0f, 0.5f);
    assert_false(paper_model_predict(&m, at_(11, 11), 1, &out));  // another action: untrained
    assert_false(paper_model_predict(&m, at_(20, 20), 0, &out));  // far away: untrained
    const uint32_t refused = m.untrusted;
    assert_true(refused >= 2u);

    assert_int_equal(paper_model_init(&m, &floor_, exact_, 16, 0.999f, 1, &st_), FW_OK);
    train_the_square_(&m);
    assert_false(paper_model_predict(&m, at_(11, 11), 0, &out));
    assert_true(paper_model_predict(&m, at_(10, 11), 0, &out));  // a tried pair is exact
    assert_int_equal(out.next, at_(11, 11));
}

// Wide tiles blend what neighbours did: beside a wall (a bump, the robot stays, -100) a free
// cell's prediction is a mix the rounding and the trust gate act on. Pinned so that the blend
// does not change unnoticed: one observation of the free move is enough to predict it exactly.
static void a_tried_pair_keeps_its_last_outcome(void **state)
{
    (void)state;
    paper_model_t m;
    model_step_t out;
    assert_int_equal(paper_model_init(&m, &floor_, wide_, 16, 0.999f, 1, &st_), FW_OK);
    (void)paper_model_learn(&m, at_(4, 4), 0, -100.0f, at_(4, 4), false);  // a bump
    assert_true(paper_model_predict(&m, at_(4, 4), 0, &out));
    assert_int_equal(out.next, at_(4, 4));
    assert_float_equal(out.reward, -100.0f, 0.5f);
    (void)paper_model_learn(&m, at_(4, 4), 0, -1.0f, at_(5, 4), false);  // the paper's rule: the last
    assert_true(paper_model_predict(&m, at_(4, 4), 0, &out));
    assert_int_equal(out.next, at_(5, 4));
    assert_float_equal(out.reward, -1.0f, 0.5f);
    assert_int_equal(out.terminal, 0);
    (void)paper_model_learn(&m, at_(5, 4), 0, 100.0f, at_(6, 4), true);
    assert_true(paper_model_predict(&m, at_(5, 4), 0, &out));
    assert_int_equal(out.terminal, 1);
    assert_float_equal(out.reward, 100.0f, 0.5f);
}

// Fig. 8's cyclic path: s0 -forward-> s1 -right-> s2 -left-> s1 -forward-> s3. CMAC-R, keyed on
// (state, the action taken next), names both pairs that led into s1: (s0, forward), the pair
// before the first forward from s1, and (s2, left), the pair before the second. A model keyed on
// the state alone would keep one of them.
static void cmac_r_names_the_predecessors_of_a_cyclic_path(void **state)
{
    (void)state;
    paper_model_t m;
    assert_int_equal(paper_model_init(&m, &robot_, exact_, 16, 0.999f, 1, &st_), FW_OK);
    // Heading 15 turning right is heading 0: CMAC-R learns the change back as -1, wrapped.
    const agent_state_t s0 = robot_at_(3, 15, 1), s1 = robot_at_(4, 15, 1), s2 = robot_at_(4, 0, 2);
    const agent_state_t s3 = robot_at_(5, 15, 0);
    (void)paper_model_learn(&m, s0, 0, -1.0f, s1, false);
    (void)paper_model_learn(&m, s1, 3, -1.0f, s2, false);
    (void)paper_model_learn(&m, s2, 2, -1.0f, s1, false);
    (void)paper_model_learn(&m, s1, 0, -1.0f, s3, false);
    (void)paper_model_learn(&m, s3, 1, -1.0f, s1, false);  // s3's successor names nothing yet

    model_pred_t p[PAPER_MAX_PREDECESSORS];
    const uint32_t n = paper_model_predecessors(&m, s1, p);
    assert_int_equal(n, 2);
    bool from_s0 = false, from_s2 = false;
    for (uint32_t i = 0; i < n; i++) {
        from_s0 |= p[i].state == s0 && p[i].action == 0u;
        from_s2 |= p[i].state == s2 && p[i].action == 2u;
        assert_float_equal(p[i].reward, -1.0f, 0.1f);
    }
    assert_true(from_s0 && from_s2);
    // Through the heading's wrap: s2 was reached from s1 by a right turn (heading 15 -> 0).
    assert_int_equal(paper_model_predecessors(&m, s2, p), 1);
    assert_int_equal(p[0].state, s1);
    assert_int_equal(p[0].action, 3);
    // A step that ends its episode is no predecessor of the next episode's first step, even when
    // that episode starts where it ended.
    (void)paper_model_learn(&m, s1, 1, 100.0f, s0, true);
    (void)paper_model_learn(&m, s0, 1, -1.0f, s0, false);  // a new episode, starting at s0
    const uint32_t n0 = paper_model_predecessors(&m, s0, p);
    assert_int_equal(n0, 0);
}

// A named predecessor is used only when CMAC-Model confirms that it leads back: one whose forward
// outcome changed since (the paper's rule keeps the last) is refused and counted.
static void unconfirmed_predecessors_are_refused(void **state)
{
    (void)state;
    paper_model_t m;
    model_pred_t p[PAPER_MAX_PREDECESSORS];
    assert_int_equal(paper_model_init(&m, &floor_, exact_, 16, 0.999f, 1, &st_), FW_OK);
    (void)paper_model_learn(&m, at_(1, 1), 0, -1.0f, at_(2, 1), false);
    (void)paper_model_learn(&m, at_(2, 1), 0, -1.0f, at_(3, 1), true);
    assert_int_equal(paper_model_predecessors(&m, at_(2, 1), p), 1);
    assert_int_equal(m.rejected, 0);
    (void)paper_model_learn(&m, at_(1, 1), 0, -100.0f, at_(1, 1), true);  // now a bump there
    assert_int_equal(paper_model_predecessors(&m, at_(2, 1), p), 0);
    assert_int_equal(m.rejected, 1);
}

// A full table: new tiles take the least-trained cell of their window (evicted), the table never
// holds more than its capacity, the newest pair is predicted, and a pair whose tile was taken is
// refused, never answered with another pair's outcome.
static void a_full_table_forgets_and_never_answers_wrongly(void **state)
{
    (void)state;
    static uint32_t k[16], rk[16];
    static uint8_t c[16], rc[16];
    static int16_t w[16 * (FW_CFG_MAX_COMPONENTS + 2)], rw[16 * (FW_CFG_MAX_COMPONENTS + 1)];
    const paper_model_storage_t small = {{k, c, w, 16}, {rk, rc, rw, 16}};
    paper_model_t m;
    assert_int_equal(paper_model_init(&m, &floor_, exact_, 16, 0.999f, 1, &small), FW_OK);
    for (uint32_t y = 0; y < 8; y++) {
        for (uint32_t x = 0; x < 8; x++) {  // 64 pairs, each its own cell, into 16 cells
            (void)paper_model_learn(&m, at_(x, y), 0, -(float)(x + 8u * y), at_(x, y + 1u), false);
        }
    }
    assert_int_equal(m.forward.stats.cells_used, 16);
    assert_true(m.forward.stats.evicted > 0u);
    model_step_t out;
    assert_true(paper_model_predict(&m, at_(7, 7), 0, &out));
    assert_int_equal(out.next, at_(7, 8));
    uint32_t known = 0;
    for (uint32_t y = 0; y < 8; y++) {
        for (uint32_t x = 0; x < 8; x++) {
            if (paper_model_predict(&m, at_(x, y), 0, &out)) {
                known++;
                assert_int_equal(out.next, at_(x, y + 1u));
                assert_float_equal(out.reward, -(float)(x + 8u * y), 0.5f);
            }
        }
    }
    assert_true(known >= 1u && known <= 16u);
}

static void init_rejects_bad_arguments(void **state)
{
    (void)state;
    paper_model_t m;
    const uint8_t too_wide[FW_CFG_MAX_COMPONENTS] = {5, 0, 0, 0};
    const uint8_t wider_than_x[FW_CFG_MAX_COMPONENTS] = {0, 0, 3, 0};  // the code has 2 bits
    const paper_model_storage_t none = {{NULL, NULL, NULL, 0}, {NULL, NULL, NULL, 0}};
    assert_int_equal(paper_model_init(&m, &floor_, too_wide, 16, 0.999f, 1, &st_), FW_ERR_INVAL);
    assert_int_equal(paper_model_init(&m, &robot_, wider_than_x, 16, 0.999f, 1, &st_), FW_ERR_INVAL);
    assert_int_equal(paper_model_init(&m, &floor_, exact_, 16, 0.999f, 1, &none), FW_ERR_INVAL);
    assert_int_equal(paper_model_init(&m, &floor_, exact_, 16, 0.999f, 0, &st_), FW_ERR_INVAL);
}

// ---- Dyna-QPC with the paper's model --------------------------------------------------------

#define Q_STATES 1024u
#define PQ_CAP 64u
static float q_[2][Q_STATES * FW_CFG_MAX_ACTIONS];
static uint32_t qk_[2][Q_STATES];
static pq_item_t heap_[2][PQ_CAP];
static uint32_t pk_[2][PQ_INDEX_SLOTS(PQ_CAP)], pp_[2][PQ_INDEX_SLOTS(PQ_CAP)];
static uint32_t afk_[2][CELLS], aik_[2][CELLS];
static uint8_t afc_[2][CELLS], aic_[2][CELLS];
static int16_t afw_[2][CELLS * (FW_CFG_MAX_COMPONENTS + 2)], aiw_[2][CELLS * (FW_CFG_MAX_COMPONENTS + 1)];

static agent_storage_t storage_(int i)
{
    agent_storage_t st;
    memset(&st, 0, sizeof st);
    st.q = q_[i];
    st.q_value_bytes = sizeof q_[i][0];
    st.q_keys = qk_[i];
    st.q_states = Q_STATES;
    st.dyna_qpc.pq_heap = heap_[i];
    st.dyna_qpc.pq_index_keys = pk_[i];
    st.dyna_qpc.pq_index_pos = pp_[i];
    st.dyna_qpc.pq_capacity = PQ_CAP;
    st.dyna_qpc.paper.forward = (model_cmac_storage_t){afk_[i], afc_[i], afw_[i], CELLS};
    st.dyna_qpc.paper.inverse = (model_cmac_storage_t){aik_[i], aic_[i], aiw_[i], CELLS};
    return st;
}

// A 10 x 10 floor, goal at (9, 9), action 0: +x, 1: -x, 2: +y, 3: -y; the edges bump.
static void floor_step_(agent_state_t s, uint8_t a, float *r, agent_state_t *next, bool *done)
{
    uint32_t c[2];
    space_unpack(&floor_, s, c);
    int32_t x = (int32_t)c[0] + (a == 0 ? 1 : a == 1 ? -1 : 0);
    int32_t y = (int32_t)c[1] + (a == 2 ? 1 : a == 3 ? -1 : 0);
    if (x < 0 || x > 9 || y < 0 || y > 9) {
        *r = -100.0f;
        *next = s;
        *done = false;
        return;
    }
    *next = at_((uint32_t)x, (uint32_t)y);
    *done = x == 9 && y == 9;
    *r = *done ? 100.0f : -1.0f;
}

static uint32_t run_episodes_(agent_t *ag, uint32_t episodes)
{
    uint32_t last = 0;
    for (uint32_t e = 0; e < episodes; e++) {
        agent_state_t s = at_(0, 0);
        uint32_t steps = 0;
        bool done = false;
        while (!done && steps < 400u) {
            const uint8_t a = agent_act(ag, s);
            float r;
            agent_state_t next;
            floor_step_(s, a, &r, &next, &done);
            agent_observe(ag, s, a, r, next, done);
            (void)agent_plan(ag, 5);
            s = next;
            steps++;
        }
        last = steps;
    }
    return last;
}

static agent_config_t paper_config_(const agent_storage_t *st, uint32_t seed)
{
    agent_config_t cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.kind = AGENT_DYNA_QPC;
    cfg.space = &floor_;
    cfg.params = agent_default_params();
    cfg.params.alpha = 0.9f;
    cfg.params.plan_alpha = 0.9f;
    cfg.params.gamma = 0.9f;
    cfg.params.theta = 1e-3f;
    cfg.params.model = AGENT_MODEL_PAPER;
    cfg.storage = st;
    cfg.seed = seed;
    return cfg;
}

// Same seed, same learning: two agents step for step, then the same Q values and counters.
static void planning_through_the_paper_model_is_deterministic(void **state)
{
    (void)state;
    static agent_t a, b;
    const agent_storage_t sa = storage_(0), sb = storage_(1);
    const agent_config_t ca = paper_config_(&sa, 42), cb = paper_config_(&sb, 42);
    assert_int_equal(agent_init(&a, &ca), FW_OK);
    assert_int_equal(agent_init(&b, &cb), FW_OK);
    const uint32_t la = run_episodes_(&a, 15), lb = run_episodes_(&b, 15);
    assert_int_equal(la, lb);
    assert_true(agent_stats(&a)->planning_updates > 0u);
    assert_memory_equal(agent_stats(&a), agent_stats(&b), sizeof(agent_stats_t));
    for (uint32_t y = 0; y < 10; y++) {
        for (uint32_t x = 0; x < 10; x++) {
            for (uint8_t act = 0; act < 4; act++) {
                assert_true(agent_q(&a, at_(x, y), act) == agent_q(&b, at_(x, y), act));
            }
        }
    }
    agent_counter_t c[AGENT_MAX_COUNTERS];
    const uint32_t n = agent_counters(&a, c);
    bool has_cmac_r = false;
    for (uint32_t i = 0; i < n; i++) {
        has_cmac_r |= strcmp(c[i].name, "cmac_r") == 0 && c[i].value > 0u && c[i].capacity == CELLS;
    }
    assert_true(has_cmac_r);
    // The greedy path from (0, 0) is learned: 18 moves.
    assert_true(la <= 30u);
}

// Planning sweeps backwards through CMAC-R: after one episode's real steps and no planning, the
// goal's value reaches the start only by planning.
static void planning_carries_the_goal_back_through_cmac_r(void **state)
{
    (void)state;
    static agent_t a;
    const agent_storage_t sa = storage_(0);
    agent_config_t ca = paper_config_(&sa, 7);
    ca.params.epsilon = 0.0f;
    ca.params.model_tile_shift[0] = ca.params.model_tile_shift[1] = 0;
    assert_int_equal(agent_init(&a, &ca), FW_OK);
    // Walk +x along y = 9 from (0, 9) to the goal, no planning.
    for (uint32_t x = 0; x < 9; x++) {
        const bool done = x == 8u;
        agent_observe(&a, at_(x, 9), 0, done ? 100.0f : -1.0f, at_(x + 1u, 9), done);
    }
    assert_true(agent_q(&a, at_(0, 9), 0) <= 0.0f);
    (void)agent_plan(&a, 200);
    assert_true(agent_q(&a, at_(0, 9), 0) > 0.0f);  // 100 * 0.9^8 - costs, through 8 predecessors
}

// The model is chosen by name; another name, or a number past the last, is refused.
static void models_are_chosen_by_name(void **state)
{
    (void)state;
    uint8_t m = 9;
    assert_int_equal(agent_model_from_name("paper", &m), FW_OK);
    assert_int_equal(m, AGENT_MODEL_PAPER);
    assert_int_equal(agent_model_from_name("relocatable", &m), FW_OK);
    assert_int_equal(m, AGENT_MODEL_RELOCATABLE);
    assert_int_equal(agent_model_from_name("cmac", &m), FW_ERR_INVAL);
    assert_int_equal(agent_model_from_name(NULL, &m), FW_ERR_INVAL);
    assert_string_equal(agent_model_name(AGENT_MODEL_PAPER), "paper");
    assert_null(agent_model_name(AGENT_MODELS));
    static agent_t a;
    const agent_storage_t sa = storage_(0);
    agent_config_t ca = paper_config_(&sa, 1);
    ca.params.model = AGENT_MODELS;
    assert_int_equal(agent_init(&a, &ca), FW_ERR_INVAL);
    ca.params.model = AGENT_MODEL_PAPER;
    ca.params.model_tile_shift[0] = PAPER_MAX_TILE_SHIFT + 1u;
    assert_int_equal(agent_init(&a, &ca), FW_ERR_INVAL);
}

// What the paper's model learned is saved and restored like any model's: its regions (both
// CMACs) copied into a second agent give the same predictions and predecessors.
static void the_learned_regions_restore(void **state)
{
    (void)state;
    static agent_t a, b;
    const agent_storage_t sa = storage_(0), sb = storage_(1);
    const agent_config_t ca = paper_config_(&sa, 3), cb = paper_config_(&sb, 4);
    assert_int_equal(agent_init(&a, &ca), FW_OK);
    assert_int_equal(agent_init(&b, &cb), FW_OK);
    (void)run_episodes_(&a, 3);
    agent_region_t ra[AGENT_MAX_REGIONS], rb[AGENT_MAX_REGIONS];
    const uint32_t n = agent_learned_regions(&a, ra);
    assert_int_equal(n, agent_learned_regions(&b, rb));
    assert_int_equal(n, 1u + PAPER_MODEL_REGIONS);  // a dense Q store (10 state bits), then the CMACs
    const void *image[AGENT_MAX_REGIONS];
    for (uint32_t i = 0; i < n; i++) {
        assert_int_equal(ra[i].size, rb[i].size);
        image[i] = ra[i].data;
    }
    assert_int_equal(agent_learned_check(&b, image), FW_OK);
    for (uint32_t i = 0; i < n; i++) {
        memcpy(rb[i].data, ra[i].data, ra[i].size);
    }
    agent_learned_restored(&b);
    assert_int_equal(b.alg.dyna_qpc.paper.forward.stats.cells_used, a.alg.dyna_qpc.paper.forward.stats.cells_used);
    model_pred_t pa[PAPER_MAX_PREDECESSORS], pb[PAPER_MAX_PREDECESSORS];
    for (uint32_t x = 0; x < 10; x++) {
        const uint32_t na = paper_model_predecessors(&a.alg.dyna_qpc.paper, at_(x, 0), pa);
        assert_int_equal(paper_model_predecessors(&b.alg.dyna_qpc.paper, at_(x, 0), pb), na);
        for (uint32_t i = 0; i < na; i++) {
            assert_int_equal(pa[i].state, pb[i].state);
            assert_int_equal(pa[i].action, pb[i].action);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(generalises_to_an_untried_pair_by_overlapping_tiles),
        cmocka_unit_test(a_tried_pair_keeps_its_last_outcome),
        cmocka_unit_test(cmac_r_names_the_predecessors_of_a_cyclic_path),
        cmocka_unit_test(unconfirmed_predecessors_are_refused),
        cmocka_unit_test(a_full_table_forgets_and_never_answers_wrongly),
        cmocka_unit_test(init_rejects_bad_arguments),
        cmocka_unit_test(planning_through_the_paper_model_is_deterministic),
        cmocka_unit_test(planning_carries_the_goal_back_through_cmac_r),
        cmocka_unit_test(models_are_chosen_by_name),
        cmocka_unit_test(the_learned_regions_restore),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
