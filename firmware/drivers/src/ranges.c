// SPDX-License-Identifier: MIT
// dynaqpc drivers: IR and sonar frames (see ranges.h).
//
// The sonar frames pack sonars of 7 bits (2 cm per bit): 1 cm resolution would buy nothing, as
// the paper's state uses 4 bits of sonar. A scan is three frames (7 + 7 + 2 sonars) so that each
// has its Counter and a whole byte for its CRC-8, like every other frame that feeds estimation,
// and its unused bits (Reserved) sent as 0 and checked; all three carry the scan's Counter, and
// the scan is taken only when all three of one Counter passed their checks (docs/can-protocol.md,
// "The sonar scan").
#include "drivers/ranges.h"

#include <string.h>

#include "dynaqpc_can.h"
#include "fw/fw_base.h"

#define SONAR_RAW_NO_ECHO 127u
#define SONAR_MM_PER_BIT 20u
#define SONAR_PER_FRAME 7u                             // parts A and B; C has the last 2
#define SONAR_ALL_PARTS ((1u << RANGES_SONAR_PARTS) - 1u)
#define SONAR_CONFLICT 0x80u  // sonar_parts: two different copies of a part came; the scan is dropped

void ranges_init(ranges_t *ranges)
{
    FW_ASSERT(ranges != NULL);
    memset(ranges, 0, sizeof *ranges);
    for (unsigned i = 0; i < RANGES_SONAR_COUNT; i++) {
        ranges->sonar_mm[i] = RANGES_NO_ECHO;
    }
    can_link_rx_init(&ranges->ir_rx);
    can_link_rx_init(&ranges->sonar_rx);
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

// One part whose Crc passed, into the scan of its Counter; the scan taken once complete. The
// first copy of a part is kept: the same copy again is a repeat (a stuck sender), a different
// one means one of the two is not the sensor's, and the scan is dropped (never taken), so a
// frame of noise that passes the Crc takes no scan's place unless the sensor's part is lost.
static int sonar_part_(ranges_t *ranges, unsigned part, const uint8_t *raw, unsigned n, uint8_t counter,
                       uint64_t now_us)
{
    const uint8_t bit = (uint8_t)(1u << part);
    uint8_t *staged = &ranges->sonar_raw[part * SONAR_PER_FRAME];
    if (ranges->sonar_parts != 0u && counter == ranges->sonar_counter) {
        if ((ranges->sonar_parts & bit) != 0u && memcmp(staged, raw, n) == 0) {
            ranges->sonar_rx.repeated++;
            return FW_ERR_NOENT;
        }
        if ((ranges->sonar_parts & (bit | SONAR_CONFLICT)) != 0u) {
            if ((ranges->sonar_parts & SONAR_CONFLICT) == 0u && ranges->sonar_parts != SONAR_ALL_PARTS) {
                ranges->sonar_parts |= SONAR_CONFLICT;
                ranges->sonar_dropped += ranges->sonar_dropped < UINT16_MAX ? 1u : 0u;
            }
            return can_link_rx_implausible(&ranges->sonar_rx);
        }
    } else {
        if (ranges->sonar_parts != 0u && ranges->sonar_parts != SONAR_ALL_PARTS &&
            (ranges->sonar_parts & SONAR_CONFLICT) == 0u) {
            ranges->sonar_dropped += ranges->sonar_dropped < UINT16_MAX ? 1u : 0u;  // a part never came
        }
        ranges->sonar_parts = 0u;
        ranges->sonar_counter = counter;
    }
    memcpy(staged, raw, n);
    ranges->sonar_parts |= bit;
    if (ranges->sonar_parts != SONAR_ALL_PARTS) {
        return RANGES_SONAR_PART;
    }
    const int err = can_link_rx_accept_e2e(&ranges->sonar_rx, counter, now_us, CAN_LINK_MAX_STEP);
    if (err < 0) {
        return err;
    }
    for (unsigned i = 0; i < RANGES_SONAR_COUNT; i++) {
        ranges->sonar_mm[i] = sonar_mm_from_raw(ranges->sonar_raw[i]);
    }
    return FW_OK;
}

int ranges_rx_sonar(ranges_t *ranges, const hal_can_frame_t *frame, uint64_t now_us)
{
    FW_ASSERT(ranges != NULL && frame != NULL);
    uint8_t raw[SONAR_PER_FRAME];
    if (can_link_frame_is(frame, DYNAQPC_CAN_SONAR_RANGES_A_FRAME_ID, DYNAQPC_CAN_SONAR_RANGES_A_LENGTH)) {
        struct dynaqpc_can_sonar_ranges_a_t m;
        if (dynaqpc_can_sonar_ranges_a_unpack(&m, frame->data, frame->dlc) != 0 || !can_link_e2e_ok(frame, 8u) ||
            m.reserved != 0u) {
            return can_link_rx_reject(&ranges->sonar_rx);
        }
        raw[0] = m.sonar0; raw[1] = m.sonar1; raw[2] = m.sonar2; raw[3] = m.sonar3;
        raw[4] = m.sonar4; raw[5] = m.sonar5; raw[6] = m.sonar6;
        return sonar_part_(ranges, 0u, raw, SONAR_PER_FRAME, m.counter, now_us);
    }
    if (can_link_frame_is(frame, DYNAQPC_CAN_SONAR_RANGES_B_FRAME_ID, DYNAQPC_CAN_SONAR_RANGES_B_LENGTH)) {
        struct dynaqpc_can_sonar_ranges_b_t m;
        if (dynaqpc_can_sonar_ranges_b_unpack(&m, frame->data, frame->dlc) != 0 || !can_link_e2e_ok(frame, 8u) ||
            m.reserved != 0u) {
            return can_link_rx_reject(&ranges->sonar_rx);
        }
        raw[0] = m.sonar7; raw[1] = m.sonar8; raw[2] = m.sonar9; raw[3] = m.sonar10;
        raw[4] = m.sonar11; raw[5] = m.sonar12; raw[6] = m.sonar13;
        return sonar_part_(ranges, 1u, raw, SONAR_PER_FRAME, m.counter, now_us);
    }
    if (can_link_frame_is(frame, DYNAQPC_CAN_SONAR_RANGES_C_FRAME_ID, DYNAQPC_CAN_SONAR_RANGES_C_LENGTH)) {
        struct dynaqpc_can_sonar_ranges_c_t m;
        if (dynaqpc_can_sonar_ranges_c_unpack(&m, frame->data, frame->dlc) != 0 || !can_link_e2e_ok(frame, 8u) ||
            m.reserved != 0u) {
            return can_link_rx_reject(&ranges->sonar_rx);
        }
        raw[0] = m.sonar14;
        raw[1] = m.sonar15;
        return sonar_part_(ranges, 2u, raw, RANGES_SONAR_COUNT - 2u * SONAR_PER_FRAME, m.counter, now_us);
    }
    return can_link_rx_reject(&ranges->sonar_rx);  // a sonar id with the wrong dlc, extended or remote
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
    return can_link_tx_seal(out, dynaqpc_can_ir_ranges_pack(out->data, &msg, sizeof out->data));
}

int ranges_encode_sonar(uint8_t *counter, const uint16_t mm[RANGES_SONAR_COUNT],
                        hal_can_frame_t out[RANGES_SONAR_PARTS])
{
    uint8_t raw[RANGES_SONAR_COUNT];
    for (unsigned i = 0; i < RANGES_SONAR_COUNT; i++) {
        raw[i] = sonar_raw_from_mm(mm[i]);
    }
    const uint8_t c = can_link_tx_counter_next(counter);  // one Counter for the whole scan
    struct dynaqpc_can_sonar_ranges_a_t a;
    struct dynaqpc_can_sonar_ranges_b_t b;
    struct dynaqpc_can_sonar_ranges_c_t cc;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    memset(&cc, 0, sizeof cc);
    a.sonar0 = raw[0]; a.sonar1 = raw[1]; a.sonar2 = raw[2]; a.sonar3 = raw[3];
    a.sonar4 = raw[4]; a.sonar5 = raw[5]; a.sonar6 = raw[6];
    b.sonar7 = raw[7]; b.sonar8 = raw[8]; b.sonar9 = raw[9]; b.sonar10 = raw[10];
    b.sonar11 = raw[11]; b.sonar12 = raw[12]; b.sonar13 = raw[13];
    cc.sonar14 = raw[14];
    cc.sonar15 = raw[15];
    a.counter = c;
    b.counter = c;
    cc.counter = c;
    can_link_frame_prepare(&out[0], DYNAQPC_CAN_SONAR_RANGES_A_FRAME_ID, DYNAQPC_CAN_SONAR_RANGES_A_LENGTH);
    can_link_frame_prepare(&out[1], DYNAQPC_CAN_SONAR_RANGES_B_FRAME_ID, DYNAQPC_CAN_SONAR_RANGES_B_LENGTH);
    can_link_frame_prepare(&out[2], DYNAQPC_CAN_SONAR_RANGES_C_FRAME_ID, DYNAQPC_CAN_SONAR_RANGES_C_LENGTH);
    if (dynaqpc_can_sonar_ranges_a_pack(out[0].data, &a, sizeof out[0].data) != (int)out[0].dlc ||
        dynaqpc_can_sonar_ranges_b_pack(out[1].data, &b, sizeof out[1].data) != (int)out[1].dlc ||
        dynaqpc_can_sonar_ranges_c_pack(out[2].data, &cc, sizeof out[2].data) != (int)out[2].dlc) {
        return FW_ERR_INVAL;
    }
    for (unsigned p = 0; p < RANGES_SONAR_PARTS; p++) {
        can_link_e2e_protect(&out[p], 8u);
    }
    return FW_OK;
}
