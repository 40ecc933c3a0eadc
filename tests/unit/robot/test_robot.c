// SPDX-License-Identifier: MIT
// Tests of the robot application's logic: state encoding, action wheels, the episode controller.
#include "test_common.h"

#include <string.h>

#include <math.h>

#include "robot/agent_profiles.h"
#include "robot/controller.h"
#include "robot/robot_geometry.h"
#include "robot/robot_motion.h"

// The sonar robot on the paper's equal grid (32 x 32 cells of 0.25 m): the encoding, motion and
// controller mechanics these tests pin. The shipped paper-sim fits its cells to the room
// (`encode auto`): test_shipped_sim_fits_its_room.
static robot_config_t sim_equal_;
static const robot_config_t *sim_ = &sim_equal_;
static const robot_config_t *lab_ = &robot_config_paper_lab;

static void sim_equal_init_(void)
{
    sim_equal_ = robot_config_paper_sim;
    memset(sim_equal_.grid, 0, sizeof sim_equal_.grid);
}

static void unpack_(const robot_config_t *cfg, agent_state_t s, uint32_t comp[4])
{
    agent_space_t sp;
    robot_config_space(cfg, &sp);
    space_unpack(&sp, s, comp);
}

static void test_shipped_configs_are_valid(void **state)
{
    (void)state;
    assert_int_equal(robot_config_check(sim_), FW_OK);
    assert_int_equal(robot_config_check(lab_), FW_OK);
    robot_config_t bad = *lab_;
    bad.n_beacons = 2;  // no Cricket fix from two beacons
    assert_int_equal(robot_config_check(&bad), FW_ERR_INVAL);
    bad = *sim_;
    bad.rays_of_bit[0] = 1u << 20;  // a sensor the robot does not have
    assert_int_equal(robot_config_check(&bad), FW_ERR_INVAL);
    bad = *sim_;
    bad.goal_x = 9.0f;  // outside the arena
    assert_int_equal(robot_config_check(&bad), FW_ERR_INVAL);
    bad = *sim_;
    bad.bits_x = 12;  // 12 + 5 + 4 + 4 = 25 bits: more than a state holds
    assert_int_equal(robot_config_check(&bad), FW_ERR_INVAL);
    bad = *lab_;
    bad.step_past_m = 0.4f;  // an aligned step would skip the 40 cm cell it should end in
    assert_int_equal(robot_config_check(&bad), FW_ERR_INVAL);
    bad.aligned_actions = 0;  // fixed steps do not use it
    assert_int_equal(robot_config_check(&bad), FW_OK);
}

// ROBOT_VALUES_ROOM: gamma from the floor's size in cells, theta from the rewards' scale; the
// paper's mode keeps what the configuration says.
static void test_values_from_the_room(void **state)
{
    (void)state;
    robot_config_t c = *sim_;
    c.values = ROBOT_VALUES_PAPER;
    c.params.gamma = 0.9f;
    c.params.theta = 1e-3f;
    agent_params_t p = robot_config_agent_params(&c);
    assert_true(p.gamma == 0.9f && p.theta == 1e-3f);
    c.values = ROBOT_VALUES_ROOM;  // 32 + 32 cells along the sides: H = 0.625 x 64 = 40
    p = robot_config_agent_params(&c);
    assert_float_equal(p.gamma, 0.975f, 1e-7f);
    assert_float_equal(p.theta, 1e-3f, 1e-9f);
    // A walk of 64 cells passes n0 = ln(1 / 3.5) / ln(0.975) = 49.5 steps, where a path's value
    // crosses zero: unknown states start at half the value of wandering for ever, 0.5 x -1 / 0.025.
    assert_float_equal(p.q_prior, -20.0f, 1e-3f);
    assert_true(p.alpha == c.params.alpha && p.epsilon == c.params.epsilon);
    c.bits_x = 6;  // a floor twice as wide: a longer horizon
    c.arena_w *= 2.0f;
    assert_true(robot_config_agent_params(&c).gamma > p.gamma);
    c.reward_goal = 1.0f, c.reward_bump = -0.5f, c.reward_step = -0.01f;  // rewards 100 x smaller
    assert_float_equal(robot_config_agent_params(&c).theta, 1e-5f, 1e-11f);
    c.values = 7;
    assert_int_equal(robot_config_check(&c), FW_ERR_INVAL);
    // paper-lab's 8 + 8 cells give the paper's own 0.9 and 1e-3.
    c = *lab_;
    c.values = ROBOT_VALUES_ROOM;
    assert_true(robot_config_agent_params(&c).gamma == 0.9f);
    assert_true(robot_config_agent_params(&c).theta == 1e-3f);
    // Its walk of 16 cells ends before n0 = 22.8 steps: the paper's prior of 0 stays.
    assert_true(robot_config_agent_params(&c).q_prior == 0.0f);
    c.reward_step = 0.0f;  // steps that cost nothing: known values never fall below 0
    c.bits_x = c.bits_y = 5;
    assert_true(robot_config_agent_params(&c).q_prior == 0.0f);
    c.values = ROBOT_VALUES_PAPER;  // and the paper's mode keeps its prior
    c.reward_step = -1.0f;
    assert_true(robot_config_agent_params(&c).q_prior == 0.0f);
}

// paper-sim as shipped: 18 x 18 cells cut at its walls' faces, in the 5 bits an axis had.
static void test_shipped_sim_fits_its_room(void **state)
{
    (void)state;
    const robot_config_t *c = &robot_config_paper_sim;
    assert_int_equal(c->grid[0].cells, 18);
    assert_int_equal(c->grid[1].cells, 18);
    assert_int_equal(c->bits_x, 5);
    uint32_t comp[4];
    robot_pose_t p = {7.99f, 0.01f, 0.0f};  // the far corner: the last cell, never one beyond
    unpack_(c, robot_encode_state(c, &p, 0), comp);
    assert_int_equal(comp[0], 17);
    assert_int_equal(comp[1], 0);
    p = (robot_pose_t){4.3f, 4.0f, 0.0f};  // the goal's cell, between the edges at 4.0 and 4.6 m
    unpack_(c, robot_encode_state(c, &p, 0), comp);
    assert_int_equal(comp[0], 9);
    // gamma auto from 18 + 18 cells: H = 0.625 x 36 = 22.5, gamma = 1 - 1 / 22.5
    assert_float_equal(robot_config_agent_params(c).gamma, 1.0f - 1.0f / 22.5f, 1e-6f);
}

static void test_defaults_need_a_scenario(void **state)
{
    (void)state;
    robot_config_t c;
    memset(&c, 0xA5, sizeof c);
    robot_config_defaults(&c);
    assert_int_equal(c.period_us, 192000u);
    assert_int_equal(c.agent, AGENT_DYNA_QPC);
    assert_true(c.params.theta == 1e-3f);
    assert_true(c.reward_goal == 100.0f && c.reward_bump == -100.0f && c.reward_step == -1.0f);
    assert_true(c.arena_w == 0.0f && c.bits_x == 0u && c.n_beacons == 0u);
    // No arena, no goal, no state encoding: not a configuration the firmware runs.
    assert_int_equal(robot_config_check(&c), FW_ERR_INVAL);
    // The arena, goal and grid of paper-lab, its sensors and actions: then it is one.
    const robot_config_t *lab = &robot_config_paper_lab;
    c.arena_w = lab->arena_w, c.arena_h = lab->arena_h;
    c.goal_x = lab->goal_x, c.goal_y = lab->goal_y, c.goal_r = lab->goal_r;
    c.bits_x = lab->bits_x, c.bits_y = lab->bits_y, c.bits_heading = lab->bits_heading;
    c.step_m = lab->step_m, c.turn_rad = lab->turn_rad, c.track_m = lab->track_m;
    c.bits_code = lab->bits_code, c.n_ranges = lab->n_ranges;
    memcpy(c.rays_of_bit, lab->rays_of_bit, sizeof c.rays_of_bit);
    memcpy(c.code_threshold_m, lab->code_threshold_m, sizeof c.code_threshold_m);
    c.step_cap = lab->step_cap;
    assert_int_equal(robot_config_check(&c), FW_OK);
}

static void test_position_cells_and_clamping(void **state)
{
    (void)state;
    uint32_t c[4];
    robot_pose_t p = {0.01f, 7.99f, 0.0f};
    unpack_(sim_, robot_encode_state(sim_, &p, 0), c);
    assert_int_equal(c[0], 0);
    assert_int_equal(c[1], 31);
    p = (robot_pose_t){4.0f, 0.26f, 0.0f};  // 8 m in 32 cells of 0.25 m
    unpack_(sim_, robot_encode_state(sim_, &p, 0), c);
    assert_int_equal(c[0], 16);
    assert_int_equal(c[1], 1);
    p = (robot_pose_t){-3.0f, 100.0f, 0.0f};  // outside: the edge cells
    unpack_(sim_, robot_encode_state(sim_, &p, 0), c);
    assert_int_equal(c[0], 0);
    assert_int_equal(c[1], 31);
    p = (robot_pose_t){NAN, NAN, NAN};  // never out of range
    unpack_(sim_, robot_encode_state(sim_, &p, 0), c);
    assert_true(c[0] < 32 && c[1] < 32 && c[2] < 16);
}

