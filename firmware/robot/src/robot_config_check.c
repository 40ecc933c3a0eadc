// SPDX-License-Identifier: MIT
// dynaqpc robot application: what robot_config_check() refuses, and why.
#include "robot/robot_config.h"

#include <math.h>
#include <stddef.h>

#include "fw/fw_base.h"
#include "robot/robot_geometry.h"

static bool finite_positive_(float v)
{
    return v > 0.0f && v < 1e30f;  // false for NaN and infinities
}

// A fitted axis: 1..min(2^bits, ROBOT_MAX_GRID_CELLS) cells whose edges rise from 0 to the side.
static bool grid_axis_ok_(const robot_grid_axis_t *g, float side, uint8_t bits)
{
    if (g->cells == 0u) {
        return true;
    }
    if (g->cells > ROBOT_MAX_GRID_CELLS || bits > 16u || g->cells > (1u << bits) || g->edge[0] != 0.0f ||
        !(fabsf(g->edge[g->cells] - side) <= 1e-3f * side)) {
        return false;
    }
    for (uint32_t k = 0; k < g->cells; k++) {
        if (!(g->edge[k + 1u] > g->edge[k])) {  // NaN fails too
            return false;
        }
    }
    return true;
}

// Some cell of the grid has its centre in the goal circle.
static bool goal_has_a_cell_(const robot_config_t *c)
{
    if (c->grid[0].cells == 0u && c->grid[1].cells == 0u) {
        // Equal cells: the cell centre nearest the goal's is the centre of the cell holding it;
        // if that one is outside the circle, so is every other.
        const robot_pose_t goal_centre = {c->goal_x, c->goal_y, 0.0f};
        return robot_in_goal(c, &goal_centre);
    }
    const uint32_t nx = robot_grid_cells(c, ROBOT_AXIS_X), ny = robot_grid_cells(c, ROBOT_AXIS_Y);
    for (uint32_t j = 0; j < ny; j++) {
        for (uint32_t i = 0; i < nx; i++) {
            float x0, w, y0, h;
            robot_grid_span(c, ROBOT_AXIS_X, i, &x0, &w);
            robot_grid_span(c, ROBOT_AXIS_Y, j, &y0, &h);
            const robot_pose_t centre = {x0 + 0.5f * w, y0 + 0.5f * h, 0.0f};
            if (robot_in_goal(c, &centre)) {
                return true;
            }
        }
    }
    return false;
}

int robot_config_check(const robot_config_t *c)
{
    if (c == NULL) {
        return FW_ERR_INVAL;
    }
    // The arena and goal are real extents; the goal lies inside the arena.
    if (!finite_positive_(c->arena_w) || !finite_positive_(c->arena_h) ||
        !finite_positive_(c->goal_r) || !(c->goal_x >= 0.0f && c->goal_x <= c->arena_w) ||
        !(c->goal_y >= 0.0f && c->goal_y <= c->arena_h)) {
        return FW_ERR_INVAL;
    }
    // Every component has 1..16 bits and the state fits the agent's key (space_validate).
    agent_space_t sp;
    robot_config_space(c, &sp);
    if (c->bits_code > ROBOT_MAX_CODE_BITS || space_validate(&sp) != FW_OK) {
        return FW_ERR_INVAL;
    }
    // A fitted grid cuts each side from 0 to its end, in rising edges.
    if (!grid_axis_ok_(&c->grid[0], c->arena_w, c->bits_x) || !grid_axis_ok_(&c->grid[1], c->arena_h, c->bits_y)) {
        return FW_ERR_INVAL;
    }
    // Goal cells: some cell must have its centre in the circle, or the goal is never reached.
    if (c->goal_cells > 1u || (c->goal_cells && !goal_has_a_cell_(c))) {
        return FW_ERR_INVAL;
    }
    // Each code bit looks at existing sensors with a real threshold.
    if (c->n_ranges > ROBOT_MAX_RANGES) {
        return FW_ERR_INVAL;
    }
    for (uint32_t k = 0; k < c->bits_code; k++) {
        const uint32_t sensors = c->n_ranges >= 32u ? UINT32_MAX : (1u << c->n_ranges) - 1u;
        if (c->rays_of_bit[k] == 0u || (c->rays_of_bit[k] & ~sensors) != 0u ||
            !finite_positive_(c->code_threshold_m[k])) {
            return FW_ERR_INVAL;
        }
    }
    // An action moves or turns, within at least one control period.
    if (!finite_positive_(c->step_m) || !finite_positive_(c->turn_rad) ||
        !finite_positive_(c->track_m) || c->action_periods == 0u || c->period_us == 0u ||
        c->step_cap == 0u) {
        return FW_ERR_INVAL;
    }
    // An aligned step ends inside the next cell, not beyond it.
    const float cell = robot_grid_min_side(c);
    if (c->aligned_actions > ROBOT_ACTIONS_CENTRED ||
        (c->aligned_actions && (!finite_positive_(c->step_past_m) || !(c->step_past_m < cell)))) {
        return FW_ERR_INVAL;
    }
    // Cricket needs three beacons for a fix.
    if (c->pose_source == ROBOT_POSE_CRICKET && (c->n_beacons < 3u || c->n_beacons > ROBOT_MAX_BEACONS)) {
        return FW_ERR_INVAL;
    }
    if (!(c->speed_of_sound == 0.0f || (c->speed_of_sound >= 300.0f && c->speed_of_sound <= 400.0f))) {
        return FW_ERR_INVAL;  // 0: the driver's 343 m/s; else a room's, as the scenario allows
    }
    if (c->pose_source != ROBOT_POSE_GPS && c->pose_source != ROBOT_POSE_CRICKET) {
        return FW_ERR_INVAL;
    }
    if (c->values != ROBOT_VALUES_ROOM && c->values != ROBOT_VALUES_PAPER) {
        return FW_ERR_INVAL;
    }
    return FW_OK;
}
