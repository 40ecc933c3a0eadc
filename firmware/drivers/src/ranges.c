// SPDX-License-Identifier: MIT
// dynaqpc drivers: IR and sonar frames (see ranges.h).
//
// The sonar frames pack 8 sonars of 7 bits (2 cm per bit) so that a counter fits in the 8 bytes:
// 1 cm resolution would buy nothing, as the paper's state uses 4 bits of sonar. The 4 bits left
// carry the end-to-end check, a CRC-4 (the IR frame has a whole byte for its CRC-8).
#include "drivers/ranges.h"

#include <string.h>

#include "dynaqpc_can.h"
#include "fw/fw_base.h"

#define SONAR_RAW_NO_ECHO 127u
#define SONAR_MM_PER_BIT 20u

void ranges_init(ranges_t *ranges)
{
    FW_ASSERT(ranges != NULL);
    memset(ranges, 0, sizeof *ranges);
    for (unsigned i = 0; i < RANGES_SONAR_COUNT; i++) {
        ranges->sonar_mm[i] = RANGES_NO_ECHO;
    }
    can_link_rx_init(&ranges->ir_rx);
    can_link_rx_init(&ranges->sonar_rx[0]);
    can_link_rx_init(&ranges->sonar_rx[1]);
}

int ranges_rx_ir(ranges_t *ranges, const hal_can_frame_t *frame, uint64_t now_us)
{
    FW_ASSERT(ranges != NULL && frame != NULL);
    struct dynaqpc_can_ir_ranges_t msg;
    if (!can_link_frame_is(frame, DYNAQPC_CAN_IR_RANGES_FRAME_ID, DYNAQPC_CAN_IR_RANGES_LENGTH) ||
        dynaqpc_can_ir_ranges_unpack(&msg, frame->data, frame->dlc) != 0 || !can_link_e2e_ok(frame, 8u) ||
        !dynaqpc_can_ir_ranges_range_left_is_in_range(msg.range_left) ||
        !dynaqpc_can_ir_ranges_range_front_is_in_range(msg.range_front) ||
        !dynaqpc_can_ir_ranges_range_right_is_in_range(msg.range_right)) {
        return can_link_rx_reject(&ranges->ir_rx);
    }
    const int err = can_link_rx_accept_e2e(&ranges->ir_rx, msg.counter, now_us, CAN_LINK_MAX_STEP);
    if (err < 0) {
        return err;
    }
    ranges->ir_mm[RANGES_IR_LEFT] = msg.range_left;
    ranges->ir_mm[RANGES_IR_FRONT] = msg.range_front;
    ranges->ir_mm[RANGES_IR_RIGHT] = msg.range_right;
    ranges->ir_valid[RANGES_IR_LEFT] = msg.valid_left != 0u;
    ranges->ir_valid[RANGES_IR_FRONT] = msg.valid_front != 0u;
    ranges->ir_valid[RANGES_IR_RIGHT] = msg.valid_right != 0u;
    return FW_OK;
}

static uint16_t sonar_mm_from_raw(uint8_t raw)
{
    return raw >= SONAR_RAW_NO_ECHO ? RANGES_NO_ECHO : (uint16_t)(raw * SONAR_MM_PER_BIT);
}

static uint8_t sonar_raw_from_mm(uint16_t mm)
{
    if (mm > RANGES_SONAR_MAX_MM) {
        return SONAR_RAW_NO_ECHO;  // also RANGES_NO_ECHO
    }
    return (uint8_t)((mm + SONAR_MM_PER_BIT / 2u) / SONAR_MM_PER_BIT);
}

int ranges_rx_sonar(ranges_t *ranges, const hal_can_frame_t *frame, uint64_t now_us)
{
    FW_ASSERT(ranges != NULL && frame != NULL);
    uint8_t raw[8];
    uint8_t counter;
    unsigned half;
    if (can_link_frame_is(frame, DYNAQPC_CAN_SONAR_RANGES_A_FRAME_ID, DYNAQPC_CAN_SONAR_RANGES_A_LENGTH)) {
        struct dynaqpc_can_sonar_ranges_a_t m;
        if (dynaqpc_can_sonar_ranges_a_unpack(&m, frame->data, frame->dlc) != 0 || !can_link_e2e_ok(frame, 4u)) {
            return can_link_rx_reject(&ranges->sonar_rx[0]);
        }
        half = 0u;
        raw[0] = m.sonar0; raw[1] = m.sonar1; raw[2] = m.sonar2; raw[3] = m.sonar3;
        raw[4] = m.sonar4; raw[5] = m.sonar5; raw[6] = m.sonar6; raw[7] = m.sonar7;
        counter = m.counter;
    } else if (can_link_frame_is(frame, DYNAQPC_CAN_SONAR_RANGES_B_FRAME_ID,
                                 DYNAQPC_CAN_SONAR_RANGES_B_LENGTH)) {
        struct dynaqpc_can_sonar_ranges_b_t m;
        if (dynaqpc_can_sonar_ranges_b_unpack(&m, frame->data, frame->dlc) != 0 || !can_link_e2e_ok(frame, 4u)) {
            return can_link_rx_reject(&ranges->sonar_rx[1]);
        }
        half = 1u;
        raw[0] = m.sonar8; raw[1] = m.sonar9; raw[2] = m.sonar10; raw[3] = m.sonar11;
        raw[4] = m.sonar12; raw[5] = m.sonar13; raw[6] = m.sonar14; raw[7] = m.sonar15;
        counter = m.counter;
    } else {
        // Not a sonar frame at all: blame the half its id is closest to.
        return can_link_rx_reject(&ranges->sonar_rx[frame->id == DYNAQPC_CAN_SONAR_RANGES_B_FRAME_ID]);
    }
    const int err = can_link_rx_accept_e2e(&ranges->sonar_rx[half], counter, now_us, CAN_LINK_MAX_STEP);
    if (err < 0) {
        return err;
    }
    for (unsigned i = 0; i < 8u; i++) {
        ranges->sonar_mm[half * 8u + i] = sonar_mm_from_raw(raw[i]);
    }
    return FW_OK;
}

