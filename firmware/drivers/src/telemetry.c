// SPDX-License-Identifier: MIT
// dynaqpc drivers: telemetry, heartbeat and operator command frames (see telemetry.h).
//
// Telemetry saturates instead of refusing: a value too large for its signal is still worth
// reporting as "at least this much", and a monitor must never lose a period's frame because one
// number overflowed. The saturation limits come from the DBC (documented there per signal).
#include "drivers/telemetry.h"

#include <math.h>
#include <string.h>

#include "dynaqpc_can.h"
#include "fw/fw_base.h"
#include "fw/fw_util.h"

static uint32_t min_u32(uint32_t v, uint32_t hi)
{
    return v > hi ? hi : v;
}

void tlm_init(tlm_t *tlm)
{
    FW_ASSERT(tlm != NULL);
    memset(tlm, 0, sizeof *tlm);
    can_link_rx_init(&tlm->tool_rx);
}

void tlm_encode_pose(tlm_t *tlm, const tlm_pose_t *pose, hal_can_frame_t *out)
{
    FW_ASSERT(tlm != NULL && pose != NULL && out != NULL);
    struct dynaqpc_can_tlm_pose_t m;
    int32_t h = pose->heading_cdeg % 36000;
    m.x = (int16_t)fw_clamp_i32(pose->x_mm, INT16_MIN, INT16_MAX);
    m.y = (int16_t)fw_clamp_i32(pose->y_mm, INT16_MIN, INT16_MAX);
    m.heading = (uint16_t)(h < 0 ? h + 36000 : h);
    m.fix_state = pose->fix_state > TLM_FIX_LOST ? (uint8_t)TLM_FIX_LOST : pose->fix_state;
    m.counter = can_link_tx_counter_next(&tlm->pose_counter);
    can_link_frame_prepare(out, DYNAQPC_CAN_TLM_POSE_FRAME_ID, DYNAQPC_CAN_TLM_POSE_LENGTH);
    (void)dynaqpc_can_tlm_pose_pack(out->data, &m, sizeof out->data);
}

void tlm_encode_learn(tlm_t *tlm, const tlm_learn_t *learn, hal_can_frame_t *out)
{
    FW_ASSERT(tlm != NULL && learn != NULL && out != NULL);
    struct dynaqpc_can_tlm_learn_t m;
    m.state = min_u32(learn->state, 0xFFFFFFu);
    m.action = (uint8_t)min_u32(learn->action, 15u);
    m.reward = (int8_t)fw_clamp_i32(learn->reward, INT8_MIN, INT8_MAX);
    m.episode = (uint16_t)(learn->episode & 0x7FFu);
    m.step = (uint16_t)min_u32(learn->step, 8191u);
    m.counter = can_link_tx_counter_next(&tlm->learn_counter);
    can_link_frame_prepare(out, DYNAQPC_CAN_TLM_LEARN_FRAME_ID, DYNAQPC_CAN_TLM_LEARN_LENGTH);
    (void)dynaqpc_can_tlm_learn_pack(out->data, &m, sizeof out->data);
}

void tlm_encode_sched(tlm_t *tlm, const tlm_sched_t *sched, hal_can_frame_t *out)
{
    FW_ASSERT(tlm != NULL && sched != NULL && out != NULL);
    struct dynaqpc_can_tlm_sched_t m;
    m.plan_updates = (uint16_t)min_u32(sched->plan_updates, 0xFFFFu);
    m.deadline_misses = (uint16_t)(sched->deadline_misses & 0xFFFFu);
    m.idle_percent = (uint8_t)((min_u32(sched->idle_permille, 1000u) + 2u) / 5u);  // 0.5 % steps
    m.queue_length = (uint16_t)min_u32(sched->queue_length, 0xFFFFu);
    m.counter = can_link_tx_counter_next(&tlm->sched_counter);
    can_link_frame_prepare(out, DYNAQPC_CAN_TLM_SCHED_FRAME_ID, DYNAQPC_CAN_TLM_SCHED_LENGTH);
    (void)dynaqpc_can_tlm_sched_pack(out->data, &m, sizeof out->data);
}