// paper-lab's goal is the cells whose centres are in its circle: of its 8 x 8 grid (0.5375 x 0.4 m
// cells) cells (6, 6) and (7, 6), centres (3.49, 2.6) and (4.03, 2.6), 0.26 and 0.29 m from
// (3.75, 2.55) with r = 0.3: x from 3.225 m to the wall, y from 2.4 to 2.8 m.
static void test_goal_as_cells(void **state)
{
    (void)state;
    const robot_config_t *lab = &robot_config_paper_lab;
    assert_true(lab->goal_cells);
    robot_pose_t p = {3.30f, 2.45f, 0.0f};  // in cell (6, 6), 0.46 m from the circle's centre
    assert_true(robot_in_goal(lab, &p));
    p = (robot_pose_t){4.25f, 2.79f, 1.0f};  // the far corner of cell (7, 6)
    assert_true(robot_in_goal(lab, &p));
    p = (robot_pose_t){3.75f, 2.30f, 0.0f};  // in the circle, in cell (6, 5)
    assert_false(robot_in_goal(lab, &p));
    p = (robot_pose_t){3.20f, 2.55f, 0.0f};  // cell (5, 6)
    assert_false(robot_in_goal(lab, &p));
    robot_config_t circle = *lab;
    circle.goal_cells = 0;
    p = (robot_pose_t){3.75f, 2.30f, 0.0f};
    assert_true(robot_in_goal(&circle, &p));
    p = (robot_pose_t){3.30f, 2.45f, 0.0f};
    assert_false(robot_in_goal(&circle, &p));
    // A configuration whose goal cells are empty is refused: a 5 cm circle on a cell corner
    // holds no cell centre (the nearest are 0.34 m away).
    robot_config_t empty = *lab;
    empty.goal_x = 3.225f;
    empty.goal_y = 2.4f;
    empty.goal_r = 0.05f;
    assert_int_equal(robot_config_check(lab), FW_OK);
    assert_int_equal(robot_config_check(&empty), FW_ERR_INVAL);
    empty.goal_cells = 0;
    assert_int_equal(robot_config_check(&empty), FW_OK);
}

static void test_heading_sectors_wrap(void **state)
{
    (void)state;
    const float pi = 3.14159265f;
    const struct {
        float heading;
        uint32_t sector;
    } cases[] = {
        {0.0f, 0}, {0.19f, 0}, {-0.19f, 0}, {0.2f, 1}, {pi / 2.0f, 4}, {pi, 8},
        {-pi / 2.0f, 12}, {2.0f * pi - 0.01f, 0}, {4.0f * pi + pi / 2.0f, 4}, {-7.0f * pi, 8},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        uint32_t c[4];
        const robot_pose_t p = {1.0f, 1.0f, cases[i].heading};
        unpack_(sim_, robot_encode_state(sim_, &p, 0), c);
        assert_int_equal(c[2], cases[i].sector);
    }
}

// Aligned turns of 2^g heading sectors leave the low g heading bits at 0 once the robot has
// turned; fixed turns, or turns that are not a power of two of sectors, leave none.
static void test_turn_step_of_aligned_turns(void **state)
{
    (void)state;
    robot_config_t cfg = *sim_;  // 16 sectors
    cfg.aligned_actions = 1;
    cfg.turn_rad = FW_PI_F / 2.0f;
    assert_int_equal(robot_turn_step_bits(&cfg), 2);
    agent_space_t sp;
    robot_config_space(&cfg, &sp);
    assert_int_equal(sp.turn_step_bits, 2);
    cfg.turn_rad = FW_PI_F / 4.0f;
    assert_int_equal(robot_turn_step_bits(&cfg), 1);
    cfg.turn_rad = FW_PI_F / 8.0f;  // one sector: every heading is reached
    assert_int_equal(robot_turn_step_bits(&cfg), 0);
    cfg.turn_rad = FW_PI_F / 3.0f;  // 60 degrees: 2.67 sectors
    assert_int_equal(robot_turn_step_bits(&cfg), 0);
    cfg.turn_rad = FW_PI_F / 2.0f;
    cfg.aligned_actions = 0;  // fixed turns drift off the sectors' centres
    assert_int_equal(robot_turn_step_bits(&cfg), 0);
}

static void test_range_code_bits(void **state)
{
    (void)state;
    float r[16];
    for (int i = 0; i < 16; i++) {
        r[i] = 2.0f;
    }
    assert_int_equal(robot_range_code(sim_, r, 16), 0);
    r[0] = 0.3f;  // front
    assert_int_equal(robot_range_code(sim_, r, 16), 1);
    r[4] = 0.1f;  // left
    assert_int_equal(robot_range_code(sim_, r, 16), 3);
    r[0] = NAN;   // a broken reading claims nothing
    r[4] = -1.0f;
    assert_int_equal(robot_range_code(sim_, r, 16), 0);
    float ir[3] = {0.29f, 0.5f, 0.31f};
    assert_int_equal(robot_range_code(lab_, ir, 3), 1);
    ir[2] = 0.05f;
    assert_int_equal(robot_range_code(lab_, ir, 3), 5);
}

static void test_action_wheels_realise_the_step(void **state)
{
    (void)state;
    robot_config_t cfg = *sim_;
    cfg.aligned_actions = 0;
    const robot_pose_t pose = {1.1f, 2.2f, 0.3f};  // fixed actions do not depend on it
    const float t = cfg.action_periods * cfg.period_us * 1e-6f;
    robot_motion_t m = robot_action_motion(&cfg, ROBOT_FORWARD, &pose);
    assert_int_equal(m.periods, cfg.action_periods);
    assert_float_equal(m.v_left * t, cfg.step_m, 1e-5);
    assert_float_equal(m.v_right, m.v_left, 0);
    m = robot_action_motion(&cfg, ROBOT_BACKWARD, &pose);
    assert_float_equal(m.v_left * t, -cfg.step_m, 1e-5);
    m = robot_action_motion(&cfg, ROBOT_TURN_LEFT, &pose);
    assert_float_equal((m.v_right - m.v_left) / cfg.track_m * t, cfg.turn_rad, 1e-5);  // counter-clockwise
    m = robot_action_motion(&cfg, ROBOT_TURN_RIGHT, &pose);
    assert_float_equal((m.v_right - m.v_left) / cfg.track_m * t, -cfg.turn_rad, 1e-5);
}

// Turn made by a motion, in radians, counter-clockwise positive.
static float turn_of_(const robot_config_t *cfg, robot_motion_t m)
{
    return (m.v_right - m.v_left) / cfg->track_m * (float)m.periods * (float)cfg->period_us * 1e-6f;
}

static float travel_of_(const robot_config_t *cfg, robot_motion_t m)
{
    return m.v_left * (float)m.periods * (float)cfg->period_us * 1e-6f;
}

static void test_aligned_turns_end_on_the_grid_of_headings(void **state)
{
    (void)state;
    robot_config_t cfg = *lab_;
    cfg.aligned_actions = 1;
    cfg.turn_rad = 3.14159265f / 4.0f;  // a grid of 45 degree headings
    const float deg = 3.14159265f / 180.0f;
    robot_pose_t pose = {1.0f, 1.0f, 20.0f * deg};
    assert_float_equal(turn_of_(&cfg, robot_action_motion(&cfg, ROBOT_TURN_LEFT, &pose)), 25.0f * deg, 1e-4);
    assert_float_equal(turn_of_(&cfg, robot_action_motion(&cfg, ROBOT_TURN_RIGHT, &pose)), -20.0f * deg, 1e-4);
    pose.heading = 43.0f * deg;  // 2 degrees short of a grid heading: on to the next one
    assert_float_equal(turn_of_(&cfg, robot_action_motion(&cfg, ROBOT_TURN_LEFT, &pose)), 47.0f * deg, 1e-4);
    assert_float_equal(turn_of_(&cfg, robot_action_motion(&cfg, ROBOT_TURN_RIGHT, &pose)), -43.0f * deg, 1e-4);
    pose.heading = -1.0f * deg;  // wraps: 359 degrees
    assert_float_equal(turn_of_(&cfg, robot_action_motion(&cfg, ROBOT_TURN_LEFT, &pose)), 46.0f * deg, 1e-4);
    assert_float_equal(turn_of_(&cfg, robot_action_motion(&cfg, ROBOT_TURN_RIGHT, &pose)), -44.0f * deg, 1e-4);
}

