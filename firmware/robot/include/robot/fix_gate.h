// SPDX-License-Identifier: MIT
// dynaqpc robot application: which fresh position fixes the robot may believe.
//
// A Cricket fix can be wrong by metres: a reflected or cross-paired range that the trilateration
// fits (drivers/cricket.c drops one such range when four or more agree; three ranges fit any of
// them). Believed, such a fix puts the step's outcome in a cell the robot never reached, and
// becomes the reference the next good fix is measured from, so that the good fix looks like a
// jump and costs the episode its heading (pose_trust.h). The gate checks each fresh fix against
// where dead reckoning puts the robot: the last believed fix, moved by the wheels' travel along
// the gyro's heading (fix_gate_travel, at each MOTOR_STATUS).
//   - a fix outside the arena is refused;
//   - a fix farther from the dead-reckoned point than FIX_GATE_JUMP_M plus FIX_GATE_SLIP of the
//     travel is refused, and held as suspect;
//   - fixes that keep agreeing with the suspect, and not with dead reckoning, for
//     FIX_GATE_CONFIRM_US become the reference. If the wheels drove less than FIX_GATE_JUMP_M
//     since the last believed fix, and that fix was corroborated (a later, different fix agreed
//     with it within FIX_GATE_AGREE_M), the robot was carried: put down elsewhere
//     (FIX_GATE_MOVED). Else dead reckoning drifted (FIX_GATE_DRIFTED): the wheels slipped, the
//     heading they drove on was off, or the fix believed last was itself wrong.
// A refused fix is not a pose: the application waits for the next fix as it does for one that is
// not fresh yet.
//
// Pure logic, no I/O, fixed memory. Context: the control task (fix_gate_check) and the CAN
// receive event (fix_gate_travel), both in the scheduler's thread.
#ifndef ROBOT_FIX_GATE_H
#define ROBOT_FIX_GATE_H

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/// How far a fix may lie from where dead reckoning puts the robot (Cricket noise, the listener's
/// offset from the axle in a turn, the heading's error), plus this share of the travel since the
/// last believed fix (wheels that slip on a wall or in a turn).
#define FIX_GATE_JUMP_M 0.30f
#define FIX_GATE_SLIP 0.25f
/// A later fix this close to dead reckoning (plus FIX_GATE_SLIP of the travel) corroborates the
/// last believed one (the Cricket's noise is about 1 cm a fix).
#define FIX_GATE_AGREE_M 0.10f
/// How long refused fixes must agree with one another before they are a move (about two of the
/// Cricket beacons' periods).
#define FIX_GATE_CONFIRM_US 2000000u

typedef enum fix_gate_verdict {
    FIX_GATE_ACCEPT = 0,   ///< believe it; it is the new reference
    FIX_GATE_REFUSE = 1,   ///< outside the arena, or a jump not (yet) confirmed: not a pose
    FIX_GATE_MOVED = 2,    ///< a jump confirmed, the robot carried: the fix is the new reference
    FIX_GATE_DRIFTED = 3,  ///< a jump confirmed, dead reckoning off: the fix is the new reference
} fix_gate_verdict_t;

/// One fresh fix.
typedef struct fix_gate_in {
    uint64_t now_us;
    float x_m, y_m;
    float arena_w, arena_h;  ///< metres; a fix outside [0, w] x [0, h] is refused
} fix_gate_in_t;

typedef struct fix_gate {
    float dr_x, dr_y;  ///< dead reckoning: the last believed fix moved by the travel since
    float travel_m;    ///< the wheels' travel since the last believed fix (unsigned)
    float suspect_x, suspect_y;  ///< the first of the refused fixes that agree
    uint32_t suspect_since_us;   ///< when the suspect was first seen (low 32 bits of the time)
    uint16_t refused_outside;    ///< control periods whose fix lay outside the arena
    uint16_t refused_jump;       ///< jumps refused (a run of fixes that agree counts once)
    uint16_t drifts;             ///< FIX_GATE_DRIFTED verdicts
    bool have_ref, have_suspect;
    bool blind;         ///< some of the travel was on a heading not trusted
    bool corroborated;  ///< a later, different fix agreed with the last believed one
} fix_gate_t;

/// An empty gate: the first fix inside the arena becomes the reference.
void fix_gate_init(fix_gate_t *gate);

/// Forgets the reference (the operator put the robot down): the next fix inside the arena is
/// believed. The counters stay.
void fix_gate_forget(fix_gate_t *gate);

/// The wheels drove `ds_m` metres (signed: backward is negative) along `heading_rad` (arena
/// frame): dead reckoning follows. A heading that is not trusted (`heading_known` false: at boot,
/// on the straight leg that finds it) gives no direction: until the next believed fix, a fix may
/// then lie anywhere within FIX_GATE_JUMP_M plus (1 + FIX_GATE_SLIP) times the travel.
void fix_gate_travel(fix_gate_t *gate, float ds_m, float heading_rad, bool heading_known);

/// Judges one fresh fix; see the file comment.
fix_gate_verdict_t fix_gate_check(fix_gate_t *gate, const fix_gate_in_t *in);

#ifdef __cplusplus
}
#endif

#endif  // ROBOT_FIX_GATE_H
