// SPDX-License-Identifier: MIT
// dynaqpc drivers: rolling counters and CRC shared by every frame (see can_link.h).
//
// Why a counter check on top of CAN's own CRC: CAN guarantees that a frame arrives intact, not
// that the sender is alive and producing new data. A sender stuck in a loop re-sending its last
// buffer passes every bus check; a counter that does not advance exposes it. Gaps tell lost
// frames (receive FIFO overruns, a busy sender) apart from silence.
#include "drivers/can_link.h"

#include <string.h>

#include "fw/fw_base.h"
#include "fw/fw_crc.h"

uint8_t can_link_crc8(uint32_t id, const uint8_t *data, size_t len)
{
    // The 11-bit id's two bytes, low first, then the payload: a frame copied under another id
    // fails the check.
    const uint8_t id_bytes[2] = {(uint8_t)(id & 0xFFu), (uint8_t)((id >> 8) & 0xFFu)};
    return fw_crc8(fw_crc8(0u, id_bytes, 2u), data, (uint32_t)len);
}

uint32_t can_link_crc32(uint32_t id, const uint8_t *data, size_t len)
{
    const uint8_t id_bytes[2] = {(uint8_t)(id & 0xFFu), (uint8_t)((id >> 8) & 0xFFu)};
    return fw_crc32(fw_crc32(0u, id_bytes, 2u), data, (uint32_t)len);
}

bool can_link_e2e_ok(const hal_can_frame_t *frame, unsigned crc_bits)
{
    if (frame->dlc == 0u || frame->dlc > 8u) {
        return false;
    }
    if (crc_bits != 8u) {
        return false;
    }
    return frame->data[frame->dlc - 1u] == can_link_crc8(frame->id, frame->data, frame->dlc - 1u);
}

void can_link_e2e_protect(hal_can_frame_t *frame, unsigned crc_bits)
{
    FW_ASSERT(crc_bits == 8u && frame->dlc > 0u && frame->dlc <= 8u);
    frame->data[frame->dlc - 1u] = can_link_crc8(frame->id, frame->data, frame->dlc - 1u);
}

// One check for all encoders: a pack that wrote another length than the frame's (a codec out of
// step with the DBC the frame was prepared from) must not leave a sealed frame that passes
// can_link_e2e_ok(). The encoders differ in their message only; this tail is the same.
int can_link_tx_seal(hal_can_frame_t *frame, int packed)
{
    if (packed != (int)frame->dlc) {
        return FW_ERR_INVAL;
    }
    can_link_e2e_protect(frame, 8u);
    return FW_OK;
}

void can_link_rx_init(can_link_rx_t *rx)
{
    FW_ASSERT(rx != NULL);
    memset(rx, 0, sizeof *rx);
}

bool can_link_frame_is(const hal_can_frame_t *frame, uint32_t id, uint8_t dlc)
{
    return frame->id == id && frame->dlc == dlc &&
           (frame->flags & (HAL_CAN_FLAG_EXTENDED | HAL_CAN_FLAG_REMOTE)) == 0u;
}

int can_link_rx_accept(can_link_rx_t *rx, uint8_t counter, uint64_t now_us)
{
    FW_ASSERT(rx != NULL);
    counter &= (uint8_t)(CAN_LINK_COUNTER_MOD - 1u);
    if (rx->seen) {
        uint8_t step = (uint8_t)((counter - rx->counter) & (CAN_LINK_COUNTER_MOD - 1u));
        if (step == 0u) {
            rx->repeated++;
            return FW_ERR_NOENT;
        }
        rx->lost += (uint32_t)(step - 1u);
    }
    rx->seen = true;
    rx->counter = counter;
    rx->frames++;
    rx->last_ok_us = now_us;
    return FW_OK;
}

int can_link_rx_accept_e2e(can_link_rx_t *rx, uint8_t counter, uint64_t now_us, uint8_t max_step)
{
    counter &= (uint8_t)(CAN_LINK_COUNTER_MOD - 1u);
    if (!rx->seen) {
        return can_link_rx_accept(rx, counter, now_us);
    }
    const uint8_t step = (uint8_t)((counter - rx->counter) & (CAN_LINK_COUNTER_MOD - 1u));
    if (step == 0u) {
        rx->repeated++;
        return FW_ERR_NOENT;
    }
    if (step <= max_step) {
        rx->sync_pending = false;
        return can_link_rx_accept(rx, counter, now_us);
    }
    if (rx->sync_pending && ((counter - rx->sync_counter) & (CAN_LINK_COUNTER_MOD - 1u)) == 1u) {
        // The sender jumped (a reboot, frames lost beyond the counter's reach): two frames in
        // sequence say so. What lay between is unknown: not counted as lost.
        rx->sync_pending = false;
        rx->seen = true;
        rx->counter = counter;
        rx->frames++;
        rx->last_ok_us = now_us;
        return CAN_LINK_RESYNC;
    }
    rx->sync_pending = true;
    rx->sync_counter = counter;
    if (rx->implausible < UINT16_MAX) {
        rx->implausible++;
    }
    return FW_ERR_INVAL;
}

int can_link_rx_reject(can_link_rx_t *rx)
{
    rx->malformed++;
    return FW_ERR_INVAL;
}

int can_link_rx_implausible(can_link_rx_t *rx)
{
    if (rx->implausible < UINT16_MAX) {
        rx->implausible++;
    }
    return FW_ERR_INVAL;
}

bool can_link_rx_silent(const can_link_rx_t *rx, uint64_t now_us, uint64_t max_age_us)
{
    if (!rx->seen) {
        return true;
    }
    return now_us > rx->last_ok_us && now_us - rx->last_ok_us > max_age_us;
}

uint8_t can_link_tx_counter_next(uint8_t *counter)
{
    FW_ASSERT(counter != NULL);
    uint8_t value = (uint8_t)(*counter & (CAN_LINK_COUNTER_MOD - 1u));
    *counter = (uint8_t)((value + 1u) & (CAN_LINK_COUNTER_MOD - 1u));
    return value;
}

void can_link_frame_prepare(hal_can_frame_t *frame, uint32_t id, uint8_t dlc)
{
    FW_ASSERT(frame != NULL && dlc <= 8u);
    memset(frame, 0, sizeof *frame);
    frame->id = id;
    frame->dlc = dlc;
}
