// SPDX-License-Identifier: MIT
// dynaqpc robot application: from a pose and range readings to the agent's state, and from the
// agent's action to wheel speeds.
#ifndef ROBOT_STATE_ENCODER_H
#define ROBOT_STATE_ENCODER_H

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

/// One action as the wheels carry it out: speed targets (m/s) held for `periods` control periods.
typedef struct robot_motion {
    float v_left, v_right;
    uint8_t periods;
} robot_motion_t;

/// The motion that realises `action` from `pose`. Without cfg->aligned_actions: step_m or turn_rad
/// over action_periods periods, whatever the pose. With it: a turn ends on the next multiple of
/// turn_rad in its direction (at least a quarter of turn_rad away), a step ends step_past_m
/// past the edge of the current x-y cell along the heading (robot_config.h says why).
robot_motion_t robot_action_motion(const robot_config_t *cfg, uint8_t action, const robot_pose_t *pose);

#ifdef __cplusplus
}
#endif

#endif // ROBOT_STATE_ENCODER_H
