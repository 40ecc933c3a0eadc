// SPDX-License-Identifier: MIT
// Fuzz target: the frame checks (docs/can-protocol.md, end-to-end protection) — the end-to-end
// Crc, the counter's plausibility and resynchronisation, the decoders behind them — on every
// frame the firmware receives (candev_rx) and on MOTOR_CMD at the motor controller
// (motor_rx_cmd). Ops, each a byte then its arguments:
//   bits 0..2: the frame: an index into candev_rx_ids (0..6), 7 MOTOR_CMD; bit 7 set: SONAR_RANGES_C
//              (candev_rx_ids[7]) instead
//   bit 3:     seal it: the fuzzer's bytes, then the right Crc written over them (else as given),
//              so the checks behind the Crc are reached
//   bit 4:     the Counter set to the last one taken + (next byte % 16), sealed or not
//   bit 6:     first, the firmware commands the wheels (the physical bounds, motor.h
//              MOTOR_PEAK_CMDS): both at (next byte - 128) x 12 mm/s, and the gyro's rate
//              limit to (next byte) x 120 cdeg/s (0: none)
//   then: dlc (byte % 9), the data bytes, the time step (byte, ms)
// Oracles: no sanitizer report; a frame whose Crc fails is never taken and changes no count but
// `malformed`; a frame taken carries a Counter 1..max_step past the last one taken, or follows
// the last refused jump by 1 (a resynchronisation); a refused jump is counted in `implausible`;
// a frame sealed by can_link_e2e_protect always passes can_link_e2e_ok; a MOTOR_STATUS taken is
// within the recent commands' bound, a GYRO_RATE taken with Status OK within the rate limit. The
// sonars (SONAR_RANGES_A, _B, _C, one scan): a part with its Reserved bits not 0 is malformed as
// one whose Crc fails; a part whose checks pass is kept (the scan's counts unchanged) or
// completes the scan, which is then taken as above, with the last good copy of
// each of its parts carrying its Counter; a part refused as malformed leaves the scan being
// assembled as it was.
#include <string.h>

#include "drivers/candev.h"
#include "drivers/can_link.h"
#include "dynaqpc_can.h"
#include "fuzz.h"
#include "fw/fw_base.h"

// Where a frame's Counter is (the low nibble of the byte given, shifted left by `shift`), its Crc
// width, the largest counter step its receiver takes and its receive state.
typedef struct frame_kind {
    uint32_t id;
    uint8_t dlc;
    uint8_t counter_byte;
    uint8_t counter_shift;
    uint8_t crc_bits;  // 0: none (TOOL_CMD's CRC-32 is its own fuzz target's business)
    uint8_t max_step;
} frame_kind_t;

static const frame_kind_t kinds_[9] = {
    {DYNAQPC_CAN_TOOL_CMD_FRAME_ID, DYNAQPC_CAN_TOOL_CMD_LENGTH, 0u, 4u, 0u, 15u},
    {DYNAQPC_CAN_MOTOR_STATUS_FRAME_ID, DYNAQPC_CAN_MOTOR_STATUS_LENGTH, 5u, 0u, 8u, CAN_LINK_MAX_STEP},
    {DYNAQPC_CAN_GYRO_RATE_FRAME_ID, DYNAQPC_CAN_GYRO_RATE_LENGTH, 3u, 4u, 8u, GYRO_MAX_STEP},
    {DYNAQPC_CAN_IR_RANGES_FRAME_ID, DYNAQPC_CAN_IR_RANGES_LENGTH, 6u, 4u, 8u, CAN_LINK_MAX_STEP},
    {DYNAQPC_CAN_SONAR_RANGES_A_FRAME_ID, DYNAQPC_CAN_SONAR_RANGES_A_LENGTH, 6u, 4u, 8u, CAN_LINK_MAX_STEP},
    {DYNAQPC_CAN_SONAR_RANGES_B_FRAME_ID, DYNAQPC_CAN_SONAR_RANGES_B_LENGTH, 6u, 4u, 8u, CAN_LINK_MAX_STEP},
    {DYNAQPC_CAN_GPS_POSE_FRAME_ID, DYNAQPC_CAN_GPS_POSE_LENGTH, 6u, 4u, 8u, CAN_LINK_MAX_STEP},
    {DYNAQPC_CAN_MOTOR_CMD_FRAME_ID, DYNAQPC_CAN_MOTOR_CMD_LENGTH, 4u, 4u, 8u, CAN_LINK_MAX_STEP},
    {DYNAQPC_CAN_SONAR_RANGES_C_FRAME_ID, DYNAQPC_CAN_SONAR_RANGES_C_LENGTH, 2u, 4u, 8u, CAN_LINK_MAX_STEP},
};

