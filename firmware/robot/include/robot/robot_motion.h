// SPDX-License-Identifier: MIT
// dynaqpc robot application: from the agent's action to wheel speeds.
#ifndef ROBOT_MOTION_H
#define ROBOT_MOTION_H

#include <stdbool.h>
#include <stdint.h>

#include "robot/robot_config.h"
#include "robot/robot_geometry.h"

#ifdef __cplusplus
extern "C" {
#endif

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

/// Whether the robot backs off after a step that bumped: with aligned actions, and a track
/// narrower than the smaller side of a cell (a robot with room to stand anywhere in its cell;
/// the lab robot, not the sonar robot), unless ROBOT_BUMP_BACKOFF is 0.
bool robot_backs_off(const robot_config_t *cfg);

/// After `action` (ROBOT_FORWARD or ROBOT_BACKWARD), started facing `heading`, bumped and left
/// the robot at `pose`: the motion back the way the step came, to step_past_m past the edge of
/// the pose's cell behind it, where an aligned step into this cell stops. Periods 0 when the
/// pose is not beyond that point, for a turn, or when actions are not aligned.
robot_motion_t robot_backoff_motion(const robot_config_t *cfg, uint8_t action, float heading,
                                    const robot_pose_t *pose);

/// The motions that settle a robot onto the grid of aligned stops, one phase at a time.
#define ROBOT_SETTLE_PHASES 4u

/// Whether the robot settles at an episode's start: robot_backs_off(), ROBOT_START_SETTLE, and a
/// quarter turn a whole number of turn_rad.
bool robot_settles(const robot_config_t *cfg);

/// Phase `phase` (0 to ROBOT_SETTLE_PHASES - 1) of settling onto the grid, from `pose` (where the
/// previous phase ended): 0 turns to the nearest multiple of turn_rad; 1 drives along the heading
/// to the nearer of the two offsets in the cell an aligned step stops at (step_past_m past the
/// edge behind, or short of the edge ahead); 2 turns a quarter turn left, unless the offset across
/// is at one of those already; 3 is 1 along the new heading. Periods 0 when the phase has nothing
/// to do, or when actions are not aligned.
robot_motion_t robot_settle_motion(const robot_config_t *cfg, uint8_t phase, const robot_pose_t *pose);

#ifdef __cplusplus
}
#endif

#endif // ROBOT_MOTION_H