void tlm_encode_value(tlm_t *tlm, const tlm_value_t *value, hal_can_frame_t *out)
{
    FW_ASSERT(tlm != NULL && value != NULL && out != NULL);
    struct dynaqpc_can_tlm_value_t m;
    const float v = value->value * 10.0f;
    int32_t raw = 0;
    if (v >= 32767.0f) {
        raw = 32767;
    } else if (v <= -32768.0f) {
        raw = -32768;
    } else if (v == v) {  // NaN as 0
        raw = (int32_t)lrintf(v);
    }
    m.state = min_u32(value->state, 0xFFFFFFu);
    m.action = (uint8_t)min_u32(value->action, 15u);
    m.value = (int16_t)raw;
    m.aliasing = value->aliasing;
    m.counter = can_link_tx_counter_next(&tlm->value_counter);
    can_link_frame_prepare(out, DYNAQPC_CAN_TLM_VALUE_FRAME_ID, DYNAQPC_CAN_TLM_VALUE_LENGTH);
    (void)dynaqpc_can_tlm_value_pack(out->data, &m, sizeof out->data);
}

void tlm_encode_episode(const tlm_episode_t *episode, hal_can_frame_t *out)
{
    FW_ASSERT(episode != NULL && out != NULL);
    struct dynaqpc_can_tlm_episode_t m;
    m.episode = (uint16_t)(episode->episode & 0xFFFFu);
    m.steps = (uint16_t)min_u32(episode->steps, 0x7FFFu);
    m.interrupted = episode->interrupted ? 1u : 0u;
    m.total_reward = fw_clamp_i32(episode->total_reward, -524288, 524287);
    m.reached_goal = episode->reached_goal ? 1u : 0u;
    m.bumps = (uint16_t)min_u32(episode->bumps, 2047u);
    can_link_frame_prepare(out, DYNAQPC_CAN_TLM_EPISODE_FRAME_ID, DYNAQPC_CAN_TLM_EPISODE_LENGTH);
    (void)dynaqpc_can_tlm_episode_pack(out->data, &m, sizeof out->data);
}

void tlm_encode_status(tlm_t *tlm, const tlm_status_t *status, hal_can_frame_t *out)
{
    FW_ASSERT(tlm != NULL && status != NULL && out != NULL);
    struct dynaqpc_can_fw_status_t m;
    uint8_t e = status->errors;
    m.mode = (uint8_t)min_u32(status->mode, TLM_MODE_FAULT);
    m.err_motor_silent = (e & TLM_ERR_MOTOR_SILENT) ? 1u : 0u;
    m.err_gyro_silent = (e & TLM_ERR_GYRO_SILENT) ? 1u : 0u;
    m.err_range_silent = (e & TLM_ERR_RANGE_SILENT) ? 1u : 0u;
    m.err_pose_lost = (e & TLM_ERR_POSE_LOST) ? 1u : 0u;
    m.err_can_bus = (e & TLM_ERR_CAN_BUS) ? 1u : 0u;
    m.err_uart = (e & TLM_ERR_UART) ? 1u : 0u;
    m.err_flash = (e & TLM_ERR_FLASH) ? 1u : 0u;
    m.err_deadline_miss = (e & TLM_ERR_DEADLINE_MISS) ? 1u : 0u;
    m.uptime = status->uptime_s;
    m.pose_trusted = status->pose_trusted ? 1u : 0u;
    m.trust_reason = (uint8_t)min_u32(status->trust_reason, TLM_TRUST_ABSOLUTE);
    m.reset_cause = (uint8_t)min_u32(status->reset_cause, 4u);
    m.boot_count = (uint8_t)(status->boot_count & 0xFFu);
    m.counter = can_link_tx_counter_next(&tlm->status_counter);
    can_link_frame_prepare(out, DYNAQPC_CAN_FW_STATUS_FRAME_ID, DYNAQPC_CAN_FW_STATUS_LENGTH);
    (void)dynaqpc_can_fw_status_pack(out->data, &m, sizeof out->data);
}

void tlm_encode_ack(const tlm_ack_t *ack, hal_can_frame_t *out)
{
    FW_ASSERT(ack != NULL && out != NULL);
    struct dynaqpc_can_tool_ack_t m;
    m.command = ack->command;
    m.counter = (uint8_t)(ack->counter & 0x0Fu);
    m.result = (uint8_t)min_u32(ack->result, TLM_ACK_FAILED);
    m.reason = (uint8_t)min_u32(ack->reason, TLM_WHY_DEVICE_SILENT);
    m.sequence = min_u32(ack->sequence, 0xFFFFFFu);
    m.episodes = (uint16_t)min_u32(ack->episodes, 0xFFFFu);
    can_link_frame_prepare(out, DYNAQPC_CAN_TOOL_ACK_FRAME_ID, DYNAQPC_CAN_TOOL_ACK_LENGTH);
    (void)dynaqpc_can_tool_ack_pack(out->data, &m, sizeof out->data);
}