// The sonar part a kind is (0..2), or -1.
static int sonar_part_of_(unsigned k)
{
    return k == 4u ? 0 : k == 5u ? 1 : k == 8u ? 2 : -1;
}

// A sonar part's unused bits (Reserved) are 0, as the DBC asks: else the firmware refuses it as
// malformed, whatever its Crc. True for every other frame.
static bool reserved_ok_(int part, const hal_can_frame_t *f)
{
    if (part == 0) {
        struct dynaqpc_can_sonar_ranges_a_t m;
        return dynaqpc_can_sonar_ranges_a_unpack(&m, f->data, f->dlc) == 0 && m.reserved == 0u;
    }
    if (part == 1) {
        struct dynaqpc_can_sonar_ranges_b_t m;
        return dynaqpc_can_sonar_ranges_b_unpack(&m, f->data, f->dlc) == 0 && m.reserved == 0u;
    }
    if (part == 2) {
        struct dynaqpc_can_sonar_ranges_c_t m;
        return dynaqpc_can_sonar_ranges_c_unpack(&m, f->data, f->dlc) == 0 && m.reserved == 0u;
    }
    return true;
}

static can_link_rx_t *rx_of_(candev_t *bus, can_link_rx_t *cmd_rx, unsigned k)
{
    switch (k) {
    case 1: return &bus->motor.rx;
    case 2: return &bus->gyro.rx;
    case 3: return &bus->ranges.ir_rx;
    case 4:
    case 5:
    case 8: return &bus->ranges.sonar_rx;
    case 6: return &bus->gps.rx;
    case 7: return cmd_rx;
    default: return NULL;
    }
}

static uint8_t counter_of_(const frame_kind_t *k, const hal_can_frame_t *f)
{
    return (uint8_t)((f->data[k->counter_byte] >> k->counter_shift) & 0x0Fu);
}