static void test_aligned_steps_cross_into_the_next_cell(void **state)
{
    (void)state;
    robot_config_t cfg = *lab_;  // 4.3 m / 8 = 0.5375 m by 3.2 m / 8 = 0.4 m cells
    cfg.aligned_actions = 1;
    const float cw = 0.5375f, ch = 0.4f, margin = cfg.step_past_m;
    robot_pose_t pose = {2.0f * cw + 0.1f, 3.0f * ch + 0.2f, 0.0f};  // heading +x
    robot_motion_t m = robot_action_motion(&cfg, ROBOT_FORWARD, &pose);
    assert_float_equal(travel_of_(&cfg, m), cw - 0.1f + margin, 1e-4);
    assert_float_equal(m.v_right, m.v_left, 0);
    assert_true(m.periods >= cfg.action_periods);
    m = robot_action_motion(&cfg, ROBOT_BACKWARD, &pose);
    assert_float_equal(travel_of_(&cfg, m), -(0.1f + margin), 1e-4);
    pose.heading = 3.14159265f / 2.0f;  // +y: 0.2 m to the edge
    assert_float_equal(travel_of_(&cfg, robot_action_motion(&cfg, ROBOT_FORWARD, &pose)), 0.2f + margin, 1e-4);
    // Diagonal: whichever edge comes first, and the pose really ends in another cell.
    pose.heading = 3.14159265f / 4.0f;
    const float d = travel_of_(&cfg, robot_action_motion(&cfg, ROBOT_FORWARD, &pose));
    const robot_pose_t end = {pose.x + d * cosf(pose.heading), pose.y + d * sinf(pose.heading), pose.heading};
    assert_int_not_equal(robot_encode_state(&cfg, &pose, 0), robot_encode_state(&cfg, &end, 0));
}

// A grid fitted to the room (`encode auto`): cells of any width along each side. Positions fall
// in the cell between its edges, aligned steps end past the fitted edge, a thin cell (inside a
// partition) is stepped over, the goal is a fitted cell's centre, and bad edges are refused.
static void test_fitted_grid(void **state)
{
    (void)state;
    robot_config_t cfg = *lab_;  // 4.3 x 3.2 m, step_past_m 0.16
    cfg.goal_cells = 0;          // the lab's goal cells are the equal grid's (below: a fitted one)
    cfg.grid[0].cells = 4;       // x: 0, 1.0, 1.9, 2.0 (a 0.1 m partition), 4.3
    const float ex[5] = {0.0f, 1.0f, 1.9f, 2.0f, 4.3f};
    for (int k = 0; k < 5; k++) {
        cfg.grid[0].edge[k] = ex[k];
    }
    assert_int_equal(robot_config_check(&cfg), FW_OK);
    assert_int_equal(robot_grid_cells(&cfg, ROBOT_AXIS_X), 4);
    assert_int_equal(robot_grid_cells(&cfg, ROBOT_AXIS_Y), 8);  // y stays 2^3 equal cells
    assert_int_equal(robot_grid_cell(&cfg, ROBOT_AXIS_X, 0.5f), 0);
    assert_int_equal(robot_grid_cell(&cfg, ROBOT_AXIS_X, 1.0f), 1);
    assert_int_equal(robot_grid_cell(&cfg, ROBOT_AXIS_X, 1.95f), 2);
    assert_int_equal(robot_grid_cell(&cfg, ROBOT_AXIS_X, 9.0f), 3);
    assert_int_equal(robot_grid_cell(&cfg, ROBOT_AXIS_X, -1.0f), 0);
    assert_int_equal(robot_grid_cell(&cfg, ROBOT_AXIS_X, NAN), 0);
    float lo, side;
    robot_grid_span(&cfg, ROBOT_AXIS_X, 1, &lo, &side);
    assert_float_equal(lo, 1.0f, 1e-6);
    assert_float_equal(side, 0.9f, 1e-6);
    // The thin cell is not a place a step stops: the smallest side is the 0.4 m y cells.
    assert_float_equal(robot_grid_min_side(&cfg), 0.4f, 1e-6);
    cfg.aligned_actions = 1;
    // From x 1.5 heading +x: to the fitted edge at 1.9 and the margin past it, over the thin cell.
    robot_pose_t pose = {1.5f, 1.0f, 0.0f};
    const float d = travel_of_(&cfg, robot_action_motion(&cfg, ROBOT_FORWARD, &pose));
    assert_float_equal(d, 0.4f + cfg.step_past_m, 1e-4);
    const robot_pose_t end = {pose.x + d, pose.y, 0.0f};
    assert_int_equal(robot_grid_cell(&cfg, ROBOT_AXIS_X, end.x), 3);
    // The state packs the fitted cell.
    uint32_t comp[4];
    unpack_(&cfg, robot_encode_state(&cfg, &end, 0), comp);
    assert_int_equal(comp[0], 3);
    // Goal cells: a fitted cell's centre stands for the pose.
    cfg.goal_cells = 1;
    cfg.goal_x = 3.15f;
    cfg.goal_y = 1.0f;
    cfg.goal_r = 0.05f;  // only the centre of x cell 3 (3.15) with y cell 2 (1.0)
    assert_int_equal(robot_config_check(&cfg), FW_OK);
    const robot_pose_t in_cell = {2.1f, 0.81f, 0.0f};
    assert_true(robot_in_goal(&cfg, &in_cell));
    cfg.goal_x = 1.9f;  // no fitted cell's centre within 5 cm
    assert_int_equal(robot_config_check(&cfg), FW_ERR_INVAL);
    cfg.goal_x = 3.15f;
    // Refused: edges that fall, that do not end at the side, more cells than the bits hold.
    cfg.grid[0].edge[2] = 0.9f;
    assert_int_equal(robot_config_check(&cfg), FW_ERR_INVAL);
    cfg.grid[0].edge[2] = 1.9f;
    cfg.grid[0].edge[4] = 4.0f;
    assert_int_equal(robot_config_check(&cfg), FW_ERR_INVAL);
    cfg.grid[0].edge[4] = 4.3f;
    cfg.bits_x = 1;
    assert_int_equal(robot_config_check(&cfg), FW_ERR_INVAL);
}

// Centred actions (ROBOT_ACTIONS_CENTRED): a step stops at the centre of the cell it enters,
// over a thin cell to the centre of the one beyond; settling and the back-off go to the centre;
// a cell narrower than twice step_past_m keeps the stop step_past_m past the edge.
static void test_centred_steps_stop_at_the_centre_of_the_next_cell(void **state)
{
    (void)state;
    robot_config_t cfg = *lab_;  // 4.3 x 3.2 m, 0.4 m rows, step_past_m 0.16
    cfg.grid[0].cells = 4;       // x: 0, 1.0, 1.9, 2.0 (a 0.1 m partition), 4.3
    const float ex[5] = {0.0f, 1.0f, 1.9f, 2.0f, 4.3f};
    for (int k = 0; k < 5; k++) {
        cfg.grid[0].edge[k] = ex[k];
    }
    cfg.goal_cells = 0;
    cfg.aligned_actions = ROBOT_ACTIONS_CENTRED;
    assert_int_equal(robot_config_check(&cfg), FW_OK);
    // East from x 0.3: to the centre of cell 1 (1.45).
    robot_pose_t pose = {0.3f, 1.0f, 0.0f};
    assert_float_equal(travel_of_(&cfg, robot_action_motion(&cfg, ROBOT_FORWARD, &pose)), 1.15f, 1e-4);
    // East from x 1.5: over the partition's thin cell to the centre of cell 3 (3.15).
    pose.x = 1.5f;
    assert_float_equal(travel_of_(&cfg, robot_action_motion(&cfg, ROBOT_FORWARD, &pose)), 1.65f, 1e-4);
    // Backward (west) from x 3.15 facing east: over the thin cell to 1.45.
    pose.x = 3.15f;
    assert_float_equal(travel_of_(&cfg, robot_action_motion(&cfg, ROBOT_BACKWARD, &pose)), -1.7f, 1e-4);
    // North along the equal rows from y 1.0 (row 2, 0.8-1.2): to row 3's centre, 1.4.
    pose = (robot_pose_t){0.5f, 1.0f, 0.5f * 3.14159265f};
    assert_float_equal(travel_of_(&cfg, robot_action_motion(&cfg, ROBOT_FORWARD, &pose)), 0.4f, 1e-4);
    // Into the last row, at the arena's wall: its centre too (from 2.5 in row 6 to 3.0).
    pose = (robot_pose_t){3.15f, 2.5f, 0.5f * 3.14159265f};
    assert_float_equal(travel_of_(&cfg, robot_action_motion(&cfg, ROBOT_FORWARD, &pose)), 0.5f, 1e-4);
    // Settling goes to the centre: from x 0.3 in cell 0 (0-1.0) facing east, 0.2 east.
    pose = (robot_pose_t){0.3f, 1.0f, 0.0f};
    assert_float_equal(travel_of_(&cfg, robot_settle_motion(&cfg, ROBOT_SETTLE_ALONG, &pose)), 0.2f, 1e-4);
    pose.x = 0.5f;
    assert_int_equal(robot_settle_motion(&cfg, ROBOT_SETTLE_ALONG, &pose).periods, 0);
    // A step east that bumped 0.8 m into cell 1 (1.0-1.9) backs off to its centre, 1.45.
    pose.x = 1.8f;
    assert_float_equal(travel_of_(&cfg, robot_backoff_motion(&cfg, ROBOT_FORWARD, 0.0f, &pose)), -0.35f, 1e-4);
    pose.x = 1.3f;  // short of the centre: nothing to back off
    assert_int_equal(robot_backoff_motion(&cfg, ROBOT_FORWARD, 0.0f, &pose).periods, 0);
    // A cell narrower than twice step_past_m (0.25 m) keeps the stop step_past_m past the edge.
    const float narrow[4] = {0.0f, 1.0f, 1.25f, 4.3f};
    cfg.grid[0].cells = 3;
    for (int k = 0; k < 4; k++) {
        cfg.grid[0].edge[k] = narrow[k];
    }
    assert_int_equal(robot_config_check(&cfg), FW_OK);
    pose = (robot_pose_t){0.5f, 1.0f, 0.0f};
    assert_float_equal(travel_of_(&cfg, robot_action_motion(&cfg, ROBOT_FORWARD, &pose)), 0.5f + cfg.step_past_m,
                       1e-4);
    pose.x = 1.2f;  // settling there: to the nearer stop, step_past_m from the east edge
    assert_float_equal(travel_of_(&cfg, robot_settle_motion(&cfg, ROBOT_SETTLE_ALONG, &pose)),
                       1.25f - cfg.step_past_m - 1.2f, 1e-4);
    // Two thin cells in a row (a partition, 1.9-2.0, that another's face at 1.95 cuts in two):
    // both are stepped over, to the centres of the cells either side (1.45 and 3.15), not to
    // step_past_m past the second thin cell's edge, 0.06 m from the partition's face.
    const float tee[6] = {0.0f, 1.0f, 1.9f, 1.95f, 2.0f, 4.3f};
    cfg.grid[0].cells = 5;
    for (int k = 0; k < 6; k++) {
        cfg.grid[0].edge[k] = tee[k];
    }
    assert_int_equal(robot_config_check(&cfg), FW_OK);
    pose = (robot_pose_t){3.15f, 1.0f, 0.0f};
    assert_float_equal(travel_of_(&cfg, robot_action_motion(&cfg, ROBOT_BACKWARD, &pose)), -1.7f, 1e-4);
    pose.x = 1.45f;
    assert_float_equal(travel_of_(&cfg, robot_action_motion(&cfg, ROBOT_FORWARD, &pose)), 1.7f, 1e-4);
    // Not a kind of actions.
    cfg.aligned_actions = ROBOT_ACTIONS_CENTRED + 1;
    assert_int_equal(robot_config_check(&cfg), FW_ERR_INVAL);
}

