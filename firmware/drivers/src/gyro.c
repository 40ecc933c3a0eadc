// SPDX-License-Identifier: MIT
// dynaqpc drivers: gyro frames and heading integration (see gyro.h).
//
// Why integrate on receive stamps rather than on the nominal 16 ms: frames are lost and delayed
// on a busy bus, and the receive time is what the firmware actually knows. The trapezoid rule
// over the two end rates is exact for a rate that changes linearly between samples; a lost frame
// (counter gap) then costs accuracy only in proportion to how much the rate bent in between.
#include "drivers/gyro.h"

#include <string.h>

#include "drivers/drivers_config.h"
#include "dynaqpc_can.h"
#include "fw/fw_base.h"

static float wrap_deg(float deg)
{
    // Bounded: a heading is wrapped after every step, so one subtraction suffices in practice;
    // the loops only guard against a huge value given to gyro_set_heading.
    while (deg >= 360.0f) {
        deg -= 360.0f;
    }
    while (deg < 0.0f) {
        deg += 360.0f;
    }
    return deg;
}

void gyro_init(gyro_t *gyro)
{
    FW_ASSERT(gyro != NULL);
    memset(gyro, 0, sizeof *gyro);
    can_link_rx_init(&gyro->rx);
    gyro->period_us = (uint16_t)FW_CFG_GYRO_PERIOD_US;
}

void gyro_set_sample_period(gyro_t *gyro, uint16_t period_us)
{
    gyro->period_us = period_us;
}

int gyro_rx_rate(gyro_t *gyro, const hal_can_frame_t *frame, uint64_t now_us)
{
    FW_ASSERT(gyro != NULL && frame != NULL);
    struct dynaqpc_can_gyro_rate_t msg;
    if (!can_link_frame_is(frame, DYNAQPC_CAN_GYRO_RATE_FRAME_ID, DYNAQPC_CAN_GYRO_RATE_LENGTH) ||
        dynaqpc_can_gyro_rate_unpack(&msg, frame->data, frame->dlc) != 0 ||
        !can_link_e2e_ok(frame, 8u) ||
        !dynaqpc_can_gyro_rate_yaw_rate_is_in_range(msg.yaw_rate) ||
        !dynaqpc_can_gyro_rate_temperature_is_in_range(msg.temperature) ||
        !dynaqpc_can_gyro_rate_status_is_in_range(msg.status)) {
        return can_link_rx_reject(&gyro->rx);
    }
    // Samples since the last accepted one (more than 1 when frames were lost), by the counter.
    const uint32_t steps = gyro->rx.seen ? (uint32_t)((msg.counter - gyro->rx.counter) & (CAN_LINK_COUNTER_MOD - 1u)) : 1u;
    // No check of the rate's change: it changes by hundreds of deg/s in one sample when a turn
    // starts or a bump stops it (docs/can-protocol.md). The rate itself cannot exceed what the
    // wheels can turn the robot at (gyro_set_rate_limit).
    const int32_t limit = gyro->rate_limit_cdeg_s;
    if (limit != 0 && msg.status == GYRO_STATUS_OK && (msg.yaw_rate > limit || msg.yaw_rate < -limit)) {
        return can_link_rx_implausible(&gyro->rx);
    }
    const int err = can_link_rx_accept_e2e(&gyro->rx, msg.counter, now_us, GYRO_MAX_STEP);
    if (err < 0) {
        return err;
    }
    gyro->rate_cdeg_s = msg.yaw_rate;
    gyro->temperature_c = msg.temperature;
    gyro->status = msg.status;
    if (msg.status != GYRO_STATUS_OK) {
        gyro->have_prev = false;  // not usable; integrate again from the next good sample
        return FW_OK;
    }
    float rate = (float)msg.yaw_rate * 0.01f;
    if (gyro->stationary) {
        // "Stationary" is when the wheels were told to stop; the robot stops some time later
        // (on the emulated board the motor command crossed a serial line, a Python bridge and
        // the bus: ~20-60 ms at 190 deg/s). Learning from those samples made the bias several
        // deg/s wrong after every turn, and the heading drifted by that much per second
        // (85 degrees off on average over the board's first episode; docs/results/emulated-board.md).
        const float off = rate - gyro->bias_deg_s;
        if (off <= (float)FW_CFG_GYRO_BIAS_GATE_DEG_S && off >= -(float)FW_CFG_GYRO_BIAS_GATE_DEG_S) {
            gyro->bias_deg_s += off / (float)(1u << FW_CFG_GYRO_BIAS_SHIFT);
        } else {
            gyro->bias_rejected++;
        }
    }
    if (gyro->have_prev && now_us >= gyro->prev_us) {
        const uint64_t rx_dt_us = now_us - gyro->prev_us;
        uint64_t dt_us = rx_dt_us;
        bool bridged = err != CAN_LINK_RESYNC && rx_dt_us <= FW_CFG_GYRO_MAX_DT_US;
        if (gyro->period_us != 0u) {
            // The samples' own spacing decides: a frame delivered late by a stalled bridge or
            // host is no gap when the counter says no sample was lost. The receive times only
            // tell a silence too long for the counter to count (CAN_LINK_COUNTER_MOD periods).
            dt_us = (uint64_t)steps * gyro->period_us;
            bridged = err != CAN_LINK_RESYNC && dt_us <= FW_CFG_GYRO_MAX_DT_US &&
                      rx_dt_us < (uint64_t)CAN_LINK_COUNTER_MOD * gyro->period_us;
        }
        if (bridged) {
            float dt = (float)dt_us * 1e-6f;
            float mean = 0.5f * (gyro->prev_rate_deg_s + rate) - gyro->bias_deg_s;
            gyro->heading_deg = wrap_deg(gyro->heading_deg + mean * dt);
        } else {
            gyro->gaps++;
            // What the heading may have missed, if the rate stayed within its two ends.
            const float r0 = gyro->prev_rate_deg_s - gyro->bias_deg_s, r1 = rate - gyro->bias_deg_s;
            const float r0a = r0 < 0.0f ? -r0 : r0, r1a = r1 < 0.0f ? -r1 : r1;
            gyro->gap_bound_deg = (r0a > r1a ? r0a : r1a) * ((float)rx_dt_us * 1e-6f);
        }
    }
    gyro->have_prev = true;
    gyro->prev_rate_deg_s = rate;
    gyro->prev_us = now_us;
    return FW_OK;
}

