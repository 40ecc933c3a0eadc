// SPDX-License-Identifier: MIT
// dynaqpc robot application: a real step's whole life on the wheels, from its start to where its
// outcome is observed.
//
// The controller (controller.h) decides what to do: it observes a state, learns, and picks an
// action. Everything between two observations belongs to this module, which the controller calls
// once each control period (robot_move_period()):
//
// - the start: the action's motion (robot_action_motion()), its heading held in closed loop
//   (robot_run_t);
// - the end: the planned periods, then (paper-lab) standing still until a fix taken since, with
//   at most ROBOT_RUN_MAX_CORRECTIONS corrections once the robot stands (closed loop), and what
//   the fixes before and after a straight step say of the gyro's heading;
// - the back-off after a step that bumped (robot_backoff_motion());
// - settling onto the grid of aligned stops before an episode's first state, or after a safe
//   stop cut a motion short (robot_settle_motion()).
//
// robot_move_period() says when the outcome is observable (ROBOT_MOVE_ARRIVED) and at which pose;
// the controller then starts the next step (robot_move_step()) or ends the episode
// (robot_move_stop()). Pure logic, no I/O, no heap.
#ifndef ROBOT_MOVE_H
#define ROBOT_MOVE_H

#include <stdbool.h>
#include <stdint.h>

#include "robot/robot_config.h"
#include "robot/robot_geometry.h"
#include "robot/robot_motion.h"

#ifdef __cplusplus
extern "C" {
#endif

/// What the sensors say at the start of a control period.
typedef struct robot_sense {
    uint64_t now_us;
    bool pose_ok;  ///< `pose` is a usable fix (Cricket: fresh and taken while still)
    robot_pose_t pose;
    uint64_t pose_time_us;  ///< when the pose was measured
    float range_m[ROBOT_MAX_RANGES];
    uint8_t n_ranges;
    bool bump;    ///< a bumper touched something during the last period
    bool bus_ok;  ///< the motor controller has been heard within cfg->bus_timeout_us
    /// The range sensors have not been heard for cfg->bus_timeout_us: range_m holds their last
    /// ranges, which no longer say what is ahead (false for a robot without ranges).
    bool ranges_silent;
    /// The wheels' odometer: metres the axle's midpoint travelled along the body (signed, summed).
    float odom_m;
    bool odom_ok;  ///< the odometer counts (the motor controller reports its wheel speeds)
} robot_sense_t;

/// Where the wheels are in a step's life.
typedef enum robot_move_phase {
    ROBOT_MOVE_IDLE = 0,      ///< nothing to do (before an episode, after its end)
    ROBOT_MOVE_DRIVING = 1,   ///< the wheels carry out a motion (a step's, a correction, a
                              ///< back-off's, settling's)
    ROBOT_MOVE_STANDING = 2,  ///< stopped after a motion (or at an episode's start), waiting for a
                              ///< fix taken since
} robot_move_phase_t;

/// What a control period of robot_move_period() ended with.
typedef enum robot_move_event {
    ROBOT_MOVE_BUSY = 0,     ///< nothing to observe yet
    ROBOT_MOVE_ARRIVED = 1,  ///< the pending step's outcome, or an episode's first state, is
                             ///< observable now, at the pose robot_move_period() gave
} robot_move_event_t;

// Fields ordered so the struct has no padding to spare (the 192 KiB paper-sim image has none).
typedef struct robot_move {
    uint8_t phase;         ///< robot_move_phase_t
    uint8_t periods_left;  ///< of the motion being driven
    bool pending;          ///< a real step is under way (its motion, back-off, corrections)
    uint8_t action;        ///< the pending step's action
    float act_heading;     ///< the heading the pending step started with
    float x0, y0;          ///< the fix the pending step started from
    bool bumped;           ///< a bumper touched since the pending step started
    bool backing_off;      ///< the pending step bumped, and the robot backs off (robot_backs_off())
    uint8_t settle_phase;  ///< the next robot_settle_phase_t of settling (robot_settles())
    bool run_check;        ///< a closed-loop motion's periods are over: check it once it stands
    robot_run_t run;       ///< the motion in closed loop (robot_closes_loop())
    float heading_offset;  ///< rad added to the sensed heading: what the fixes said of the gyro's
    /// The gyro's scale from the fixes (closed loop; heading_from_fix_() in robot_move.c): a gyro
    /// that reads (1 + s) times every rotation is off by gyro_share = s/(1 + s) of the rotation
    /// it read since the operator gave the heading (gyro_turned, unwrapped, since the episode's
    /// start); the heading subtracts gyro_share x gyro_turned. gyro_share is learnt from the lines
    /// of the straight steps and kept from episode to episode; gyro_last is the gyro's heading at
    /// the last period (ROBOT_GYRO_UNSEEN before the episode's first).
    float gyro_turned;
    uint64_t stopped_at_us;  ///< when the wheels stopped after the last motion
    float v_left, v_right;   ///< the wheel speeds being commanded (m/s)
    float gyro_last, gyro_share;
} robot_move_t;

/// At boot: nothing learnt of the wheels (robot_run_init()), idle.
void robot_move_init(robot_move_t *mv);

/// An episode starts: no step pending, the heading as the operator gives it (no offset), the
/// robot standing; it settles onto the grid (robot_settles()) before its first state. What the
/// closed loop learnt of the wheels is kept.
void robot_move_episode(robot_move_t *mv);

/// The robot was put where it stands at `now_us` (an episode's start: by hand, or by the
/// simulator) without its wheels turning: the first state waits for a pose taken since.
void robot_move_placed(robot_move_t *mv, uint64_t now_us);

/// Ends whatever motion: no step pending, wheels stopped, idle.
void robot_move_stop(robot_move_t *mv);

/// A safe stop that cut a motion short is over: the pending step (its outcome unknown) is
/// dropped, and the robot stands from `now_us` and settles again from where it is before a
/// first state is observed afresh. A safe stop while the robot stood keeps its step.
void robot_move_cut(robot_move_t *mv, uint64_t now_us);

/// One control period. `halted`: a safe stop holds the wheels at zero and the motion where it
/// was (a bump is still latched). Otherwise drives the motion on, and when the pending step's
/// outcome (or the episode's first state) is observable returns ROBOT_MOVE_ARRIVED with the pose
/// to observe in *at (the sensed one, its heading as the fixes corrected it); then the controller
/// calls robot_move_step() or robot_move_stop() in the same period. The wheel speeds to command
/// are mv->v_left, mv->v_right.
robot_move_event_t robot_move_period(robot_move_t *mv, const robot_config_t *cfg,
                                     const robot_sense_t *sensed, bool halted, robot_pose_t *at);

/// Starts the step that carries out `action` from the pose robot_move_period() gave (`at`), with
/// the period's odometer from `sensed`.
void robot_move_step(robot_move_t *mv, const robot_config_t *cfg, uint8_t action,
                     const robot_pose_t *at, const robot_sense_t *sensed);

/// Whether a real step is pending (false before an episode's first state).
bool robot_move_pending(const robot_move_t *mv);

/// Whether the pending step bumped.
bool robot_move_bumped(const robot_move_t *mv);

/// The heading the motions use for the gyro's `gyro_heading_rad`: with what the Cricket fixes have
/// said of the gyro (heading_offset, gyro_share; as of the last control period).
float robot_move_heading(const robot_move_t *mv, float gyro_heading_rad);

#ifdef __cplusplus
}
#endif

#endif  // ROBOT_MOVE_H
