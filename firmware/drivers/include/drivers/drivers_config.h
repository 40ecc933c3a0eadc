// SPDX-License-Identifier: MIT
// dynaqpc drivers: compile-time capacities and defaults. Override any of them in the file named
// by FW_CONFIG_FILE (see fw_config.h), never here.
#ifndef DRIVERS_CONFIG_H
#define DRIVERS_CONFIG_H

#include "fw/fw_user_config.h"

#include "fw/fw_base.h"

/// Longest Cricket line kept, in characters without the line end. A default v2 line with every
/// field on is about 80 characters; longer lines are discarded and counted.
#ifndef FW_CFG_CRICKET_LINE_MAX
#define FW_CFG_CRICKET_LINE_MAX 128
#endif
/// Beacons in the Cricket beacon table (one range slot each).
#ifndef FW_CFG_CRICKET_MAX_BEACONS
#define FW_CFG_CRICKET_MAX_BEACONS 8
#endif
/// Characters kept of a Cricket line's space id (SP=...).
#ifndef FW_CFG_CRICKET_SPACE_MAX
#define FW_CFG_CRICKET_SPACE_MAX 16
#endif
/// Longest gap between two gyro samples that the heading integrator bridges, in µs. A longer
/// gap (gyro silent) is not integrated and is counted: the heading is then suspect.
#ifndef FW_CFG_GYRO_MAX_DT_US
#define FW_CFG_GYRO_MAX_DT_US 100000u
#endif
/// The gyro's sample period (GYRO_RATE's cycle time, docs/dynaqpc.dbc), µs, or 0: the default of
/// gyro_set_sample_period (robot_app_options_t gyro_period_ms overrides it at run time). With a period,
/// the heading integrates each interval over the samples' own spacing (the frame counter's steps
/// times the period), not over the frames' receive times, which a bus or a bridge bunches: the
/// emulated board's receive times jitter by tens of ms on a loaded host, and its heading was
/// 20-30 degrees off after bumps (spiky rates weighted by the wrong intervals); with the period,
/// within a degree (docs/results/emulated-board.md). The netduinoplus2 port sets 16000. 0 (the default
/// elsewhere, for now): over the receive times, as every figure in docs/results/ was measured
/// (in lock-step they are the sample times but for idle planning's lead of up to ~3.5 ms; with
/// 16000 the lock-step runs learn differently, not better or worse).
#ifndef FW_CFG_GYRO_PERIOD_US
#define FW_CFG_GYRO_PERIOD_US 0u
#endif
/// Gyro bias estimator: while stationary, bias += (rate - bias) / 2^shift per sample.
#ifndef FW_CFG_GYRO_BIAS_SHIFT
#define FW_CFG_GYRO_BIAS_SHIFT 6
#endif
/// Gyro bias estimator's gate, deg/s: a stationary sample farther than this from the estimate is
/// the robot still turning (the wheels stop some time after the command: the bus, the motor's
/// own ramp), not bias, and is not learnt from (counted in bias_rejected). Far above a MEMS
/// gyro's noise (the simulated one's: 0.6 deg/s sd) and far below a turn's rate (~190 deg/s).
#ifndef FW_CFG_GYRO_BIAS_GATE_DEG_S
#define FW_CFG_GYRO_BIAS_GATE_DEG_S 10
#endif

FW_STATIC_ASSERT(FW_CFG_CRICKET_LINE_MAX >= 32 && FW_CFG_CRICKET_LINE_MAX <= 1024, cricket_line_max);
FW_STATIC_ASSERT(FW_CFG_CRICKET_MAX_BEACONS >= 3 && FW_CFG_CRICKET_MAX_BEACONS <= 64, cricket_beacons);
FW_STATIC_ASSERT(FW_CFG_CRICKET_SPACE_MAX >= 1 && FW_CFG_CRICKET_SPACE_MAX <= 64, cricket_space);
FW_STATIC_ASSERT(FW_CFG_GYRO_MAX_DT_US >= 1000u, gyro_max_dt);
FW_STATIC_ASSERT(FW_CFG_GYRO_BIAS_SHIFT >= 1 && FW_CFG_GYRO_BIAS_SHIFT <= 12, gyro_bias_shift);
FW_STATIC_ASSERT(FW_CFG_GYRO_BIAS_GATE_DEG_S >= 1 && FW_CFG_GYRO_BIAS_GATE_DEG_S <= 300, gyro_bias_gate);

#endif // DRIVERS_CONFIG_H