int ranges_encode_ir(uint8_t *counter, const uint16_t mm[RANGES_IR_COUNT],
                     const bool valid[RANGES_IR_COUNT], hal_can_frame_t *out)
{
    struct dynaqpc_can_ir_ranges_t msg;
    memset(&msg, 0, sizeof msg);
    msg.range_left = valid[RANGES_IR_LEFT] ? mm[RANGES_IR_LEFT] : 0u;
    msg.range_front = valid[RANGES_IR_FRONT] ? mm[RANGES_IR_FRONT] : 0u;
    msg.range_right = valid[RANGES_IR_RIGHT] ? mm[RANGES_IR_RIGHT] : 0u;
    msg.valid_left = valid[RANGES_IR_LEFT] ? 1u : 0u;
    msg.valid_front = valid[RANGES_IR_FRONT] ? 1u : 0u;
    msg.valid_right = valid[RANGES_IR_RIGHT] ? 1u : 0u;
    if (!dynaqpc_can_ir_ranges_range_left_is_in_range(msg.range_left) ||
        !dynaqpc_can_ir_ranges_range_front_is_in_range(msg.range_front) ||
        !dynaqpc_can_ir_ranges_range_right_is_in_range(msg.range_right)) {
        return FW_ERR_INVAL;
    }
    msg.counter = can_link_tx_counter_next(counter);
    can_link_frame_prepare(out, DYNAQPC_CAN_IR_RANGES_FRAME_ID, DYNAQPC_CAN_IR_RANGES_LENGTH);
    if (dynaqpc_can_ir_ranges_pack(out->data, &msg, sizeof out->data) != (int)out->dlc) {
        return FW_ERR_INVAL;
    }
    can_link_e2e_protect(out, 8u);
    return FW_OK;
}

int ranges_encode_sonar(uint8_t *counter, unsigned half, const uint16_t mm[RANGES_SONAR_COUNT],
                        hal_can_frame_t *out)
{
    int n;
    if (half == 0u) {
        struct dynaqpc_can_sonar_ranges_a_t m;
        m.sonar0 = sonar_raw_from_mm(mm[0]); m.sonar1 = sonar_raw_from_mm(mm[1]);
        m.sonar2 = sonar_raw_from_mm(mm[2]); m.sonar3 = sonar_raw_from_mm(mm[3]);
        m.sonar4 = sonar_raw_from_mm(mm[4]); m.sonar5 = sonar_raw_from_mm(mm[5]);
        m.sonar6 = sonar_raw_from_mm(mm[6]); m.sonar7 = sonar_raw_from_mm(mm[7]);
        m.counter = can_link_tx_counter_next(counter);
        can_link_frame_prepare(out, DYNAQPC_CAN_SONAR_RANGES_A_FRAME_ID,
                               DYNAQPC_CAN_SONAR_RANGES_A_LENGTH);
        n = dynaqpc_can_sonar_ranges_a_pack(out->data, &m, sizeof out->data);
    } else if (half == 1u) {
        struct dynaqpc_can_sonar_ranges_b_t m;
        m.sonar8 = sonar_raw_from_mm(mm[8]); m.sonar9 = sonar_raw_from_mm(mm[9]);
        m.sonar10 = sonar_raw_from_mm(mm[10]); m.sonar11 = sonar_raw_from_mm(mm[11]);
        m.sonar12 = sonar_raw_from_mm(mm[12]); m.sonar13 = sonar_raw_from_mm(mm[13]);
        m.sonar14 = sonar_raw_from_mm(mm[14]); m.sonar15 = sonar_raw_from_mm(mm[15]);
        m.counter = can_link_tx_counter_next(counter);
        can_link_frame_prepare(out, DYNAQPC_CAN_SONAR_RANGES_B_FRAME_ID,
                               DYNAQPC_CAN_SONAR_RANGES_B_LENGTH);
        n = dynaqpc_can_sonar_ranges_b_pack(out->data, &m, sizeof out->data);
    } else {
        return FW_ERR_INVAL;
    }
    if (n != (int)out->dlc) {
        return FW_ERR_INVAL;
    }
    can_link_e2e_protect(out, 4u);
    return FW_OK;
}