int tlm_rx_tool_cmd(tlm_t *tlm, const hal_can_frame_t *frame, uint64_t now_us, tlm_tool_cmd_t *out)
{
    FW_ASSERT(tlm != NULL && frame != NULL && out != NULL);
    struct dynaqpc_can_tool_cmd_t m;
    if (!can_link_frame_is(frame, DYNAQPC_CAN_TOOL_CMD_FRAME_ID, DYNAQPC_CAN_TOOL_CMD_LENGTH) ||
        dynaqpc_can_tool_cmd_unpack(&m, frame->data, frame->dlc) != 0 ||
        m.crc != can_link_crc32(frame->id, frame->data, frame->dlc - 4u) ||
        !dynaqpc_can_tool_cmd_command_is_in_range(m.command)) {
        return can_link_rx_reject(&tlm->tool_rx);
    }
    // Commands are not periodic: a counter gap is not a loss, only a repeat matters.
    if (tlm->tool_rx.seen && m.counter == tlm->tool_rx.counter) {
        tlm->tool_rx.repeated++;
        return FW_ERR_NOENT;
    }
    tlm->tool_rx.seen = true;
    tlm->tool_rx.counter = m.counter;
    tlm->tool_rx.frames++;
    tlm->tool_rx.last_ok_us = now_us;
    out->command = m.command;
    out->argument = m.argument;
    return FW_OK;
}

int tlm_encode_tool_cmd(uint8_t *counter, const tlm_tool_cmd_t *cmd, hal_can_frame_t *out)
{
    struct dynaqpc_can_tool_cmd_t m;
    if (!dynaqpc_can_tool_cmd_command_is_in_range(cmd->command)) {
        return FW_ERR_INVAL;
    }
    m.command = cmd->command;
    m.argument = cmd->argument > 0xFFFFFFu ? 0xFFFFFFu : cmd->argument;  // 0xFFFFFF: "none"
    m.counter = can_link_tx_counter_next(counter);
    m.crc = 0u;
    can_link_frame_prepare(out, DYNAQPC_CAN_TOOL_CMD_FRAME_ID, DYNAQPC_CAN_TOOL_CMD_LENGTH);
    (void)dynaqpc_can_tool_cmd_pack(out->data, &m, sizeof out->data);
    const uint32_t crc = can_link_crc32(out->id, out->data, out->dlc - 4u);
    out->data[4] = (uint8_t)crc;
    out->data[5] = (uint8_t)(crc >> 8);
    out->data[6] = (uint8_t)(crc >> 16);
    out->data[7] = (uint8_t)(crc >> 24);
    return FW_OK;
}

int tlm_decode_pose(const hal_can_frame_t *frame, tlm_pose_t *out)
{
    struct dynaqpc_can_tlm_pose_t m;
    if (!can_link_frame_is(frame, DYNAQPC_CAN_TLM_POSE_FRAME_ID, DYNAQPC_CAN_TLM_POSE_LENGTH) ||
        dynaqpc_can_tlm_pose_unpack(&m, frame->data, frame->dlc) != 0 ||
        !dynaqpc_can_tlm_pose_heading_is_in_range(m.heading)) {
        return FW_ERR_INVAL;
    }
    out->x_mm = m.x;
    out->y_mm = m.y;
    out->heading_cdeg = m.heading;
    out->fix_state = m.fix_state;
    return FW_OK;
}

int tlm_decode_learn(const hal_can_frame_t *frame, tlm_learn_t *out)
{
    struct dynaqpc_can_tlm_learn_t m;
    if (!can_link_frame_is(frame, DYNAQPC_CAN_TLM_LEARN_FRAME_ID, DYNAQPC_CAN_TLM_LEARN_LENGTH) ||
        dynaqpc_can_tlm_learn_unpack(&m, frame->data, frame->dlc) != 0) {
        return FW_ERR_INVAL;
    }
    out->state = m.state;
    out->action = m.action;
    out->reward = m.reward;
    out->episode = m.episode;
    out->step = m.step;
    return FW_OK;
}

