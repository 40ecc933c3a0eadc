// SPDX-License-Identifier: MIT
// dynaqpc robot application: what robot_config_check() refuses, and why.
#include "robot/robot_config.h"

#include <stddef.h>

#include "fw/fw_base.h"
#include "robot/robot_geometry.h"

static bool finite_positive_(float v)
{
    return v > 0.0f && v < 1e30f;  // false for NaN and infinities
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
    // Goal cells: the cell centre nearest the goal's is the centre of the cell holding it; if
    // that one is outside the circle, so is every other, and the goal could never be reached.
    const robot_pose_t goal_centre = {c->goal_x, c->goal_y, 0.0f};
    if (c->goal_cells > 1u || (c->goal_cells && !robot_in_goal(c, &goal_centre))) {
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
    float cell_w, cell_h;
    robot_cell_size(c, &cell_w, &cell_h);
    const float cell = cell_w < cell_h ? cell_w : cell_h;
    if (c->aligned_actions && (!finite_positive_(c->step_past_m) || !(c->step_past_m < cell))) {
        return FW_ERR_INVAL;
    }
    // Cricket needs three beacons for a fix.
    if (c->pose_source == ROBOT_POSE_CRICKET && (c->n_beacons < 3u || c->n_beacons > ROBOT_MAX_BEACONS)) {
        return FW_ERR_INVAL;
    }
    if (c->pose_source != ROBOT_POSE_GPS && c->pose_source != ROBOT_POSE_CRICKET) {
        return FW_ERR_INVAL;
    }
    if (c->values != ROBOT_VALUES_ROOM && c->values != ROBOT_VALUES_PAPER) {
        return FW_ERR_INVAL;
    }
    return FW_OK;
}
