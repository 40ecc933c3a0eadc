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

/// The cell of v in [0, extent) cut into 2^bits equal cells; values outside (NaN too) clamp to
/// the edge cells.
uint32_t robot_cell_of(float v, float extent, uint8_t bits);

/// Axes of the state grid (robot_config_t.grid).
#define ROBOT_AXIS_X 0u
#define ROBOT_AXIS_Y 1u

/// Cells along `axis`: 2^bits, or the fitted grid's count.
uint32_t robot_grid_cells(const robot_config_t *cfg, uint32_t axis);

/// The cell of coordinate v along `axis`; values outside the arena (NaN too) clamp to the edge
/// cells.
uint32_t robot_grid_cell(const robot_config_t *cfg, uint32_t axis, float v);

/// Where cell k along `axis` lies: from *lo (m), *side wide.
void robot_grid_span(const robot_config_t *cfg, uint32_t axis, uint32_t k, float *lo, float *side);

/// The smallest side of a cell a step can stop in (m): min over both axes of the cells at least
/// step_past_m wide (narrower fitted cells lie inside obstacles and are stepped over); with equal
/// cells, the smaller of the two cell sides.
float robot_grid_min_side(const robot_config_t *cfg);

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
