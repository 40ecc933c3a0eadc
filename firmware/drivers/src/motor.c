// SPDX-License-Identifier: MIT
// dynaqpc drivers: the motor controller's frames (see motor.h).
//
// The pack/unpack of each frame is the code cantools generates from docs/dynaqpc.dbc
// (src/generated/dynaqpc_can.c); this file adds what a DBC cannot say: which values are refused,
// the counter and CRC, and the conversion to the structs the application uses. Ranges are
// checked with the generated *_is_in_range() functions so that the limits live in the DBC only.
#include "drivers/motor.h"

#include <string.h>

#include "dynaqpc_can.h"
#include "fw/fw_base.h"

void motor_init(motor_t *motor)
{
    FW_ASSERT(motor != NULL);
    memset(motor, 0, sizeof *motor);
    can_link_rx_init(&motor->rx);
    motor->peak_prev = -1;
}

int32_t motor_cmd_peak_mm_s(const motor_t *motor)
{
    FW_ASSERT(motor != NULL);
    if (motor->peak_prev < 0) {
        return -1;
    }
    return motor->peak_now > motor->peak_prev ? motor->peak_now : motor->peak_prev;
}

static int32_t abs_(int32_t v)
{
    return v < 0 ? -v : v;
}

// A measured speed no wheel driven by the recent commands reaches (motor.h).
static bool implausible_(const motor_t *motor, int32_t left, int32_t right)
{
    const int32_t peak = motor_cmd_peak_mm_s(motor);
    if (peak < 0) {
        return false;
    }
    const int32_t limit = peak + peak / 2 + MOTOR_PLAUSIBLE_SLACK_MM_S;
    return abs_(left) > limit || abs_(right) > limit;
}

int motor_rx_status(motor_t *motor, const hal_can_frame_t *frame, uint64_t now_us)
{
    FW_ASSERT(motor != NULL && frame != NULL);
    struct dynaqpc_can_motor_status_t msg;
    if (!can_link_frame_is(frame, DYNAQPC_CAN_MOTOR_STATUS_FRAME_ID, DYNAQPC_CAN_MOTOR_STATUS_LENGTH) ||
        dynaqpc_can_motor_status_unpack(&msg, frame->data, frame->dlc) != 0 || !can_link_e2e_ok(frame, 8u) ||
        !dynaqpc_can_motor_status_speed_left_is_in_range(msg.speed_left) ||
        !dynaqpc_can_motor_status_speed_right_is_in_range(msg.speed_right)) {
        return can_link_rx_reject(&motor->rx);
    }
    if (implausible_(motor, msg.speed_left, msg.speed_right)) {
        return can_link_rx_implausible(&motor->rx);
    }
    const int err = can_link_rx_accept_e2e(&motor->rx, msg.counter, now_us, CAN_LINK_MAX_STEP);
    if (err < 0) {
        return err;
    }
    motor_status_t *s = &motor->status;
    s->speed_left_mm_s = msg.speed_left;
    s->speed_right_mm_s = msg.speed_right;
    s->bump_front = msg.bump_front != 0u;
    s->bump_rear = msg.bump_rear != 0u;
    s->enabled = msg.enabled != 0u;
    s->faults = (uint8_t)((msg.fault_over_current ? MOTOR_FAULT_OVERCURRENT : 0u) |
                          (msg.fault_stall ? MOTOR_FAULT_STALL : 0u) |
                          (msg.fault_under_voltage ? MOTOR_FAULT_UNDERVOLTAGE : 0u) |
                          (msg.fault_cmd_timeout ? MOTOR_FAULT_CMD_TIMEOUT : 0u));
    return FW_OK;
}

