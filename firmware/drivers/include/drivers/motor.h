// SPDX-License-Identifier: MIT
// dynaqpc drivers: the motor controller (MOTOR_CMD out, MOTOR_STATUS in; docs/dynaqpc.dbc).
//
// Firmware side: motor_rx_status() decodes MOTOR_STATUS into motor_t; motor_encode_cmd() builds
// MOTOR_CMD with its counter and CRC. Send MOTOR_CMD every control period: the controller stops
// the wheels after MOTOR_CMD_TIMEOUT_MS without a valid one.
// Device side (simulator, bench tools): motor_encode_status(), motor_decode_cmd().
// Context: one thread; nothing blocks; no function keeps a pointer it was given.
#ifndef DRIVERS_MOTOR_H
#define DRIVERS_MOTOR_H

#include <stdbool.h>
#include <stdint.h>

#include "drivers/can_link.h"
#include "hal/hal_can.h"

#ifdef __cplusplus
extern "C" {
#endif

#define MOTOR_CMD_TIMEOUT_MS 500u    ///< the controller's safety timeout on MOTOR_CMD
#define MOTOR_CMD_SPEED_MAX 1500     ///< |speed target| limit of MOTOR_CMD, mm/s
#define MOTOR_STATUS_SPEED_MAX 2000  ///< |measured speed| limit of MOTOR_STATUS, mm/s
/// MOTOR_STATUS's plausibility against the firmware's own commands (motor_encode_cmd): a wheel
/// turns no faster than the fastest target of the last MOTOR_PEAK_CMDS to 2 x MOTOR_PEAK_CMDS - 1
/// commands (a stop's run-down included: 4 commands are 0.77 s at the paper's 192 ms) by more
/// than half of it again plus MOTOR_PLAUSIBLE_SLACK_MM_S (noise, a wheel that does not match, a
/// push). Checked once MOTOR_PEAK_CMDS commands were built since motor_init.
#define MOTOR_PEAK_CMDS 4u
#define MOTOR_PLAUSIBLE_SLACK_MM_S 150

/// motor_status_t.faults bits (MOTOR_STATUS Fault* signals).
#define MOTOR_FAULT_OVERCURRENT 0x01u
#define MOTOR_FAULT_STALL 0x02u
#define MOTOR_FAULT_UNDERVOLTAGE 0x04u
#define MOTOR_FAULT_CMD_TIMEOUT 0x08u

typedef struct motor_status {
    int16_t speed_left_mm_s;  ///< measured, positive forward
    int16_t speed_right_mm_s;
    bool bump_front;
    bool bump_rear;
    bool enabled;             ///< the wheels are driven
    uint8_t faults;           ///< MOTOR_FAULT_* bits
} motor_status_t;

typedef struct motor_cmd {
    int16_t speed_left_mm_s;  ///< target, -MOTOR_CMD_SPEED_MAX..MOTOR_CMD_SPEED_MAX
    int16_t speed_right_mm_s;
    bool enable;
} motor_cmd_t;

/// The firmware's view of the motor controller.
typedef struct motor {
    motor_status_t status;  ///< last accepted MOTOR_STATUS
    can_link_rx_t rx;       ///< MOTOR_STATUS bookkeeping (silence: rx.last_ok_us)
    uint8_t tx_counter;     ///< next MOTOR_CMD counter
    uint8_t peak_cmds;      ///< commands in the current run of MOTOR_PEAK_CMDS
    int16_t peak_now;       ///< the fastest |target| of the current run, mm/s
    int16_t peak_prev;      ///< of the run before it; -1 until one run is complete
} motor_t;

void motor_init(motor_t *motor);

/// Decodes a MOTOR_STATUS frame received at `now_us` into motor->status.
/// Returns FW_OK, FW_ERR_INVAL (not a well-formed MOTOR_STATUS: wrong id/dlc/flags, a Crc that
/// fails, a speed out of range, counted in rx.malformed; or implausible: a counter jump over
/// CAN_LINK_MAX_STEP, or a speed beyond what the recent commands allow (MOTOR_PEAK_CMDS),
/// counted in rx.implausible; status unchanged) or FW_ERR_NOENT (counter repeated).
int motor_rx_status(motor_t *motor, const hal_can_frame_t *frame, uint64_t now_us);

/// The fastest |speed target| of the recent commands (MOTOR_PEAK_CMDS), mm/s, or -1 before
/// MOTOR_PEAK_CMDS commands were built.
int32_t motor_cmd_peak_mm_s(const motor_t *motor);

/// Builds the next MOTOR_CMD into `out`. Returns FW_OK or FW_ERR_INVAL (a speed beyond
/// ±MOTOR_CMD_SPEED_MAX: nothing built, the counter does not advance).
int motor_encode_cmd(motor_t *motor, const motor_cmd_t *cmd, hal_can_frame_t *out);

/// Device side: builds MOTOR_STATUS with counter `*counter` (advanced). FW_OK or FW_ERR_INVAL.
int motor_encode_status(uint8_t *counter, const motor_status_t *status, hal_can_frame_t *out);

/// Device side: decodes MOTOR_CMD. Returns FW_OK, or FW_ERR_INVAL (malformed, out of range or
/// CRC mismatch: the controller ignores it). `counter_out` may be NULL.
int motor_decode_cmd(const hal_can_frame_t *frame, motor_cmd_t *out, uint8_t *counter_out);

/// Device side: what a motor controller takes of MOTOR_CMD: motor_decode_cmd() and then the
/// counter's plausibility on `rx` (can_link_rx_accept_e2e: a repeated counter, a stuck sender, is
/// FW_ERR_NOENT; a jump over CAN_LINK_MAX_STEP is FW_ERR_INVAL until the next frame in sequence).
/// FW_OK (act on *out) or an error (ignore the frame; the safety timeout runs on).
int motor_rx_cmd(can_link_rx_t *rx, const hal_can_frame_t *frame, uint64_t now_us, motor_cmd_t *out);

#ifdef __cplusplus
}
#endif

#endif // DRIVERS_MOTOR_H