static void test_backoff_returns_to_where_an_aligned_step_stops(void **state)
{
    (void)state;
    robot_config_t cfg = *lab_;  // 0.5375 x 0.4 m cells, a 0.18 m track
    const float cw = 0.5375f, margin = cfg.step_past_m;
    assert_true(robot_backs_off(&cfg));
    assert_false(robot_backs_off(sim_));  // a 0.40 m track in 0.25 m cells: no room to stand anywhere
    // Stopped by a bump 0.45 m into cell 2 while stepping east: back to margin past its west edge.
    robot_pose_t pose = {2.0f * cw + 0.45f, 1.0f, 0.0f};
    robot_motion_t m = robot_backoff_motion(&cfg, ROBOT_FORWARD, 0.0f, &pose);
    assert_true(m.periods >= 1u);
    assert_float_equal(m.v_right, m.v_left, 0);
    assert_float_equal(travel_of_(&cfg, m), -(0.45f - margin), 1e-4);
    // Not beyond the stop: nothing to do.
    pose.x = 2.0f * cw + 0.10f;
    assert_int_equal(robot_backoff_motion(&cfg, ROBOT_FORWARD, 0.0f, &pose).periods, 0);
    // Stepping west (a backward step facing east): forward again, east, to margin short of the
    // east edge.
    assert_float_equal(travel_of_(&cfg, robot_backoff_motion(&cfg, ROBOT_BACKWARD, 0.0f, &pose)),
                       cw - 0.10f - margin, 1e-4);
    assert_int_equal(robot_backoff_motion(&cfg, ROBOT_TURN_LEFT, 0.0f, &pose).periods, 0);
    // Fixed steps have no stop to go back to: half a step back, whatever the cell.
    cfg.aligned_actions = 0;
    assert_true(robot_backs_off(&cfg));
    pose.x = 2.0f * cw + 0.45f;
    assert_float_equal(travel_of_(&cfg, robot_backoff_motion(&cfg, ROBOT_FORWARD, 0.0f, &pose)), -0.5f * cfg.step_m,
                       1e-4);
    assert_float_equal(travel_of_(&cfg, robot_backoff_motion(&cfg, ROBOT_BACKWARD, 0.0f, &pose)), 0.5f * cfg.step_m,
                       1e-4);
    assert_int_equal(robot_backoff_motion(&cfg, ROBOT_TURN_RIGHT, 0.0f, &pose).periods, 0);
}

static void test_settling_ends_on_the_grid_of_aligned_stops(void **state)
{
    (void)state;
    robot_config_t cfg = *lab_;  // 0.5375 x 0.4 m cells, 90 degree turns
    const float cw = 0.5375f, ch = 0.4f, margin = cfg.step_past_m;
    const float deg = 3.14159265f / 180.0f;
    assert_true(robot_settles(&cfg));
    assert_false(robot_settles(sim_));  // it does not back off either
    // Put down 0.45 m into cell 2 along x and 0.10 m into row 1, facing 20 degrees.
    robot_pose_t pose = {2.0f * cw + 0.45f, ch + 0.10f, 20.0f * deg};
    // To the nearest grid heading, east.
    assert_float_equal(turn_of_(&cfg, robot_settle_motion(&cfg, ROBOT_SETTLE_FACE_GRID, &pose)), -20.0f * deg, 1e-4);
    pose.heading = 0.0f;
    // To the nearer stop along x: margin short of the east edge.
    robot_motion_t m = robot_settle_motion(&cfg, ROBOT_SETTLE_ALONG, &pose);
    assert_float_equal(m.v_right, m.v_left, 0);
    assert_float_equal(travel_of_(&cfg, m), (cw - margin) - 0.45f, 1e-4);
    pose.x = 3.0f * cw - margin;
    // A quarter turn left, north; then to margin past the south edge.
    assert_float_equal(turn_of_(&cfg, robot_settle_motion(&cfg, ROBOT_SETTLE_QUARTER_LEFT, &pose)), 90.0f * deg, 1e-4);
    pose.heading = 90.0f * deg;
    assert_float_equal(travel_of_(&cfg, robot_settle_motion(&cfg, ROBOT_SETTLE_ACROSS, &pose)), margin - 0.10f, 1e-4);
    pose.y = ch + margin;
    // On the grid: nothing more to do in any phase.
    for (uint8_t phase = ROBOT_SETTLE_FACE_GRID; phase < ROBOT_SETTLE_PHASES; phase++) {
        assert_int_equal(robot_settle_motion(&cfg, phase, &pose).periods, 0);
    }
    // Settled across already: no quarter turn.
    pose = (robot_pose_t){2.0f * cw + 0.45f, ch + margin, 0.0f};
    assert_int_equal(robot_settle_motion(&cfg, ROBOT_SETTLE_QUARTER_LEFT, &pose).periods, 0);
    assert_int_equal(robot_settle_motion(&cfg, ROBOT_SETTLE_PHASES, &pose).periods, 0);
    cfg.turn_rad = 3.14159265f / 4.0f;  // 45 degree headings: an aligned step may be diagonal
    assert_false(robot_settles(&cfg));
    // Fixed steps and 45 degree turns: only the heading settles, to the nearest multiple of the turn.
    cfg = *lab_;
    cfg.aligned_actions = 0;
    cfg.turn_rad = 45.0f * deg;
    assert_true(robot_settles(&cfg));
    pose = (robot_pose_t){2.0f * cw + 0.45f, ch + 0.10f, 60.0f * deg};
    assert_float_equal(turn_of_(&cfg, robot_settle_motion(&cfg, ROBOT_SETTLE_FACE_GRID, &pose)), -15.0f * deg, 1e-4);
    for (uint8_t phase = ROBOT_SETTLE_ALONG; phase < ROBOT_SETTLE_PHASES; phase++) {
        assert_int_equal(robot_settle_motion(&cfg, phase, &pose).periods, 0);
    }
    cfg.turn_rad = 50.0f * deg;  // no whole number of turns makes a circle: no heading to settle on
    assert_false(robot_settles(&cfg));
}

// ---- The controller, driving an ideal kinematic robot ------------------------------------------

typedef struct bench {
    robot_config_t cfg;
    robot_ctrl_t ctrl;
    robot_sense_t sense;
    uint64_t now;
} bench_t;

static bench_t bench_;

static void bench_init_(const robot_config_t *cfg, agent_kind_t kind)
{
    bench_.cfg = *cfg;
    bench_.cfg.agent = kind;
    // These tests are about episodes, rewards and safety, so the actions are the plain fixed
    // ones (one period, 45 degree turns); the aligned motions have their own tests above.
    bench_.cfg.aligned_actions = 0;
    bench_.cfg.action_periods = 1;
    bench_.cfg.turn_rad = 3.14159265f / 4.0f;
    static agent_space_t space;
    robot_config_space(&bench_.cfg, &space);
    agent_config_t ac = {kind, &space, bench_.cfg.params, &agent_storage_paper_sim, 7};
    assert_int_equal(agent_init(&agent_paper_sim, &ac), FW_OK);
    robot_ctrl_init(&bench_.ctrl, &bench_.cfg, &agent_paper_sim);
    bench_.now = 1000000;
    bench_.sense = (robot_sense_t){0};
    bench_.sense.bus_ok = true;
    bench_.sense.pose_ok = true;
    bench_.sense.n_ranges = bench_.cfg.n_ranges;
    for (int i = 0; i < 16; i++) {
        bench_.sense.range_m[i] = 2.0f;
    }
}

