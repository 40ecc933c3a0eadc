// SPDX-License-Identifier: MIT
// dynaqpc robot application: the state grid over the arena, the agent's state a pose and range
// readings encode, and the goal on that grid. Depends on the configuration's fields only.
#ifndef ROBOT_GEOMETRY_H
#define ROBOT_GEOMETRY_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/space.h"
#include "robot/robot_config.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The robot's pose in the arena frame: metres, heading in radians counter-clockwise from +x.
typedef struct robot_pose {
    float x, y, heading;
} robot_pose_t;

/// The size (m) of one cell of the state grid: the arena cut into 2^bits_x by 2^bits_y cells.
void robot_cell_size(const robot_config_t *cfg, float *w, float *h);

/// The cell of v in [0, extent) cut into 2^bits equal cells; values outside (NaN too) clamp to
/// the edge cells.
uint32_t robot_cell_of(float v, float extent, uint8_t bits);

/// The agent's state space for this robot: x, y, heading (circular), range code (absolute).
void robot_config_space(const robot_config_t *cfg, agent_space_t *out);

/// How many low heading bits aligned turns never change once the robot has turned: g when a
/// turn is exactly 2^g heading sectors (90 degrees over 16 sectors: 2), else 0 (fixed turns, or
/// turns that do not divide the sectors). The model keeps its percept map over the headings
/// turns reach (agent_space_t.turn_step_bits), so 16 sectors cost the memory of 4.
uint32_t robot_turn_step_bits(const robot_config_t *cfg);

/// The range code: bit k set when a sensor of rays_of_bit[k] reads below its threshold.
/// Readings that are not finite or not positive count as "nothing near".
uint32_t robot_range_code(const robot_config_t *cfg, const float *range_m, uint32_t n);

/// The state: x and y cells of the arena (clamped to it), heading sector (sector 0 centred on
/// +x, sectors counter-clockwise), and the range code.
agent_state_t robot_encode_state(const robot_config_t *cfg, const robot_pose_t *pose,
                                 uint32_t range_code);

/// True when the pose is inside the goal circle, or with cfg->goal_cells when the centre of the
/// pose's state cell is (docs/scenarios.md, "The goal as cells").
bool robot_in_goal(const robot_config_t *cfg, const robot_pose_t *pose);

#ifdef __cplusplus
}
#endif

#endif // ROBOT_GEOMETRY_H