void gyro_set_rate_limit(gyro_t *gyro, uint16_t limit_cdeg_s)
{
    gyro->rate_limit_cdeg_s = limit_cdeg_s;
}

void gyro_set_heading(gyro_t *gyro, float heading_deg)
{
    if (heading_deg > 1e6f || heading_deg < -1e6f || heading_deg != heading_deg) {
        heading_deg = 0.0f;  // NaN or absurd: refuse to loop on it
    }
    gyro->heading_deg = wrap_deg(heading_deg);
}

float gyro_heading_deg(const gyro_t *gyro)
{
    return gyro->heading_deg;
}

void gyro_set_stationary(gyro_t *gyro, bool stationary)
{
    gyro->stationary = stationary;
}

int gyro_encode_rate(uint8_t *counter, int16_t rate_cdeg_s, int8_t temperature_c, uint8_t status,
                     hal_can_frame_t *out)
{
    FW_ASSERT(counter != NULL && out != NULL);
    struct dynaqpc_can_gyro_rate_t msg;
    memset(&msg, 0, sizeof msg);
    msg.yaw_rate = rate_cdeg_s;
    msg.temperature = temperature_c;
    msg.status = status;
    if (!dynaqpc_can_gyro_rate_yaw_rate_is_in_range(msg.yaw_rate) ||
        !dynaqpc_can_gyro_rate_temperature_is_in_range(msg.temperature) ||
        !dynaqpc_can_gyro_rate_status_is_in_range(msg.status)) {
        return FW_ERR_INVAL;
    }
    msg.counter = can_link_tx_counter_next(counter);
    msg.crc = 0u;
    can_link_frame_prepare(out, DYNAQPC_CAN_GYRO_RATE_FRAME_ID, DYNAQPC_CAN_GYRO_RATE_LENGTH);
    return can_link_tx_seal(out, dynaqpc_can_gyro_rate_pack(out->data, &msg, sizeof out->data));
}