// One control period: the sensors report, the controller commands, the ideal robot moves.
static void bench_period_(void)
{
    robot_sense_t *in = &bench_.sense;
    in->now_us = bench_.now;
    in->pose_time_us = bench_.now;
    float vl, vr;
    robot_ctrl_period(&bench_.ctrl, in, &vl, &vr);
    const float dt = bench_.cfg.period_us * 1e-6f;
    const float v = 0.5f * (vl + vr);
    in->pose.heading += (vr - vl) / bench_.cfg.track_m * dt;
    in->pose.x += v * cosf(in->pose.heading) * dt;
    in->pose.y += v * sinf(in->pose.heading) * dt;
    in->bump = false;
    bench_.now += bench_.cfg.period_us;
}

static void test_episode_reaches_goal_with_reward_and_report(void **state)
{
    (void)state;
    bench_init_(sim_, AGENT_Q_LEARNING);
    bench_.sense.pose = (robot_pose_t){3.0f, 4.0f, 0.0f};  // 1 m west of the goal, facing it
    agent_paper_sim.params.epsilon = 0.0f;
    robot_ctrl_start_episode(&bench_.ctrl);
    uint32_t periods = 0;
    while (!bench_.ctrl.episode_done && periods < 1000) {
        bench_period_();
        periods++;
    }
    assert_true(bench_.ctrl.episode_done);
    const robot_episode_report_t *rep = &bench_.ctrl.last_episode;
    assert_int_equal(rep->episode, 1);
    assert_true(rep->reached_goal);
    assert_int_equal(rep->steps, agent_paper_sim.stats.real_steps);
    assert_true(rep->reward <= 100.0f - (float)(rep->steps - 1));  // -1 a step, +100 at the goal
    assert_float_equal(rep->reward, 100.0f - (float)(rep->steps - 1), 1e-3);
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_IDLE);
    assert_float_equal(bench_.ctrl.move.v_left, 0.0f, 0);  // stopped at the end
}

static void test_step_cap_ends_the_episode(void **state)
{
    (void)state;
    bench_init_(sim_, AGENT_Q_LEARNING);
    bench_.cfg.step_cap = 7;
    bench_.sense.pose = (robot_pose_t){0.5f, 0.5f, 0.0f};
    robot_ctrl_start_episode(&bench_.ctrl);
    for (int i = 0; i < 20 && !bench_.ctrl.episode_done; i++) {
        bench_.sense.pose = (robot_pose_t){0.5f, 0.5f, 0.0f};  // held far from the goal
        bench_period_();
    }
    assert_true(bench_.ctrl.episode_done);
    assert_int_equal(bench_.ctrl.last_episode.steps, 7);
    assert_false(bench_.ctrl.last_episode.reached_goal);
    assert_float_equal(bench_.ctrl.last_episode.reward, -7.0f, 1e-6);
}

// The state of `spot` with the bench's ranges, its Q values set to q[0..3].
static agent_state_t spot_with_values_(const robot_pose_t *spot, const float q[4])
{
    const agent_state_t s =
        robot_encode_state(&bench_.cfg, spot, robot_range_code(&bench_.cfg, bench_.sense.range_m, bench_.sense.n_ranges));
    const qstore_row_t row = qstore_row_for_update(&agent_paper_sim.q, s);
    for (uint8_t a = 0; a < 4u; a++) {
        qstore_set(&agent_paper_sim.q, row, a, q[a]);
    }
    return s;
}

// A replayed (frozen) table cannot unlearn a loop: a state met for the third time within the last
// FW_CFG_LOOP_WINDOW steps takes the best action taken least often there. Stepping back and forth
// between two spots, the greedy action (2) comes twice in the first, then the others, best first.
static void test_replay_leaves_a_loop(void **state)
{
    (void)state;
    bench_init_(sim_, AGENT_Q_LEARNING);
    bench_.cfg.step_cap = 16;
    const robot_pose_t spot = {0.5f, 0.5f, 0.0f};
    const robot_pose_t other = {2.5f, 0.5f, 0.0f};
    bench_.sense.pose = spot;
    bench_.ctrl.learning = false;
    robot_ctrl_start_episode(&bench_.ctrl);
    // The spot's state: its values make action 2 greedy, then 3, 0 and 1.
    const float q[4] = {-3.0f, -4.0f, -1.0f, -2.0f};
    const agent_state_t s = spot_with_values_(&spot, q);
    uint8_t taken[8];
    uint32_t n = 0;
    for (int i = 0; i < 100 && !bench_.ctrl.episode_done; i++) {
        bench_.sense.pose = i % 2 == 0 ? spot : other;
        bench_period_();
        if (bench_.ctrl.step_done && !bench_.ctrl.episode_done && bench_.ctrl.s == s && n < 8u) {
            taken[n++] = bench_.ctrl.a;
        }
    }
    assert_true(bench_.ctrl.episode_done);
    // Twice greedy; then each action not taken yet, best first; then the least taken, best first.
    const uint8_t want[8] = {2, 2, 3, 0, 1, 3, 0, 1};
    assert_int_equal(n, 8);
    assert_memory_equal(taken, want, 8);
    assert_true(bench_.ctrl.loop_escapes >= 6u);
    // A learning robot leaves it too (its ε-greedy action overruled), though it also unlearns it.
    agent_paper_sim.params.epsilon = 0.0f;
    bench_.ctrl.learning = true;
    bench_.ctrl.loop_escapes = 0;
    robot_ctrl_start_episode(&bench_.ctrl);
    uint32_t seen = 0;
    for (int i = 0; i < 100 && (i == 0 || !bench_.ctrl.episode_done); i++) {  // (done: the last one's)
        bench_.sense.pose = i % 2 == 0 ? spot : other;
        bench_period_();
        seen |= bench_.ctrl.step_done && bench_.ctrl.s == s ? 1u << bench_.ctrl.a : 0u;
    }
    assert_true(bench_.ctrl.episode_done);
    assert_int_equal(seen, 0xFu);
    assert_true(bench_.ctrl.loop_escapes > 0u);
}

// With fixed steps a step that stays in its cell is progress, not a return: held on one spot, a
// run of one state is one visit, and the greedy action is never overruled.
static void test_fixed_steps_through_a_cell_are_no_loop(void **state)
{
    (void)state;
    bench_init_(sim_, AGENT_Q_LEARNING);
    bench_.cfg.step_cap = 8;
    const robot_pose_t spot = {0.5f, 0.5f, 0.0f};
    bench_.sense.pose = spot;
    bench_.ctrl.learning = false;
    robot_ctrl_start_episode(&bench_.ctrl);
    const float q[4] = {-1.0f, -5.0f, -5.0f, -5.0f};  // action 0 greedy
    const agent_state_t s = spot_with_values_(&spot, q);
    uint32_t steps = 0;
    for (int i = 0; i < 100 && !bench_.ctrl.episode_done; i++) {
        bench_.sense.pose = spot;
        bench_period_();
        if (bench_.ctrl.step_done && !bench_.ctrl.episode_done) {
            assert_int_equal(bench_.ctrl.s, s);
            assert_int_equal(bench_.ctrl.a, 0);
            steps++;
        }
    }
    assert_true(bench_.ctrl.episode_done);
    assert_true(steps >= 6u);
    assert_int_equal(bench_.ctrl.loop_escapes, 0);
}

// A robot put at its start by hand (or by the simulator) has not turned its wheels, so a fix
// whose ranges were taken before the episode started is of where it stood before: the first
// state waits for a pose taken since.
static void test_first_state_waits_for_a_pose_taken_since_the_start(void **state)
{
    (void)state;
    bench_init_(sim_, AGENT_Q_LEARNING);
    const robot_pose_t before = {3.0f, 4.0f, 0.0f};  // where the last episode ended
    const robot_pose_t start = {0.5f, 0.5f, 0.0f};   // where the robot was put
    robot_ctrl_start_episode(&bench_.ctrl);
    float vl, vr;
    robot_sense_t *in = &bench_.sense;
    in->now_us = bench_.now;
    in->pose = before;
    in->pose_time_us = bench_.now - 200000u;  // taken before the start, and still usable
    robot_ctrl_period(&bench_.ctrl, in, &vl, &vr);
    assert_false(bench_.ctrl.step_done);
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_WAIT_FIX);
    bench_.now += bench_.cfg.period_us;
    in->now_us = bench_.now;
    in->pose = start;
    in->pose_time_us = bench_.now;
    robot_ctrl_period(&bench_.ctrl, in, &vl, &vr);
    assert_true(bench_.ctrl.step_done);
    const agent_state_t s =
        robot_encode_state(&bench_.cfg, &start, robot_range_code(&bench_.cfg, in->range_m, in->n_ranges));
    assert_int_equal(bench_.ctrl.last_step.state, s);
}