int motor_encode_cmd(motor_t *motor, const motor_cmd_t *cmd, hal_can_frame_t *out)
{
    FW_ASSERT(motor != NULL && cmd != NULL && out != NULL);
    struct dynaqpc_can_motor_cmd_t msg;
    memset(&msg, 0, sizeof msg);
    msg.speed_left = cmd->speed_left_mm_s;
    msg.speed_right = cmd->speed_right_mm_s;
    msg.enable = cmd->enable ? 1u : 0u;
    if (!dynaqpc_can_motor_cmd_speed_left_is_in_range(msg.speed_left) ||
        !dynaqpc_can_motor_cmd_speed_right_is_in_range(msg.speed_right)) {
        return FW_ERR_INVAL;
    }
    msg.counter = can_link_tx_counter_next(&motor->tx_counter);
    can_link_frame_prepare(out, DYNAQPC_CAN_MOTOR_CMD_FRAME_ID, DYNAQPC_CAN_MOTOR_CMD_LENGTH);
    const int err = can_link_tx_seal(out, dynaqpc_can_motor_cmd_pack(out->data, &msg, sizeof out->data));
    if (err != FW_OK) {
        return err;
    }
    const int32_t l = abs_(msg.speed_left), r = abs_(msg.speed_right);
    const int16_t fastest = (int16_t)(l > r ? l : r);
    motor->peak_now = fastest > motor->peak_now ? fastest : motor->peak_now;
    if (++motor->peak_cmds >= MOTOR_PEAK_CMDS) {
        motor->peak_prev = motor->peak_now;
        motor->peak_now = 0;
        motor->peak_cmds = 0;
    }
    return FW_OK;
}

int motor_encode_status(uint8_t *counter, const motor_status_t *status, hal_can_frame_t *out)
{
    FW_ASSERT(counter != NULL && status != NULL && out != NULL);
    struct dynaqpc_can_motor_status_t msg;
    memset(&msg, 0, sizeof msg);
    msg.speed_left = status->speed_left_mm_s;
    msg.speed_right = status->speed_right_mm_s;
    msg.bump_front = status->bump_front ? 1u : 0u;
    msg.bump_rear = status->bump_rear ? 1u : 0u;
    msg.enabled = status->enabled ? 1u : 0u;
    msg.fault_over_current = (status->faults & MOTOR_FAULT_OVERCURRENT) ? 1u : 0u;
    msg.fault_stall = (status->faults & MOTOR_FAULT_STALL) ? 1u : 0u;
    msg.fault_under_voltage = (status->faults & MOTOR_FAULT_UNDERVOLTAGE) ? 1u : 0u;
    msg.fault_cmd_timeout = (status->faults & MOTOR_FAULT_CMD_TIMEOUT) ? 1u : 0u;
    if (!dynaqpc_can_motor_status_speed_left_is_in_range(msg.speed_left) ||
        !dynaqpc_can_motor_status_speed_right_is_in_range(msg.speed_right)) {
        return FW_ERR_INVAL;
    }
    msg.counter = can_link_tx_counter_next(counter);
    can_link_frame_prepare(out, DYNAQPC_CAN_MOTOR_STATUS_FRAME_ID, DYNAQPC_CAN_MOTOR_STATUS_LENGTH);
    return can_link_tx_seal(out, dynaqpc_can_motor_status_pack(out->data, &msg, sizeof out->data));
}

int motor_decode_cmd(const hal_can_frame_t *frame, motor_cmd_t *out, uint8_t *counter_out)
{
    FW_ASSERT(frame != NULL && out != NULL);
    struct dynaqpc_can_motor_cmd_t msg;
    if (!can_link_frame_is(frame, DYNAQPC_CAN_MOTOR_CMD_FRAME_ID, DYNAQPC_CAN_MOTOR_CMD_LENGTH) ||
        dynaqpc_can_motor_cmd_unpack(&msg, frame->data, frame->dlc) != 0 ||
        !can_link_e2e_ok(frame, 8u) ||
        !dynaqpc_can_motor_cmd_speed_left_is_in_range(msg.speed_left) ||
        !dynaqpc_can_motor_cmd_speed_right_is_in_range(msg.speed_right)) {
        return FW_ERR_INVAL;
    }
    out->speed_left_mm_s = msg.speed_left;
    out->speed_right_mm_s = msg.speed_right;
    out->enable = msg.enable != 0u;
    if (counter_out != NULL) {
        *counter_out = msg.counter;
    }
    return FW_OK;
}

int motor_rx_cmd(can_link_rx_t *rx, const hal_can_frame_t *frame, uint64_t now_us, motor_cmd_t *out)
{
    motor_cmd_t cmd;
    uint8_t counter;
    if (motor_decode_cmd(frame, &cmd, &counter) != FW_OK) {
        return can_link_rx_reject(rx);
    }
    const int err = can_link_rx_accept_e2e(rx, counter, now_us, CAN_LINK_MAX_STEP);
    if (err < 0) {
        return err;
    }
    *out = cmd;
    return FW_OK;
}
