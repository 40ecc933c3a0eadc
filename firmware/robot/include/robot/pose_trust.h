// SPDX-License-Identifier: MIT
// dynaqpc robot application: whether the firmware may trust its heading, and how it finds it again.
//
// A robot whose heading comes from an integrated gyro (the lab robot: Cricket gives x, y only)
// does not know its heading at boot (the integrator starts at 0), after a gap in the gyro's
// samples (a turn then goes unmeasured), after its own control task stalled (the samples bunched
// up behind it are integrated over the wrong times) or after its position jumped (it was picked
// up and put down: fresh fixes that keep agreeing away from the last believed one, robot/fix_gate.h).
// While the heading is not trusted the application starts no episode and learns
// from no step: a running episode is ended as interrupted (robot_ctrl_interrupt) the period the
// trust is lost, before its pending step is observed.
//
// Trust comes back in one of two ways:
//   - the operator's START_EPISODE carries the heading (the operator put the robot down): at once;
//   - a straight leg (pose_trust_leg_period): the robot stands until a fresh Cricket fix A, drives
//     straight ahead POSE_TRUST_LEG_M, stands until a fresh fix B, and takes the heading of the
//     track A->B for the gyro's mean heading over the leg. It first turns a quarter turn in place
//     (up to three times) while something is in front within POSE_TRUST_CLEAR_M; a bump or a
//     track shorter than POSE_TRUST_MIN_TRACK_M starts it again after a quarter turn. With the
//     lab's Cricket noise (8.7 mm RMS per fix, docs/can-protocol.md) a 0.4 m track gives the
//     heading to about 2 degrees RMS; measured in tests/unit/robot (unit.pose_trust) and by
//     `dynaqpc-sim soak`.
// A robot whose pose source measures its heading (GPS_POSE) is trusted whenever that source is.
//
// Pure logic, no I/O, fixed memory. Context: the control task.
#ifndef ROBOT_POSE_TRUST_H
#define ROBOT_POSE_TRUST_H

#include <stdbool.h>
#include <stdint.h>

#include "robot/robot_config.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The leg's length, speed, and the clearance it wants in front.
#define POSE_TRUST_LEG_M 0.40f
#define POSE_TRUST_LEG_SPEED_M_S 0.20f
#define POSE_TRUST_CLEAR_M 0.60f
/// A track shorter than this (a bump cut the leg short) gives no heading.
#define POSE_TRUST_MIN_TRACK_M 0.25f
/// The quarter turn before a new try, in control periods.
#define POSE_TRUST_TURN_PERIODS 4u
/// A gyro gap that can have hidden more turn than this (its length times the larger of the rates
/// at its ends), degrees, or any gap while the wheels drive: the heading is lost. Gaps of a robot
/// standing still cost nothing.
#define POSE_TRUST_GAP_DEG 2.0f
/// A control task that ran this much later than its period: the gyro's samples bunched behind it.
#define POSE_TRUST_STALL_US 500000u

/// Why the pose is (not) trusted: FW_STATUS TrustReason.
typedef enum pose_trust_reason {
    POSE_TRUST_WHY_BOOT = 0,      ///< untrusted: booted (the gyro's integral starts at 0)
    POSE_TRUST_WHY_GYRO_GAP = 1,  ///< untrusted: the gyro's samples had a gap, or it went silent or faulty
    POSE_TRUST_WHY_FIX_JUMP = 2,  ///< untrusted: the position jumped (the robot was moved)
    POSE_TRUST_WHY_STALL = 3,     ///< untrusted: the control task stalled
    POSE_TRUST_WHY_OPERATOR = 4,  ///< trusted: START_EPISODE carried the heading
    POSE_TRUST_WHY_LEG = 5,       ///< trusted: a straight leg's Cricket track gave the heading
    POSE_TRUST_WHY_ABSOLUTE = 6,  ///< trusted: the pose source measures the heading (GPS_POSE)
} pose_trust_reason_t;

/// The phases of the straight leg.
typedef enum pose_trust_phase {
    POSE_TRUST_LEG_IDLE = 0,   ///< not finding the heading
    POSE_TRUST_LEG_FIX_A = 1,  ///< standing, waiting for the first fix
    POSE_TRUST_LEG_DRIVE = 2,  ///< driving straight
    POSE_TRUST_LEG_FIX_B = 3,  ///< standing, waiting for the second fix
    POSE_TRUST_LEG_TURN = 4,   ///< turning a quarter turn before another try
} pose_trust_phase_t;

/// What the leg reads each control period.
typedef struct pose_trust_in {
    uint64_t now_us;
    bool fix_fresh;        ///< a fresh fix, taken while the robot stood still
    float x_m, y_m;        ///< the fix
    uint64_t fix_us;       ///< when its oldest range was taken
    float heading_deg;     ///< the gyro's heading (relative turns are right even when untrusted)
    float front_m;         ///< the nearest range ahead (a large value: nothing in view)
    bool bump;             ///< a bumper touched something in the last period
} pose_trust_in_t;

typedef struct pose_trust {
    uint64_t stopped_us;       ///< when the wheels last stopped: a fix must be younger
    float ax_m, ay_m, a_heading_deg;  ///< fix A and the gyro then
    float correction_deg;      ///< the last leg's change to the gyro's heading
    uint32_t losses;           ///< times the trust was lost
    uint16_t losses_by[4];     ///< of them, by reason (BOOT never: it is untrusted from the start)
    uint16_t legs;             ///< legs that gave a heading
    uint16_t legs_failed;      ///< legs cut short (a bump) or without room
    bool trusted;
    uint8_t reason;            ///< pose_trust_reason_t
    uint8_t phase;             ///< pose_trust_phase_t
    uint8_t periods_left;      ///< of the current drive or turn
    uint8_t turns;             ///< quarter turns in a row for want of room
} pose_trust_t;

/// Untrusted (reason BOOT) unless `absolute` (the pose source measures the heading).
void pose_trust_init(pose_trust_t *t, bool absolute);

/// The heading is lost for `reason`; cancels a leg in progress. A robot with an absolute
/// heading source ignores it. Counted in `losses` when the pose was trusted.
void pose_trust_lose(pose_trust_t *t, pose_trust_reason_t reason);

/// The heading is known again (OPERATOR, LEG); cancels a leg in progress.
void pose_trust_grant(pose_trust_t *t, pose_trust_reason_t reason);

/// Stops a leg in progress (the operator's STOP or SAFE_STOP); the trust stays as it is.
void pose_trust_cancel(pose_trust_t *t);

/// One control period of finding the heading by a straight leg. Starts a leg when none runs.
/// Writes the wheel speeds (m/s, forward positive). Returns true when the leg gave the heading:
/// then *correction_deg is what to add to the gyro's heading, and the pose is trusted (LEG).
bool pose_trust_leg_period(pose_trust_t *t, const robot_config_t *cfg, const pose_trust_in_t *in,
                           float *v_left, float *v_right, float *correction_deg);

#ifdef __cplusplus
}
#endif

#endif // ROBOT_POSE_TRUST_H