static void test_bump_costs_and_is_counted(void **state)
{
    (void)state;
    bench_init_(sim_, AGENT_Q_LEARNING);
    bench_.cfg.step_cap = 3;
    bench_.sense.pose = (robot_pose_t){0.5f, 0.5f, 0.0f};
    robot_ctrl_start_episode(&bench_.ctrl);
    bench_period_();               // first state, first action
    bench_.sense.bump = true;      // the action hits something
    bench_period_();
    assert_true(bench_.ctrl.step_done);
    assert_float_equal(bench_.ctrl.last_step.reward, -100.0f, 0);
    bench_period_();
    bench_period_();
    assert_true(bench_.ctrl.episode_done);
    assert_int_equal(bench_.ctrl.last_episode.bumps, 1);
    assert_float_equal(bench_.ctrl.last_episode.reward, -102.0f, 1e-6);
}

// A step that bumps backs off before its outcome is observed: the step is learned once, with the
// bump's reward, at the pose where the back-off ended.
static void test_bumped_step_backs_off_then_is_observed(void **state)
{
    (void)state;
    bench_init_(lab_, AGENT_Q_LEARNING);
    bench_.cfg.aligned_actions = 1;  // the lab robot's own motion
    bench_.cfg.action_periods = lab_->action_periods;
    bench_.cfg.turn_rad = lab_->turn_rad;
    agent_paper_sim.params.epsilon = 0.0f;
    const float cw = 0.5375f;
    const robot_pose_t blocked = {2.0f * cw + 0.45f, 1.0f, 0.0f};  // facing east, 0.45 m in
    // Put down on the grid of aligned stops in the same cell, so that there is nothing to settle.
    bench_.sense.pose = (robot_pose_t){2.0f * cw + bench_.cfg.step_past_m, 0.8f + bench_.cfg.step_past_m, 0.0f};
    const agent_state_t s0 = robot_encode_state(&bench_.cfg, &blocked, 0);
    qstore_set(&agent_paper_sim.q, qstore_row_for_update(&agent_paper_sim.q, s0), ROBOT_FORWARD, 10.0f);
    robot_ctrl_start_episode(&bench_.ctrl);
    bench_period_();  // the first state: forward
    assert_true(bench_.ctrl.step_done);
    assert_int_equal(bench_.ctrl.a, ROBOT_FORWARD);
    // The step hits something at once and goes nowhere.
    for (int i = 0; i < 20 && bench_.ctrl.mode == ROBOT_MODE_ACTING && !bench_.ctrl.move.backing_off; i++) {
        bench_.sense.bump = true;
        bench_period_();
        bench_.sense.pose = blocked;
    }
    for (int i = 0; i < 5 && !bench_.ctrl.move.backing_off; i++) {
        bench_.sense.pose = blocked;
        bench_period_();  // waiting for the fix; then the back-off's first period
    }
    assert_true(bench_.ctrl.move.backing_off);
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_ACTING);
    assert_true(bench_.ctrl.move.v_left < 0.0f);
    assert_int_equal(agent_paper_sim.stats.real_steps, 0);  // not observed yet
    for (int i = 0; i < 50 && !bench_.ctrl.step_done; i++) {
        bench_period_();
    }
    assert_true(bench_.ctrl.step_done);
    assert_int_equal(agent_paper_sim.stats.real_steps, 1);
    assert_float_equal(bench_.ctrl.last_step.reward, -100.0f, 0);
    assert_float_equal(bench_.sense.pose.x, 2.0f * cw + bench_.cfg.step_past_m, 2e-3);
    assert_false(bench_.ctrl.move.backing_off);
    assert_int_equal(bench_.ctrl.last_episode.bumps, 0);  // the episode goes on
    assert_int_equal(bench_.ctrl.bumps, 1);
}

// Runs the controller until a real step (or an episode's first state) is observed; returns how
// many motions started before it (settling's, when no step was pending). *at gets the pose it
// was observed at (the period's, before the next action moved the robot).
static uint32_t motions_until_observed_(robot_pose_t *at)
{
    uint32_t motions = 0;
    robot_mode_t last = bench_.ctrl.mode;
    for (uint32_t i = 0; i < 200u; i++) {
        *at = bench_.sense.pose;
        bench_period_();
        if (bench_.ctrl.step_done) {
            return motions;
        }
        motions += bench_.ctrl.mode == ROBOT_MODE_ACTING && last != ROBOT_MODE_ACTING;
        last = bench_.ctrl.mode;
    }
    fail_msg("nothing observed in 200 periods");
    return motions;
}

static void bench_init_lab_aligned_(void)
{
    bench_init_(lab_, AGENT_Q_LEARNING);
    bench_.cfg.aligned_actions = 1;  // the lab robot's own motion
    bench_.cfg.action_periods = lab_->action_periods;
    bench_.cfg.turn_rad = lab_->turn_rad;
}

// An episode's first state is observed where settling onto the grid ends, and settling is not a
// real step; every episode settles, and so does a robot whose step a safe stop cut short.
static void test_episode_starts_after_settling(void **state)
{
    (void)state;
    bench_init_lab_aligned_();
    const float cw = 0.5375f, ch = 0.4f, margin = bench_.cfg.step_past_m;
    const float deg = 3.14159265f / 180.0f;
    bench_.sense.pose = (robot_pose_t){2.0f * cw + 0.45f, ch + 0.10f, 20.0f * deg};
    robot_ctrl_start_episode(&bench_.ctrl);
    robot_pose_t at;
    assert_int_equal(motions_until_observed_(&at), 4);  // face east, along x, turn north, along y
    assert_int_equal(bench_.ctrl.last_step.step, 0);
    assert_int_equal(agent_paper_sim.stats.real_steps, 0);
    assert_float_equal(at.x, 3.0f * cw - margin, 2e-3);
    assert_float_equal(at.y, ch + margin, 2e-3);
    assert_float_equal(at.heading, 90.0f * deg, 1e-3);
    assert_int_equal(bench_.ctrl.last_step.state, robot_encode_state(&bench_.cfg, &at, 0));

    // A second episode, put down facing a grid heading with the offset along it off the grid:
    // one motion.
    robot_ctrl_stop(&bench_.ctrl);
    bench_.sense.pose = (robot_pose_t){2.0f * cw + 0.30f, ch + margin, 0.0f};
    robot_ctrl_start_episode(&bench_.ctrl);
    assert_int_equal(motions_until_observed_(&at), 1);
    assert_float_equal(at.x, 3.0f * cw - margin, 2e-3);
    assert_float_equal(at.heading, 0.0f, 1e-3);

    // Put down on the grid: the first state at once.
    robot_ctrl_stop(&bench_.ctrl);
    bench_.sense.pose = (robot_pose_t){2.0f * cw + margin, ch + margin, 0.0f};
    robot_ctrl_start_episode(&bench_.ctrl);
    assert_int_equal(motions_until_observed_(&at), 0);

    // The bus goes silent during the first step: the step is dropped, and the robot settles
    // again from where the stop left it before it observes a first state afresh.
    bench_period_();
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_ACTING);
    bench_.sense.bus_ok = false;
    bench_period_();
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_SAFE_STOP);
    bench_.sense.bus_ok = true;
    assert_true(motions_until_observed_(&at) >= 1u);
    assert_int_equal(bench_.ctrl.last_step.step, 0);
    assert_int_equal(agent_paper_sim.stats.real_steps, 0);
}

// The sonar robot (aligned actions, larger than its cells) does not settle.
static void test_a_robot_larger_than_its_cells_does_not_settle(void **state)
{
    (void)state;
    bench_init_(sim_, AGENT_Q_LEARNING);
    bench_.cfg.aligned_actions = 1;
    bench_.cfg.turn_rad = sim_->turn_rad;
    bench_.sense.pose = (robot_pose_t){1.1f, 2.2f, 0.3f};
    robot_ctrl_start_episode(&bench_.ctrl);
    bench_period_();
    assert_true(bench_.ctrl.step_done);
}

static void test_operator_safe_stop_holds_until_start(void **state)
{
    (void)state;
    bench_init_(sim_, AGENT_Q_LEARNING);
    bench_.sense.pose = (robot_pose_t){0.5f, 0.5f, 0.0f};
    robot_ctrl_start_episode(&bench_.ctrl);
    bench_period_();
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_ACTING);
    const uint32_t steps = agent_paper_sim.stats.real_steps;
    robot_ctrl_safe_stop(&bench_.ctrl);
    for (int i = 0; i < 5; i++) {  // bus and pose are fine: it stays stopped all the same
        bench_period_();
        assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_SAFE_STOP);
        assert_float_equal(bench_.ctrl.move.v_left, 0.0f, 0);
        assert_float_equal(bench_.ctrl.move.v_right, 0.0f, 0);
    }
    assert_int_equal(agent_paper_sim.stats.real_steps, steps);
    assert_int_equal(bench_.ctrl.safe_stops, 1);
    robot_ctrl_start_episode(&bench_.ctrl);
    bench_period_();
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_ACTING);
    robot_ctrl_safe_stop(&bench_.ctrl);
    robot_ctrl_stop(&bench_.ctrl);
    bench_period_();
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_IDLE);
}

