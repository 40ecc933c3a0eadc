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

/// True when the pose is inside the goal circle.
bool robot_in_goal(const robot_config_t *cfg, const robot_pose_t *pose);

/// Wheel speed targets (m/s) that realise `action` over action_periods control periods.
void robot_action_wheels(const robot_config_t *cfg, uint8_t action, float *v_left, float *v_right);

#ifdef __cplusplus
}
#endif

#endif // ROBOT_STATE_ENCODER_H