int tlm_decode_sched(const hal_can_frame_t *frame, tlm_sched_t *out)
{
    struct dynaqpc_can_tlm_sched_t m;
    if (!can_link_frame_is(frame, DYNAQPC_CAN_TLM_SCHED_FRAME_ID, DYNAQPC_CAN_TLM_SCHED_LENGTH) ||
        dynaqpc_can_tlm_sched_unpack(&m, frame->data, frame->dlc) != 0 ||
        !dynaqpc_can_tlm_sched_idle_percent_is_in_range(m.idle_percent)) {
        return FW_ERR_INVAL;
    }
    out->plan_updates = m.plan_updates;
    out->deadline_misses = m.deadline_misses;
    out->idle_permille = (uint32_t)m.idle_percent * 5u;
    out->queue_length = m.queue_length;
    return FW_OK;
}

int tlm_decode_episode(const hal_can_frame_t *frame, tlm_episode_t *out)
{
    struct dynaqpc_can_tlm_episode_t m;
    if (!can_link_frame_is(frame, DYNAQPC_CAN_TLM_EPISODE_FRAME_ID, DYNAQPC_CAN_TLM_EPISODE_LENGTH) ||
        dynaqpc_can_tlm_episode_unpack(&m, frame->data, frame->dlc) != 0) {
        return FW_ERR_INVAL;
    }
    out->episode = m.episode;
    out->steps = m.steps;
    out->total_reward = m.total_reward;
    out->reached_goal = m.reached_goal != 0u;
    out->bumps = m.bumps;
    out->interrupted = m.interrupted != 0u;
    return FW_OK;
}

int tlm_decode_status(const hal_can_frame_t *frame, tlm_status_t *out)
{
    struct dynaqpc_can_fw_status_t m;
    if (!can_link_frame_is(frame, DYNAQPC_CAN_FW_STATUS_FRAME_ID, DYNAQPC_CAN_FW_STATUS_LENGTH) ||
        dynaqpc_can_fw_status_unpack(&m, frame->data, frame->dlc) != 0 ||
        !dynaqpc_can_fw_status_mode_is_in_range(m.mode) ||
        !dynaqpc_can_fw_status_trust_reason_is_in_range(m.trust_reason) ||
        !dynaqpc_can_fw_status_reset_cause_is_in_range(m.reset_cause)) {
        return FW_ERR_INVAL;
    }
    out->mode = m.mode;
    out->errors = (uint8_t)((m.err_motor_silent ? TLM_ERR_MOTOR_SILENT : 0u) |
                            (m.err_gyro_silent ? TLM_ERR_GYRO_SILENT : 0u) |
                            (m.err_range_silent ? TLM_ERR_RANGE_SILENT : 0u) |
                            (m.err_pose_lost ? TLM_ERR_POSE_LOST : 0u) |
                            (m.err_can_bus ? TLM_ERR_CAN_BUS : 0u) | (m.err_uart ? TLM_ERR_UART : 0u) |
                            (m.err_flash ? TLM_ERR_FLASH : 0u) |
                            (m.err_deadline_miss ? TLM_ERR_DEADLINE_MISS : 0u));
    out->uptime_s = m.uptime;
    out->pose_trusted = m.pose_trusted != 0u;
    out->trust_reason = m.trust_reason;
    out->reset_cause = m.reset_cause;
    out->boot_count = m.boot_count;
    return FW_OK;
}

int tlm_decode_ack(const hal_can_frame_t *frame, tlm_ack_t *out)
{
    struct dynaqpc_can_tool_ack_t m;
    if (!can_link_frame_is(frame, DYNAQPC_CAN_TOOL_ACK_FRAME_ID, DYNAQPC_CAN_TOOL_ACK_LENGTH) ||
        dynaqpc_can_tool_ack_unpack(&m, frame->data, frame->dlc) != 0 ||
        !dynaqpc_can_tool_ack_result_is_in_range(m.result) ||
        !dynaqpc_can_tool_ack_reason_is_in_range(m.reason)) {
        return FW_ERR_INVAL;
    }
    out->command = m.command;
    out->counter = m.counter;
    out->result = m.result;
    out->reason = m.reason;
    out->sequence = m.sequence;
    out->episodes = m.episodes;
    return FW_OK;
}

int tlm_decode_value(const hal_can_frame_t *frame, tlm_value_t *out)
{
    struct dynaqpc_can_tlm_value_t m;
    if (!can_link_frame_is(frame, DYNAQPC_CAN_TLM_VALUE_FRAME_ID, DYNAQPC_CAN_TLM_VALUE_LENGTH) ||
        dynaqpc_can_tlm_value_unpack(&m, frame->data, frame->dlc) != 0) {
        return FW_ERR_INVAL;
    }
    out->state = m.state;
    out->action = m.action;
    out->value = (float)m.value * 0.1f;
    out->aliasing = m.aliasing;
    return FW_OK;
}