static void test_safe_stop_on_bus_loss_and_resume(void **state)
{
    (void)state;
    bench_init_(sim_, AGENT_Q_LEARNING);
    bench_.sense.pose = (robot_pose_t){0.5f, 0.5f, 0.0f};
    robot_ctrl_start_episode(&bench_.ctrl);
    bench_period_();
    bench_period_();  // one real step
    assert_int_equal(bench_.ctrl.last_step.step, 1);
    const uint32_t steps = agent_paper_sim.stats.real_steps;
    bench_.sense.bus_ok = false;
    for (int i = 0; i < 5; i++) {
        bench_period_();
        assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_SAFE_STOP);
        assert_float_equal(bench_.ctrl.move.v_left, 0.0f, 0);
        assert_float_equal(bench_.ctrl.move.v_right, 0.0f, 0);
    }
    assert_int_equal(agent_paper_sim.stats.real_steps, steps);  // nothing learned while stopped
    assert_int_equal(bench_.ctrl.safe_stops, 1);
    bench_.sense.bus_ok = true;
    bench_period_();  // back: a fresh first state, no update from the interrupted step
    assert_int_equal(agent_paper_sim.stats.real_steps, steps);
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_ACTING);
    // Reported as a start state (TLM_LEARN Step 0, reward 0); the episode's count goes on.
    assert_true(bench_.ctrl.step_done);
    assert_int_equal(bench_.ctrl.last_step.step, 0);
    assert_float_equal(bench_.ctrl.last_step.reward, 0.0f, 0);
    assert_int_equal(bench_.ctrl.step, 1);
    bench_period_();
    assert_int_equal(agent_paper_sim.stats.real_steps, steps + 1);
    assert_int_equal(bench_.ctrl.last_step.step, 2);
}

static void test_waits_for_a_fix_taken_after_stopping(void **state)
{
    (void)state;
    bench_init_(lab_, AGENT_Q_LEARNING);
    bench_.sense.pose = (robot_pose_t){1.0f, 1.0f, 0.0f};
    robot_ctrl_start_episode(&bench_.ctrl);
    bench_period_();  // first state from a fresh fix
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_ACTING);
    for (int i = 0; i < bench_.cfg.action_periods; i++) {
        bench_period_();
    }
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_WAIT_FIX);
    assert_float_equal(bench_.ctrl.move.v_left, 0.0f, 0);
    // A fix measured before the wheels stopped is not the outcome of the action.
    const uint64_t stopped = bench_.ctrl.move.stopped_at_us;
    robot_sense_t in = bench_.sense;
    in.now_us = stopped + 300000;
    in.pose_time_us = stopped - 1;
    float vl, vr;
    robot_ctrl_period(&bench_.ctrl, &in, &vl, &vr);
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_WAIT_FIX);
    assert_int_equal(agent_paper_sim.stats.real_steps, 0);
    in.now_us += 192000;
    in.pose_time_us = stopped + 200000;
    robot_ctrl_period(&bench_.ctrl, &in, &vl, &vr);
    assert_int_equal(agent_paper_sim.stats.real_steps, 1);
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_ACTING);
}

// A fault while the robot stood waiting for the fix of a finished action: once it passes, that
// fix is still the action's outcome and is learned from (resume_mode).
static void test_safe_stop_while_waiting_for_a_fix_keeps_the_step(void **state)
{
    (void)state;
    bench_init_(lab_, AGENT_Q_LEARNING);
    bench_.sense.pose = (robot_pose_t){1.0f, 1.0f, 0.0f};
    robot_ctrl_start_episode(&bench_.ctrl);
    bench_period_();
    for (int i = 0; i < bench_.cfg.action_periods; i++) {
        bench_period_();
    }
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_WAIT_FIX);
    const uint64_t stopped = bench_.ctrl.move.stopped_at_us;
    robot_sense_t in = bench_.sense;
    in.now_us = stopped + 100000;
    in.pose_time_us = stopped - 1;
    in.bus_ok = false;
    float vl, vr;
    robot_ctrl_period(&bench_.ctrl, &in, &vl, &vr);
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_SAFE_STOP);
    assert_int_equal(bench_.ctrl.resume_mode, ROBOT_MODE_WAIT_FIX);
    in.bus_ok = true;
    in.now_us += 192000;
    robot_ctrl_period(&bench_.ctrl, &in, &vl, &vr);  // back, no fresh fix yet
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_WAIT_FIX);
    assert_int_equal(agent_paper_sim.stats.real_steps, 0);
    in.now_us += 192000;
    in.pose_time_us = stopped + 300000;
    robot_ctrl_period(&bench_.ctrl, &in, &vl, &vr);
    assert_int_equal(agent_paper_sim.stats.real_steps, 1);  // the step is learned
}

static void test_fixed_planning_runs_after_each_step(void **state)
{
    (void)state;
    bench_init_(sim_, AGENT_DYNA_QPC);
    bench_.cfg.planning = 5;  // the paper's N (the shipped scenarios plan in idle time)
    bench_.sense.pose = (robot_pose_t){1.0f, 1.0f, 0.0f};
    robot_ctrl_start_episode(&bench_.ctrl);
    for (int i = 0; i < 30; i++) {
        bench_period_();
    }
    const agent_stats_t *st = &agent_paper_sim.stats;
    assert_true(st->real_steps >= 29);
    // Every step asks for up to N = 5 updates, stopping early when the queue is empty.
    assert_true(st->planning_updates > 0);
    assert_true(st->planning_updates + st->planning_skipped <= 5u * st->real_steps);
    const uint32_t before = st->planning_updates;
    assert_false(robot_ctrl_plan(&bench_.ctrl));  // fixed N: no idle planning
    robot_ctrl_stop(&bench_.ctrl);
    assert_false(robot_ctrl_plan(&bench_.ctrl));  // not between episodes either: N is the paper's
    assert_int_equal(st->planning_updates, before);
}

static void test_idle_planning_when_planning_is_zero(void **state)
{
    (void)state;
    bench_init_(sim_, AGENT_DYNA_QPC);
    bench_.cfg.planning = 0;
    bench_.sense.pose = (robot_pose_t){1.0f, 1.0f, 0.0f};
    robot_ctrl_start_episode(&bench_.ctrl);
    for (int i = 0; i < 30; i++) {
        bench_period_();
    }
    const agent_stats_t *st = &agent_paper_sim.stats;
    assert_true(st->real_steps >= 29);
    // Each step plans a first ROBOT_PLAN_BEFORE_ACT updates before its next action is chosen...
    assert_true(st->planning_updates > 0);
    assert_true(st->planning_updates + st->planning_skipped <= ROBOT_PLAN_BEFORE_ACT * st->real_steps);
    const uint32_t before = st->planning_updates + st->planning_skipped;
    // ...and the idle hook plans on until the queue runs dry.
    uint32_t n = 0;
    while (robot_ctrl_plan(&bench_.ctrl) && n < 100000) {
        n++;
    }
    assert_true(n < 100000);
    assert_int_equal(st->planning_updates + st->planning_skipped, before + n);
}

// With idle planning the first updates come before the next action: after one real step the
// control period has planned on it (with none, the queue would still hold the step's pair).
static void test_idle_planning_plans_before_the_next_action(void **state)
{
    (void)state;
    bench_init_(sim_, AGENT_DYNA_QPC);
    bench_.cfg.planning = 0;
    bench_.sense.pose = (robot_pose_t){1.0f, 1.0f, 0.0f};
    robot_ctrl_start_episode(&bench_.ctrl);
    const agent_stats_t *st = &agent_paper_sim.stats;
    for (int i = 0; i < 30 && st->real_steps < 1u; i++) {
        bench_period_();
    }
    assert_int_equal(st->real_steps, 1);
    assert_true(st->planning_updates >= 1u);
    assert_true(st->planning_updates + st->planning_skipped <= ROBOT_PLAN_BEFORE_ACT);
}

// A kinematic robot whose wheels run at `gl` and `gr` times their commands, driven by the
// closed loop for one motion: its planned periods, then corrections while it stands. Returns the
// periods the motion took.
typedef struct wheeled_ {
    float x, y, heading, odom, gl, gr;
} wheeled_t;

static void wheeled_period_(const robot_config_t *cfg, wheeled_t *w, float vl, float vr)
{
    const float dt = cfg->period_us * 1e-6f;
    const float l = w->gl * vl, r = w->gr * vr;
    w->heading += (r - l) / cfg->track_m * dt;
    w->x += 0.5f * (l + r) * cosf(w->heading) * dt;
    w->y += 0.5f * (l + r) * sinf(w->heading) * dt;
    w->odom += 0.5f * (l + r) * dt;
}

