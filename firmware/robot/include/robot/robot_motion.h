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
/// past the edge of the current x-y cell along the heading, or with ROBOT_ACTIONS_CENTRED at the
/// centre of the cell it enters (robot_config.h says why).
robot_motion_t robot_action_motion(const robot_config_t *cfg, uint8_t action, const robot_pose_t *pose);

/// Whether the robot backs off after a step that bumped, unless ROBOT_BUMP_BACKOFF is 0: with
/// fixed steps (no cfg->aligned_actions) always; with aligned actions, when its track is narrower
/// than the smaller side of a cell (a robot with room to stand anywhere in its cell; the lab
/// robot, not the sonar robot).
bool robot_backs_off(const robot_config_t *cfg);

/// After `action` (ROBOT_FORWARD or ROBOT_BACKWARD), started facing `heading`, bumped and left
/// the robot at `pose`: the motion back the way the step came, to step_past_m past the edge of
/// the pose's cell behind it (with ROBOT_ACTIONS_CENTRED: to the cell's centre), where an aligned
/// step into this cell stops. Periods 0 when the
/// pose is not beyond that point, or for a turn. With fixed steps: half a step back.
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
/// headings an aligned step may be diagonal, and the stops are not a cell's sides). With fixed
/// steps and turns that divide the circle, only the heading settles (ROBOT_SETTLE_FACE_GRID: to
/// the nearest multiple of turn_rad); ROBOT_START_SETTLE still applies. It settles at
/// an episode's start, and again after a safe stop cut a step short (the controller starts
/// afresh from wherever the stop left it).
bool robot_settles(const robot_config_t *cfg);

/// Phase `phase` (robot_settle_phase_t) of settling onto the grid, from `pose` (where the
/// previous phase ended). An aligned stop is an offset in the cell at which an aligned step along
/// that axis stops: step_past_m past the edge behind, or short of the edge ahead (with
/// ROBOT_ACTIONS_CENTRED: the cell's centre). Periods 0 when
/// the phase has nothing to do, for a phase beyond the last, or, with fixed steps, for every
/// phase but ROBOT_SETTLE_FACE_GRID.
/// Settling is not a real step: a bump while settling is not counted, not rewarded and not backed
/// off from, and settling goes on from where the bump left the robot (its first state may then
/// be off the grid; about 3 % of starts on the lab robot's far-goal tuning rooms).
robot_motion_t robot_settle_motion(const robot_config_t *cfg, uint8_t phase, const robot_pose_t *pose);

/// A motion carried out in closed loop (robot_closes_loop()): the planned motion's wheel speeds,
/// corrected as it goes by what the gyro and the wheels' odometer say.
///
/// - A drive holds its heading: each period the differential of the wheel speeds turns the robot
///   back to it over the periods left, and a trim learnt from earlier drives cancels the wheels'
///   mismatch from the start. It holds the nearest grid heading when it starts within an eighth
///   of a turn of one (aligned quarter turns), else its start heading.
/// - A turn ends on its heading: the turn it commands is divided by the turn gain learnt from
///   earlier turns (the gyro's turn per commanded turn).
/// - When the planned periods are over and the robot stands (robot_run_correction()), a heading
///   more than ROBOT_RUN_HEADING_TOL off, or (a drive) an odometer more than ROBOT_RUN_DIST_TOL
///   short or past the planned distance, starts a correction motion of one period; at most
///   ROBOT_RUN_MAX_CORRECTIONS per planned motion, so a motion is bounded in time.
///
/// The drive's speed along the heading is not recomputed during the motion: at the period's edge
/// the robot is still at speed, and what the wheels travel while they slow down is not yet on
/// the odometer (on the lab robot ~1 cm and, for a turn, ~3 degrees at 60 m/s^2).
typedef struct robot_run {
    robot_motion_t m;        ///< the motion as started
    bool turn;               ///< a turn in place; otherwise a drive
    uint8_t periods_left;    ///< of the planned ones
    uint8_t corrections;     ///< correction motions started for the planned motion
    float hold;              ///< rad: a drive's heading, a turn's end heading
    float dist;              ///< m: a drive's planned distance (negative: backward)
    float start_heading;     ///< rad: the gyro's heading when the planned motion started
    float odom0;             ///< m: the odometer then
    bool odom_ok;            ///< the odometer counts
    float commanded_turn;    ///< rad: what the wheel commands would have turned an exact robot
    /// What the robot's own wheels have taught (kept from motion to motion and episode to
    /// episode): a drive commands v (1 - trim) left and v (1 + trim) right; a turn of a radians
    /// is commanded as a / turn_gain.
    float trim, turn_gain;
} robot_run_t;

/// Tolerances and bound of the closed loop.
#define ROBOT_RUN_HEADING_TOL 0.0436f  // rad, 2.5 degrees
#define ROBOT_RUN_DIST_TOL 0.02f       // m
#define ROBOT_RUN_MAX_CORRECTIONS 2u

/// Whether the robot closes its motions on its gyro and odometer: ROBOT_CLOSED_LOOP, and a heading
/// from the gyro (the Cricket robot; the GPS robot's heading is the GPS's, noisy to a degree).
bool robot_closes_loop(const robot_config_t *cfg);

/// Before the first motion: nothing learnt (trim 0, turn gain 1).
void robot_run_init(robot_run_t *r);

/// Starts the planned motion `m` (robot_action_motion(), robot_backoff_motion(),
/// robot_settle_motion()) from the gyro's `heading` and the odometer `odom` (m, along the body;
/// `odom_ok` false: it does not count, and a drive's distance is open loop). `hold` is the
/// heading a drive holds when it is not the grid's (robot_run_t). Returns the first period's wheel
/// speeds in *vl, *vr.
void robot_run_start(robot_run_t *r, const robot_config_t *cfg, const robot_motion_t *m, float heading,
                     float hold, float odom, bool odom_ok, float *vl, float *vr);

/// One control period of the motion in progress (planned or correction): true, with the wheel
/// speeds for the next period in *vl, *vr, while it goes on; false when its periods are over.
bool robot_run_period(robot_run_t *r, const robot_config_t *cfg, float heading, float odom, float *vl, float *vr);

/// After a motion's periods are over and the robot stands: learns from the planned motion (on
/// the first call after it, when `learn`: it did not bump) and starts a correction motion if one
/// is needed and allowed (true, *vl, *vr its speeds); false when the motion is done.
bool robot_run_correction(robot_run_t *r, const robot_config_t *cfg, float heading, float odom, bool learn,
                          float *vl, float *vr);

#ifdef __cplusplus
}
#endif

#endif // ROBOT_MOTION_H