static candev_t bus_;
static uint8_t sonar_last_[3];  // the Counter of each sonar part's last frame whose checks passed

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_in_t in = {data, size};
    candev_init(&bus_);
    memset(sonar_last_, 0xFF, sizeof sonar_last_);
    can_link_rx_t cmd_rx;
    can_link_rx_init(&cmd_rx);
    uint64_t now = 0;
    for (uint32_t ops = 0; in.left > 0u && ops < 512u; ops++) {
        const uint8_t op = fuzz_u8(&in);
        const unsigned which = (op & 0x80u) != 0u ? 8u : op & 7u;
        if ((op & 0x40u) != 0u) {
            const int16_t v = (int16_t)(((int32_t)fuzz_u8(&in) - 128) * 12);
            const motor_cmd_t cmd = {v, (int16_t)-v, true};
            hal_can_frame_t out;
            (void)motor_encode_cmd(&bus_.motor, &cmd, &out);
            gyro_set_rate_limit(&bus_.gyro, (uint16_t)(fuzz_u8(&in) * 120u));
        }
        const frame_kind_t *k = &kinds_[which];
        hal_can_frame_t f;
        memset(&f, 0, sizeof f);
        f.id = k->id;
        const uint8_t jump = (op & 0x10u) != 0u ? (uint8_t)(fuzz_u8(&in) & 0x0Fu) : 0u;
        f.dlc = (uint8_t)(fuzz_u8(&in) % 9u);
        if ((op & 0x20u) != 0u) {
            f.dlc = k->dlc;  // mostly the right length: the checks behind the dlc
        }
        for (uint32_t i = 0; i < f.dlc; i++) {
            f.data[i] = fuzz_u8(&in);
        }
        now += (uint64_t)fuzz_u8(&in) * 1000u;
        can_link_rx_t *rx = rx_of_(&bus_, &cmd_rx, which);
        if ((op & 0x10u) != 0u && rx != NULL && f.dlc == k->dlc) {
            const uint8_t c = (uint8_t)((rx->counter + jump) & 0x0Fu);
            f.data[k->counter_byte] = (uint8_t)((f.data[k->counter_byte] & ~(0x0Fu << k->counter_shift)) |
                                                (uint8_t)(c << k->counter_shift));
        }
        if ((op & 0x08u) != 0u && k->crc_bits != 0u && f.dlc > 0u) {
            can_link_e2e_protect(&f, k->crc_bits);
            if (!can_link_e2e_ok(&f, k->crc_bits)) {
                __builtin_trap();  // a sealed frame always passes
            }
        }
        if (rx == NULL) {
            tlm_tool_cmd_t cmd;
            (void)candev_rx(&bus_, &f, now, &cmd);
            continue;
        }
        const can_link_rx_t before = *rx;
        const uint8_t parts_before = bus_.ranges.sonar_parts;
        const uint8_t scan_counter_before = bus_.ranges.sonar_counter;
        const int part = sonar_part_of_(which);
        int r;
        if (which == 7u) {
            motor_cmd_t cmd;
            r = motor_rx_cmd(rx, &f, now, &cmd);
        } else {
            r = candev_rx(&bus_, &f, now, NULL);
        }
        const bool right_frame = f.dlc == k->dlc && (f.flags & (HAL_CAN_FLAG_EXTENDED | HAL_CAN_FLAG_REMOTE)) == 0u;
        if (!right_frame || !can_link_e2e_ok(&f, k->crc_bits) || !reserved_ok_(part, &f)) {
            // Refused as malformed: nothing but that count changes.
            if (r >= 0 || rx->malformed != before.malformed + 1u || rx->frames != before.frames ||
                rx->counter != before.counter || rx->implausible != before.implausible ||
                bus_.ranges.sonar_parts != parts_before || bus_.ranges.sonar_counter != scan_counter_before) {
                __builtin_trap();
            }
            continue;
        }
        if (part >= 0) {
            sonar_last_[part] = counter_of_(k, &f);
        }
        if (r == CANDEV_RX_SONAR_PART) {
            // Kept for its scan: the scans' counts unchanged, the scan being assembled is its Counter's.
            if (part < 0 || rx->frames != before.frames || rx->counter != before.counter ||
                bus_.ranges.sonar_counter != counter_of_(k, &f) ||
                (bus_.ranges.sonar_parts & (1u << (unsigned)part)) == 0u) {
                __builtin_trap();
            }
            continue;
        }
        if (r >= 0) {
            const uint8_t c = counter_of_(k, &f);
            if (part >= 0 && (sonar_last_[0] != c || sonar_last_[1] != c || sonar_last_[2] != c)) {
                __builtin_trap();  // a scan taken from parts of different Counters
            }
            const uint8_t step = (uint8_t)((c - before.counter) & 0x0Fu);
            const bool resync = before.sync_pending && ((c - before.sync_counter) & 0x0Fu) == 1u;
            if (rx->counter != c || rx->frames != before.frames + 1u ||
                (before.seen && !(step >= 1u && step <= k->max_step) && !resync)) {
                __builtin_trap();
            }
            const int32_t peak = motor_cmd_peak_mm_s(&bus_.motor);
            const int32_t most = peak + peak / 2 + MOTOR_PLAUSIBLE_SLACK_MM_S;
            const motor_status_t *ms = &bus_.motor.status;
            if (which == 1u && peak >= 0 &&
                (ms->speed_left_mm_s > most || ms->speed_left_mm_s < -most ||
                 ms->speed_right_mm_s > most || ms->speed_right_mm_s < -most)) {
                __builtin_trap();  // beyond the robot's physics, taken
            }
            const int32_t limit = bus_.gyro.rate_limit_cdeg_s;
            if (which == 2u && limit != 0 && bus_.gyro.status == GYRO_STATUS_OK &&
                (bus_.gyro.rate_cdeg_s > limit || bus_.gyro.rate_cdeg_s < -limit)) {
                __builtin_trap();
            }
        } else if (r == FW_ERR_INVAL && rx->implausible != before.implausible &&
                   rx->implausible != before.implausible + 1u) {
            __builtin_trap();
        }
    }
    return 0;
}