static int run_motion_(const robot_config_t *cfg, robot_run_t *run, wheeled_t *w, const robot_motion_t *m)
{
    float vl, vr;
    int periods = 0;
    robot_run_start(run, cfg, m, w->heading, w->heading, w->odom, true, &vl, &vr);
    for (;;) {
        wheeled_period_(cfg, w, vl, vr);
        periods++;
        if (robot_run_period(run, cfg, w->heading, w->odom, &vl, &vr)) {
            continue;
        }
        if (!robot_run_correction(run, cfg, w->heading, w->odom, true, &vl, &vr)) {
            return periods;
        }
    }
}

static float wrap_deg_(float rad)
{
    float d = fmodf(rad * 57.29578f, 360.0f);
    return d > 180.0f ? d - 360.0f : d < -180.0f ? d + 360.0f : d;
}

// The lab robot closes its motions on its gyro and odometer: with wheels 8 % slow and 6 % fast,
// turns end on the grid, steps go straight once the trim has learnt the mismatch, each motion
// bounded in time; an exact robot's motion needs no correction.
static void test_closed_loop_motion_on_mismatched_wheels(void **state)
{
    (void)state;
    robot_config_t cfg = *lab_;
    assert_true(robot_closes_loop(&cfg));
    assert_false(robot_closes_loop(sim_));  // its heading is the GPS's
    const float deg = 3.14159265f / 180.0f;
    robot_run_t run;
    robot_run_init(&run);
    wheeled_t w = {1.0f, 1.0f, 0.0f, 0.0f, 0.92f, 1.06f};
    for (int i = 0; i < 12; i++) {
        const robot_pose_t pose = {w.x, w.y, w.heading};
        const robot_motion_t turn = robot_action_motion(&cfg, ROBOT_TURN_LEFT, &pose);
        const int periods = run_motion_(&cfg, &run, &w, &turn);
        assert_true(periods <= turn.periods + (int)ROBOT_RUN_MAX_CORRECTIONS);
        // On a quarter-turn heading, within the tolerance (one correction may still be under way
        // at the bound; after a few turns the gain is learnt and none is needed).
        const float off = wrap_deg_(w.heading - roundf(w.heading / (90.0f * deg)) * 90.0f * deg);
        assert_true(fabsf(off) < (i < 3 ? 6.0f : 2.6f));
        if (i >= 3) {
            assert_int_equal(periods, turn.periods);
        }
    }
    assert_float_equal(run.turn_gain, 0.99f, 0.02f);  // (0.92 + 1.06) / 2
    // Steps: the first ones bend and are corrected, later ones go straight.
    float bend = 0.0f;
    for (int i = 0; i < 12; i++) {
        const robot_pose_t pose = {w.x, w.y, w.heading};
        const robot_motion_t step = robot_action_motion(&cfg, ROBOT_FORWARD, &pose);
        const float h0 = w.heading, o0 = w.odom, x0 = w.x, y0 = w.y;
        const int periods = run_motion_(&cfg, &run, &w, &step);
        assert_true(periods <= step.periods + (int)ROBOT_RUN_MAX_CORRECTIONS);
        const float d = travel_of_(&cfg, step);
        assert_float_equal(w.odom - o0, d, ROBOT_RUN_DIST_TOL + 1e-3f);
        assert_true(fabsf(wrap_deg_(w.heading - h0)) < 2.6f);
        // Sideways: how far the step left its line.
        bend = fabsf(-(w.x - x0) * sinf(h0) + (w.y - y0) * cosf(h0));
        w.x = x0 + d * cosf(h0);  // stay in the room (the test's robot has no walls)
        w.y = y0 + d * sinf(h0);
        w.x = fmodf(w.x + 100.0f, 4.0f);
        w.y = fmodf(w.y + 100.0f, 3.0f);
    }
    assert_true(bend < 0.005f);
    assert_float_equal(run.trim, (0.92f - 1.06f) / (0.92f + 1.06f), 0.01f);
    // An exact robot: no correction, the planned periods only.
    robot_run_t exact;
    robot_run_init(&exact);
    wheeled_t e = {1.0f, 1.0f, 0.0f, 0.0f, 1.0f, 1.0f};
    const robot_pose_t pose = {e.x, e.y, e.heading};
    const robot_motion_t turn = robot_action_motion(&cfg, ROBOT_TURN_RIGHT, &pose);
    assert_int_equal(run_motion_(&cfg, &exact, &e, &turn), turn.periods);
    assert_float_equal(wrap_deg_(e.heading), -90.0f, 0.01f);
    assert_int_equal(exact.corrections, 0);
}

// The lab robot's heading takes the Cricket's word after a straight step: fixes that put the
// step's line 10 degrees left of the heading the gyro held move the heading 2 degrees left.
static void test_heading_follows_the_fixes_of_a_straight_step(void **state)
{
    (void)state;
    bench_init_lab_aligned_();
    agent_paper_sim.params.epsilon = 0.0f;
    const float cw = 0.5375f;
    bench_.sense.pose = (robot_pose_t){2.0f * cw + bench_.cfg.step_past_m, 0.8f + bench_.cfg.step_past_m, 0.0f};
    const agent_state_t s0 = robot_encode_state(&bench_.cfg, &bench_.sense.pose, 0);
    qstore_set(&agent_paper_sim.q, qstore_row_for_update(&agent_paper_sim.q, s0), ROBOT_FORWARD, 10.0f);
    robot_ctrl_start_episode(&bench_.ctrl);
    for (int i = 0; i < 20 && !(bench_.ctrl.step_done && robot_move_pending(&bench_.ctrl.move)); i++) {
        bench_period_();  // settling (nothing to do along x), then the first state: forward
    }
    assert_int_equal(bench_.ctrl.a, ROBOT_FORWARD);
    const float x0 = bench_.ctrl.move.x0, y0 = bench_.ctrl.move.y0;
    for (int i = 0; i < 20 && bench_.ctrl.mode == ROBOT_MODE_ACTING; i++) {
        bench_period_();
    }
    assert_int_equal(bench_.ctrl.mode, ROBOT_MODE_WAIT_FIX);
    assert_float_equal(bench_.ctrl.move.heading_offset, 0.0f, 0);
    const float d = bench_.sense.pose.x - x0;
    assert_true(d > 0.3f);
    bench_.sense.pose.y = y0 + d * tanf(10.0f * 3.14159265f / 180.0f);
    bench_period_();  // the fix after the step: observed
    assert_true(bench_.ctrl.step_done);
    assert_float_equal(bench_.ctrl.move.heading_offset, 0.2f * 10.0f * 3.14159265f / 180.0f, 1e-3);
    // A new episode starts from the heading the operator gives.
    robot_ctrl_start_episode(&bench_.ctrl);
    assert_float_equal(bench_.ctrl.move.heading_offset, 0.0f, 0);
}

int main(void)
{
    sim_equal_init_();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shipped_configs_are_valid),
        cmocka_unit_test(test_shipped_sim_fits_its_room),
        cmocka_unit_test(test_defaults_need_a_scenario),
        cmocka_unit_test(test_values_from_the_room),
        cmocka_unit_test(test_position_cells_and_clamping),
        cmocka_unit_test(test_goal_as_cells),
        cmocka_unit_test(test_heading_sectors_wrap),
        cmocka_unit_test(test_turn_step_of_aligned_turns),
        cmocka_unit_test(test_range_code_bits),
        cmocka_unit_test(test_action_wheels_realise_the_step),
        cmocka_unit_test(test_aligned_turns_end_on_the_grid_of_headings),
        cmocka_unit_test(test_aligned_steps_cross_into_the_next_cell),
        cmocka_unit_test(test_fitted_grid),
        cmocka_unit_test(test_centred_steps_stop_at_the_centre_of_the_next_cell),
        cmocka_unit_test(test_backoff_returns_to_where_an_aligned_step_stops),
        cmocka_unit_test(test_settling_ends_on_the_grid_of_aligned_stops),
        cmocka_unit_test(test_episode_reaches_goal_with_reward_and_report),
        cmocka_unit_test(test_step_cap_ends_the_episode),
        cmocka_unit_test(test_replay_leaves_a_loop),
        cmocka_unit_test(test_fixed_steps_through_a_cell_are_no_loop),
        cmocka_unit_test(test_first_state_waits_for_a_pose_taken_since_the_start),
        cmocka_unit_test(test_bump_costs_and_is_counted),
        cmocka_unit_test(test_bumped_step_backs_off_then_is_observed),
        cmocka_unit_test(test_episode_starts_after_settling),
        cmocka_unit_test(test_a_robot_larger_than_its_cells_does_not_settle),
        cmocka_unit_test(test_operator_safe_stop_holds_until_start),
        cmocka_unit_test(test_safe_stop_on_bus_loss_and_resume),
        cmocka_unit_test(test_waits_for_a_fix_taken_after_stopping),
        cmocka_unit_test(test_safe_stop_while_waiting_for_a_fix_keeps_the_step),
        cmocka_unit_test(test_fixed_planning_runs_after_each_step),
        cmocka_unit_test(test_idle_planning_when_planning_is_zero),
        cmocka_unit_test(test_idle_planning_plans_before_the_next_action),
        cmocka_unit_test(test_closed_loop_motion_on_mismatched_wheels),
        cmocka_unit_test(test_heading_follows_the_fixes_of_a_straight_step),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
