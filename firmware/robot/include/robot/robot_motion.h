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

/// The phases of settling onto the grid of aligned stops, in order.
typedef enum robot_settle_phase {
    ROBOT_SETTLE_FACE_GRID = 0,      ///< turn to the nearest grid heading
    ROBOT_SETTLE_ALONG = 1,          ///< drive to the nearer aligned stop along it
    ROBOT_SETTLE_QUARTER_LEFT = 2,   ///< a quarter turn left, unless the offset across is a stop
    ROBOT_SETTLE_ACROSS = 3,         ///< drive to the nearer aligned stop along the new heading
    ROBOT_SETTLE_PHASES = 4,
} robot_settle_phase_t;

/// Whether the robot settles onto the grid of aligned stops before it observes a first state:
/// robot_backs_off(), ROBOT_START_SETTLE, and turns of a quarter turn (on a finer grid of
/// headings an aligned step may be diagonal, and the stops are not a cell's sides). It settles at
/// an episode's start, and again after a safe stop cut a step short (the controller starts
/// afresh from wherever the stop left it).
bool robot_settles(const robot_config_t *cfg);

/// Phase `phase` (robot_settle_phase_t) of settling onto the grid, from `pose` (where the
/// previous phase ended). An aligned stop is an offset in the cell at which an aligned step along
/// that axis stops: step_past_m past the edge behind, or short of the edge ahead. Periods 0 when
/// the phase has nothing to do, for a phase beyond the last, or when actions are not aligned.
/// Settling is not a real step: a bump while settling is not counted, not rewarded and not backed
/// off from, and settling goes on from where the bump left the robot (its first state may then
/// be off the grid; about 3 % of starts on the lab robot's far-goal tuning rooms).
robot_motion_t robot_settle_motion(const robot_config_t *cfg, uint8_t phase, const robot_pose_t *pose);

#ifdef __cplusplus
}
#endif

#endif // ROBOT_MOTION_H
