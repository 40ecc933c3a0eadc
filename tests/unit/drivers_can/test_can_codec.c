// SPDX-License-Identifier: MIT
// Frame codecs of docs/dynaqpc.dbc: round trips of every frame, the exact bytes of hand-checked
// frames, CRC, saturation, and refusal of malformed frames.
#include "test_common.h"

#include <stdio.h>

#include <string.h>

#include "drivers/candev.h"
#include "dynaqpc_can.h"
#include "fw/fw_base.h"

static void test_crc8_matches_sae_j1850_check_value(void **state)
{
    (void)state;
    // CRC-8/SAE-J1850 check value over "123456789" is 0x4B. Our CRC prefixes the id's two bytes,
    // so feed "12" as the id (0x3231: low byte '1', high byte '2') and the rest as data.
    const uint8_t rest[] = {'3', '4', '5', '6', '7', '8', '9'};
    assert_int_equal(can_link_crc8(0x3231u, rest, sizeof rest), 0x4Bu);
}

static void test_motor_cmd_bytes_are_as_documented(void **state)
{
    (void)state;
    motor_t m;
    motor_init(&m);
    hal_can_frame_t f;
    const motor_cmd_t cmd = {.speed_left_mm_s = 300, .speed_right_mm_s = -300, .enable = true};
    assert_int_equal(motor_encode_cmd(&m, &cmd, &f), FW_OK);
    assert_int_equal(f.id, 0x080u);
    assert_int_equal(f.dlc, 6u);
    // 300 = 0x012C, -300 = 0xFED4 (little-endian), enable bit 32, counter 0 in bits 36..39.
    const uint8_t want[5] = {0x2C, 0x01, 0xD4, 0xFE, 0x01};
    assert_memory_equal(f.data, want, sizeof want);
    assert_int_equal(f.data[5], can_link_crc8(0x080u, f.data, 5));
    // The counter advances by one per frame, wrapping at 16.
    for (unsigned i = 1; i < 20; i++) {
        assert_int_equal(motor_encode_cmd(&m, &cmd, &f), FW_OK);
        assert_int_equal(f.data[4] >> 4, i % 16u);
    }
}

static void test_motor_cmd_round_trip_and_crc_check(void **state)
{
    (void)state;
    motor_t m;
    motor_init(&m);
    hal_can_frame_t f;
    const motor_cmd_t cmd = {.speed_left_mm_s = -1500, .speed_right_mm_s = 1500, .enable = false};
    assert_int_equal(motor_encode_cmd(&m, &cmd, &f), FW_OK);
    motor_cmd_t back;
    uint8_t counter = 99;
    assert_int_equal(motor_decode_cmd(&f, &back, &counter), FW_OK);
    assert_int_equal(back.speed_left_mm_s, -1500);
    assert_int_equal(back.speed_right_mm_s, 1500);
    assert_false(back.enable);
    assert_int_equal(counter, 0);
    // Any flipped bit breaks the CRC.
    for (unsigned bit = 0; bit < 48u; bit++) {
        hal_can_frame_t bad = f;
        bad.data[bit / 8u] ^= (uint8_t)(1u << (bit % 8u));
        assert_int_equal(motor_decode_cmd(&bad, &back, NULL), FW_ERR_INVAL);
    }
    // Out-of-range targets are refused and do not consume a counter value.
    const motor_cmd_t too_fast = {.speed_left_mm_s = 1501, .speed_right_mm_s = 0, .enable = true};
    assert_int_equal(motor_encode_cmd(&m, &too_fast, &f), FW_ERR_INVAL);
    assert_int_equal(m.tx_counter, 1);
}

static void test_motor_status_round_trip(void **state)
{
    (void)state;
    motor_t m;
    motor_init(&m);
    uint8_t tx = 0;
    const motor_status_t s = {.speed_left_mm_s = -2000, .speed_right_mm_s = 1234, .bump_front = true,
                              .bump_rear = false, .enabled = true,
                              .faults = MOTOR_FAULT_STALL | MOTOR_FAULT_CMD_TIMEOUT};
    hal_can_frame_t f;
    assert_int_equal(motor_encode_status(&tx, &s, &f), FW_OK);
    assert_int_equal(motor_rx_status(&m, &f, 1000u), FW_OK);
    assert_int_equal(m.status.speed_left_mm_s, -2000);
    assert_int_equal(m.status.speed_right_mm_s, 1234);
    assert_true(m.status.bump_front);
    assert_false(m.status.bump_rear);
    assert_true(m.status.enabled);
    assert_int_equal(m.status.faults, MOTOR_FAULT_STALL | MOTOR_FAULT_CMD_TIMEOUT);
    assert_int_equal(m.rx.frames, 1);
    assert_int_equal(m.rx.last_ok_us, 1000u);
}

static void test_gyro_gps_ranges_round_trip(void **state)
{
    (void)state;
    candev_t bus;
    candev_init(&bus);
    uint8_t c_gyro = 0, c_gps = 0, c_ir = 0, c_sonar = 0;
    hal_can_frame_t f;

    assert_int_equal(gyro_encode_rate(&c_gyro, -12345, -7, GYRO_STATUS_OK, &f), FW_OK);
    assert_int_equal(candev_rx(&bus, &f, 10u, NULL), CANDEV_RX_GYRO);
    assert_int_equal(bus.gyro.rate_cdeg_s, -12345);
    assert_int_equal(bus.gyro.temperature_c, -7);

    const gps_pose_t p = {.x_mm = -32768, .y_mm = 7999, .heading_cdeg = 35999, .fix = GPS_FIX_GOOD};
    assert_int_equal(gps_encode_pose(&c_gps, &p, &f), FW_OK);
    assert_int_equal(candev_rx(&bus, &f, 20u, NULL), CANDEV_RX_GPS);
    assert_int_equal(bus.gps.pose.x_mm, p.x_mm);
    assert_int_equal(bus.gps.pose.y_mm, p.y_mm);
    assert_int_equal(bus.gps.pose.heading_cdeg, p.heading_cdeg);
    assert_int_equal(bus.gps.pose.fix, p.fix);

    const uint16_t ir[3] = {0, 2000, 299};
    const bool valid[3] = {true, true, false};
    assert_int_equal(ranges_encode_ir(&c_ir, ir, valid, &f), FW_OK);
    assert_int_equal(candev_rx(&bus, &f, 30u, NULL), CANDEV_RX_IR);
    assert_int_equal(bus.ranges.ir_mm[RANGES_IR_LEFT], 0);
    assert_int_equal(bus.ranges.ir_mm[RANGES_IR_FRONT], 2000);
    assert_true(bus.ranges.ir_valid[RANGES_IR_FRONT]);
    assert_false(bus.ranges.ir_valid[RANGES_IR_RIGHT]);

    uint16_t sonar[RANGES_SONAR_COUNT];
    for (unsigned i = 0; i < RANGES_SONAR_COUNT; i++) {
        sonar[i] = (uint16_t)(i * 150u + 9u);  // 9 mm rounds to 0, 159 to 160, ...
    }
    sonar[3] = RANGES_NO_ECHO;
    sonar[12] = 2521;  // beyond the frame's reach: no echo
    // One scan, three frames of one Counter: sonar_mm changes only with the third.
    hal_can_frame_t scan[RANGES_SONAR_PARTS];
    assert_int_equal(ranges_encode_sonar(&c_sonar, sonar, scan), FW_OK);
    assert_int_equal(c_sonar, 1);
    static const uint8_t dlcs[RANGES_SONAR_PARTS] = {8u, 8u, 4u};
    for (unsigned k = 0; k < RANGES_SONAR_PARTS; k++) {
        assert_int_equal(scan[k].id, 0x0B1u + k);
        assert_int_equal(scan[k].dlc, dlcs[k]);
        assert_int_equal(scan[k].data[scan[k].dlc - 1u], can_link_crc8(scan[k].id, scan[k].data, scan[k].dlc - 1u));
        assert_int_equal(scan[k].data[scan[k].dlc - 2u] >> 4, 0);  // the Counter, high nibble before the Crc
        assert_int_equal(candev_rx(&bus, &scan[k], 40u, NULL), k < 2u ? CANDEV_RX_SONAR_PART : CANDEV_RX_SONAR);
        assert_int_equal(bus.ranges.sonar_mm[0], k < 2u ? RANGES_NO_ECHO : 0u);
    }
    for (unsigned i = 0; i < RANGES_SONAR_COUNT; i++) {
        uint16_t want = (i == 3u || i == 12u) ? RANGES_NO_ECHO : (uint16_t)((sonar[i] + 10u) / 20u * 20u);
        assert_int_equal(bus.ranges.sonar_mm[i], want);
    }
    assert_int_equal(bus.ranges.sonar_rx.frames, 1);
}

static void test_telemetry_saturates_and_round_trips(void **state)
{
    (void)state;
    tlm_t t;
    tlm_init(&t);
    hal_can_frame_t f;

    const tlm_pose_t pose = {.x_mm = 40000, .y_mm = -40000, .heading_cdeg = -100, .fix_state = 7};
    tlm_encode_pose(&t, &pose, &f);
    tlm_pose_t p;
    assert_int_equal(tlm_decode_pose(&f, &p), FW_OK);
    assert_int_equal(p.x_mm, 32767);
    assert_int_equal(p.y_mm, -32768);
    assert_int_equal(p.heading_cdeg, 35900);
    assert_int_equal(p.fix_state, TLM_FIX_LOST);

    const tlm_learn_t learn = {.state = 0x1234567u, .action = 3, .reward = -100, .episode = 2049,
                               .step = 5000};
    tlm_encode_learn(&t, &learn, &f);
    tlm_learn_t l;
    assert_int_equal(tlm_decode_learn(&f, &l), FW_OK);
    assert_int_equal(l.state, 0xFFFFFFu);
    assert_int_equal(l.action, 3);
    assert_int_equal(l.reward, -100);
    assert_int_equal(l.episode, 1);
    assert_int_equal(l.step, 5000);

    const tlm_sched_t sched = {.plan_updates = 70000, .deadline_misses = 65537, .idle_permille = 873,
                               .queue_length = 17};
    tlm_encode_sched(&t, &sched, &f);
    tlm_sched_t s;
    assert_int_equal(tlm_decode_sched(&f, &s), FW_OK);
    assert_int_equal(s.plan_updates, 65535);
    assert_int_equal(s.deadline_misses, 1);
    assert_int_equal(s.idle_permille, 875);
    assert_int_equal(s.queue_length, 17);

    const tlm_episode_t ep = {.episode = 12, .steps = 4999, .total_reward = -600000,
                              .reached_goal = true, .bumps = 3};
    tlm_encode_episode(&ep, &f);
    tlm_episode_t e;
    assert_int_equal(tlm_decode_episode(&f, &e), FW_OK);
    assert_int_equal(e.episode, 12);
    assert_int_equal(e.steps, 4999);
    assert_int_equal(e.total_reward, -524288);
    assert_true(e.reached_goal);
    assert_int_equal(e.bumps, 3);

    const tlm_status_t st = {.mode = TLM_MODE_SAFE_STOP,
                             .errors = TLM_ERR_GYRO_SILENT | TLM_ERR_DEADLINE_MISS,
                             .uptime_s = 123456};
    tlm_encode_status(&t, &st, &f);
    tlm_status_t s2;
    assert_int_equal(tlm_decode_status(&f, &s2), FW_OK);
    assert_int_equal(s2.mode, st.mode);
    assert_int_equal(s2.errors, st.errors);
    assert_int_equal(s2.uptime_s, st.uptime_s);
}

static void test_tool_cmd_crc_and_repeats(void **state)
{
    (void)state;
    candev_t bus;
    candev_init(&bus);
    uint8_t counter = 5;
    hal_can_frame_t f;
    tlm_tool_cmd_t got;
    const tlm_tool_cmd_t cmd = {.command = TLM_CMD_SAFE_STOP, .argument = 0xBEEFu};
    assert_int_equal(tlm_encode_tool_cmd(&counter, &cmd, &f), FW_OK);
    assert_int_equal(f.dlc, 8);
    assert_int_equal(candev_rx(&bus, &f, 1u, &got), CANDEV_RX_TOOL_CMD);
    assert_int_equal(got.command, TLM_CMD_SAFE_STOP);
    assert_int_equal(got.argument, 0xBEEFu);
    // The same frame again is a repeat, not a second command.
    assert_int_equal(candev_rx(&bus, &f, 2u, &got), FW_ERR_NOENT);
    assert_int_equal(bus.tlm.tool_rx.repeated, 1);
    // A corrupted CRC is refused.
    assert_int_equal(tlm_encode_tool_cmd(&counter, &cmd, &f), FW_OK);
    f.data[6] ^= 0x01u;
    assert_int_equal(candev_rx(&bus, &f, 3u, &got), FW_ERR_INVAL);
    assert_int_equal(bus.tlm.tool_rx.malformed, 1);
    // Arguments beyond 24 bits go as 0xFFFFFF, "none" (START_EPISODE: keep the heading).
    const tlm_tool_cmd_t keep = {.command = TLM_CMD_START_EPISODE, .argument = 0xFFFFFFFFu};
    assert_int_equal(tlm_encode_tool_cmd(&counter, &keep, &f), FW_OK);
    assert_int_equal(candev_rx(&bus, &f, 3u, &got), CANDEV_RX_TOOL_CMD);
    assert_int_equal(got.argument, 0xFFFFFFu);
    // An unknown command is refused on both sides.
    const tlm_tool_cmd_t unknown = {.command = 7, .argument = 0};
    assert_int_equal(tlm_encode_tool_cmd(&counter, &unknown, &f), FW_ERR_INVAL);
    assert_int_equal(tlm_encode_tool_cmd(&counter, &cmd, &f), FW_OK);
    f.data[0] = (uint8_t)((f.data[0] & 0xF0u) | 7u);
    const uint32_t crc = can_link_crc32(f.id, f.data, 4);
    for (unsigned i = 0; i < 4u; i++) {
        f.data[4 + i] = (uint8_t)(crc >> (8u * i));
    }
    assert_int_equal(candev_rx(&bus, &f, 4u, &got), FW_ERR_INVAL);
}

// The end-to-end protected frames that feed estimation (docs/can-protocol.md): one valid frame
// of each, every single bit flipped in it refused and counted as malformed, never used; then 10^6
// random frames of the right length, of which only those passing the Crc (1/256), the range
// checks and the counter's plausibility (a step of 1..3 of 16; the gyro 1..6) are taken. A sonar
// frame is one part of a scan (SONAR_RANGES_A, _B, _C): a part that passes its Crc is kept for
// the scan of its Counter, and no scan is taken from one part (test_random_sonar_frames_...).
static int e2e_rx_(candev_t *bus, const hal_can_frame_t *f, uint64_t t)
{
    return candev_rx(bus, f, t, NULL);
}

static void e2e_frame_(unsigned which, hal_can_frame_t *f)
{
    uint8_t c = 0;
    const motor_status_t ms = {.speed_left_mm_s = 123, .speed_right_mm_s = -45, .bump_front = true};
    const gps_pose_t gp = {.x_mm = 1200, .y_mm = -300, .heading_cdeg = 9000, .fix = GPS_FIX_GOOD};
    const uint16_t ir[3] = {100, 2000, 350};
    const bool valid[3] = {true, false, true};
    uint16_t sonar[RANGES_SONAR_COUNT];
    for (unsigned i = 0; i < RANGES_SONAR_COUNT; i++) {
        sonar[i] = (uint16_t)(100u + 150u * i);
    }
    switch (which) {
    case 0: assert_int_equal(motor_encode_status(&c, &ms, f), FW_OK); break;
    case 1: assert_int_equal(gyro_encode_rate(&c, 1234, 25, GYRO_STATUS_OK, f), FW_OK); break;
    case 2: assert_int_equal(ranges_encode_ir(&c, ir, valid, f), FW_OK); break;
    case 3:
    case 4:
    case 5: {
        hal_can_frame_t scan[RANGES_SONAR_PARTS];
        assert_int_equal(ranges_encode_sonar(&c, sonar, scan), FW_OK);
        *f = scan[which - 3u];
        break;
    }
    default: assert_int_equal(gps_encode_pose(&c, &gp, f), FW_OK); break;
    }
}

static const can_link_rx_t *e2e_rx_state_(const candev_t *bus, unsigned which)
{
    switch (which) {
    case 0: return &bus->motor.rx;
    case 1: return &bus->gyro.rx;
    case 2: return &bus->ranges.ir_rx;
    case 3:
    case 4:
    case 5: return &bus->ranges.sonar_rx;
    default: return &bus->gps.rx;
    }
}

static void test_e2e_refuses_corruption_and_most_noise(void **state)
{
    (void)state;
    static const char *const names[7] = {"MOTOR_STATUS",   "GYRO_RATE",      "IR_RANGES", "SONAR_RANGES_A",
                                         "SONAR_RANGES_B", "SONAR_RANGES_C", "GPS_POSE"};
    uint32_t x = 2463534242u;
    for (unsigned which = 0; which < 7u; which++) {
        candev_t bus;
        candev_init(&bus);
        hal_can_frame_t f;
        e2e_frame_(which, &f);
        const can_link_rx_t *rx = e2e_rx_state_(&bus, which);
        const unsigned bits = 8u * (f.dlc < HAL_CAN_MAX_DLC ? f.dlc : HAL_CAN_MAX_DLC);
        for (unsigned bit = 0; bit < bits; bit++) {
            hal_can_frame_t bad = f;
            bad.data[bit / 8u] ^= (uint8_t)(1u << (bit % 8u));
            assert_int_equal(e2e_rx_(&bus, &bad, 1000u), FW_ERR_INVAL);
        }
        assert_int_equal(rx->malformed, bits);
        assert_int_equal(rx->frames, 0);
        assert_true(e2e_rx_(&bus, &f, 1000u) >= 0);
        uint32_t accepted = 0;
        const uint32_t n = 1000000u;
        for (uint32_t i = 0; i < n; i++) {
            for (unsigned b = 0; b < f.dlc && b < HAL_CAN_MAX_DLC; b++) {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                f.data[b] = (uint8_t)x;
            }
            accepted += e2e_rx_(&bus, &f, 2000u + i) >= 0 ? 1u : 0u;
        }
        const bool sonar = which >= 3u && which <= 5u;
        printf("random %s frames: %u taken of %u (%.3f %%)%s; refused: %u Crc or range, %u counter jump, %u repeated\n",
               names[which], accepted, n, 100.0 * accepted / n, sonar ? " as a part, 0 scans" : "",
               rx->malformed - bits, rx->implausible, rx->repeated);
        // The Crc's share times the counter's: 1/256 x 3/16 (gyro 6/16). A sonar part's counter
        // is checked with its scan's, and one part alone is no scan: 1/256 (times 1/8 or 1/64 for
        // its Reserved bits) kept, none taken.
        const double steps = which == 1u ? 6.0 : sonar ? 16.0 : 3.0;
        assert_true((double)accepted < 1.3 * n * steps / 16.0 / 256.0);
        if (sonar) {
            assert_int_equal(rx->frames, 0);
        }
    }
}

// The physical bounds on top (motor.h MOTOR_PEAK_CMDS, gyro_set_rate_limit): of random frames
// that reach a robot standing still (its recent commands 0: wheels within the slack, the gyro
// within 30 deg/s), how many are used (MOTOR_STATUS: taken; GYRO_RATE: taken with Status OK, the
// samples that are integrated), against the same frames without the bounds. Printed; bounded by
// the Crc's and the counter's share times the bounds' (MOTOR_STATUS 301 of 65,536 speeds per
// wheel; GYRO_RATE Status OK 1 in 4 and 6,001 of 65,536 rates).
static uint32_t random_frames_used_(unsigned which, bool bounded, uint32_t n, can_link_rx_t *out)
{
    uint32_t x = 88172645u;
    candev_t bus;
    candev_init(&bus);
    if (bounded) {
        for (unsigned i = 0; i < MOTOR_PEAK_CMDS; i++) {
            const motor_cmd_t stop = {0, 0, true};
            hal_can_frame_t cmd;
            assert_int_equal(motor_encode_cmd(&bus.motor, &stop, &cmd), FW_OK);
        }
        gyro_set_rate_limit(&bus.gyro, 3000u);
    }
    hal_can_frame_t f;
    e2e_frame_(which, &f);
    uint32_t used = 0;
    for (uint32_t i = 0; i < n; i++) {
        for (unsigned b = 0; b < f.dlc && b < HAL_CAN_MAX_DLC; b++) {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            f.data[b] = (uint8_t)x;
        }
        if (e2e_rx_(&bus, &f, 2000u + i) >= 0 && (which == 0u || bus.gyro.status == GYRO_STATUS_OK)) {
            used++;
        }
    }
    *out = *e2e_rx_state_(&bus, which);
    return used;
}

static void test_physical_bounds_refuse_most_random_frames_that_pass_the_crc(void **state)
{
    (void)state;
    static const char *const names[2] = {"MOTOR_STATUS", "GYRO_RATE"};
    const uint32_t n = 1000000u;
    for (unsigned which = 0; which < 2u; which++) {
        can_link_rx_t rx;
        const uint32_t unbounded = random_frames_used_(which, false, n, &rx);
        const uint32_t used = random_frames_used_(which, true, n, &rx);
        printf("random %s frames at a standing robot: %u used of %u (%.4f %%; %u without the physical bounds); "
               "refused: %u Crc or range, %u implausible (counter jump or beyond the robot's physics), %u repeated\n",
               names[which], used, n, 100.0 * used / n, unbounded, rx.malformed, rx.implausible, rx.repeated);
        const double share = which == 0u ? (301.0 / 65536.0) * (301.0 / 65536.0) * 3.0 / 16.0
                                         : 0.25 * (6001.0 / 65536.0) * 6.0 / 16.0;
        assert_true((double)used <= 2.0 * n * share / 256.0 + 3.0);
        assert_true(used < unbounded);
    }
}

// A sonar scan is three frames of one Counter (SONAR_RANGES_A, _B, _C), taken only when all three
// passed their checks: a part lost, corrupted or sent twice with different content drops the scan
// (counted in sonar_dropped, never used), and sonar_mm keeps the last scan taken.
static void sonar_scan_(uint8_t *c, uint16_t mm0, hal_can_frame_t scan[RANGES_SONAR_PARTS])
{
    uint16_t mm[RANGES_SONAR_COUNT];
    for (unsigned i = 0; i < RANGES_SONAR_COUNT; i++) {
        mm[i] = (uint16_t)(mm0 + 20u * i);
    }
    assert_int_equal(ranges_encode_sonar(c, mm, scan), FW_OK);
}

static void test_sonar_scan_needs_all_parts_of_one_counter(void **state)
{
    (void)state;
    candev_t bus;
    candev_init(&bus);
    const ranges_t *rg = &bus.ranges;
    uint8_t c = 0;
    hal_can_frame_t s[RANGES_SONAR_PARTS];
    sonar_scan_(&c, 100u, s);  // scan 0: taken
    for (unsigned p = 0; p < RANGES_SONAR_PARTS; p++) {
        assert_int_equal(candev_rx(&bus, &s[p], 1u, NULL), p < 2u ? CANDEV_RX_SONAR_PART : CANDEV_RX_SONAR);
    }
    assert_int_equal(rg->sonar_mm[15], 400u);
    assert_int_equal(candev_rx(&bus, &s[0], 2u, NULL), FW_ERR_NOENT);  // a stuck sender: repeated
    assert_int_equal(rg->sonar_rx.repeated, 1);

    sonar_scan_(&c, 200u, s);  // scan 1: its C lost
    assert_int_equal(candev_rx(&bus, &s[0], 3u, NULL), CANDEV_RX_SONAR_PART);
    assert_int_equal(candev_rx(&bus, &s[1], 3u, NULL), CANDEV_RX_SONAR_PART);
    sonar_scan_(&c, 300u, s);  // scan 2: taken; scan 1 dropped
    for (unsigned p = 0; p < RANGES_SONAR_PARTS; p++) {
        assert_int_equal(candev_rx(&bus, &s[p], 4u, NULL), p < 2u ? CANDEV_RX_SONAR_PART : CANDEV_RX_SONAR);
    }
    assert_int_equal(rg->sonar_dropped, 1);
    assert_int_equal(rg->sonar_rx.lost, 1);
    assert_int_equal(rg->sonar_mm[0], 300u);

    sonar_scan_(&c, 500u, s);  // scan 3: its B corrupted; parts arrive in any order
    s[1].data[2] ^= 0x10u;
    assert_int_equal(candev_rx(&bus, &s[2], 5u, NULL), CANDEV_RX_SONAR_PART);
    assert_int_equal(candev_rx(&bus, &s[1], 5u, NULL), FW_ERR_INVAL);
    assert_int_equal(candev_rx(&bus, &s[0], 5u, NULL), CANDEV_RX_SONAR_PART);
    assert_int_equal(rg->sonar_mm[0], 300u);
    assert_int_equal(rg->sonar_rx.malformed, 1);

    // Scan 4: a part that passes its Crc and carries the scan's Counter, but not the sensor's
    // reading, came first. The sensor's own copy differs: the scan is dropped, not guessed at.
    sonar_scan_(&c, 700u, s);
    hal_can_frame_t forged[RANGES_SONAR_PARTS];
    uint8_t c4 = (uint8_t)(c - 1u);
    sonar_scan_(&c4, 1500u, forged);
    assert_int_equal(candev_rx(&bus, &forged[1], 6u, NULL), CANDEV_RX_SONAR_PART);
    assert_int_equal(candev_rx(&bus, &s[0], 6u, NULL), CANDEV_RX_SONAR_PART);
    assert_int_equal(candev_rx(&bus, &s[1], 6u, NULL), FW_ERR_INVAL);
    assert_int_equal(candev_rx(&bus, &s[2], 6u, NULL), FW_ERR_INVAL);
    assert_int_equal(rg->sonar_mm[0], 300u);
    assert_int_equal(rg->sonar_dropped, 3);  // scans 1, 3 and 4
    assert_int_equal(rg->sonar_rx.implausible, 2);

    sonar_scan_(&c, 900u, s);  // scan 5: taken (a step of 3 from scan 2)
    for (unsigned p = 0; p < RANGES_SONAR_PARTS; p++) {
        assert_int_equal(candev_rx(&bus, &s[p], 7u, NULL), p < 2u ? CANDEV_RX_SONAR_PART : CANDEV_RX_SONAR);
    }
    assert_int_equal(rg->sonar_mm[0], 900u);
    assert_int_equal(rg->sonar_rx.frames, 3);
    assert_int_equal(rg->sonar_rx.counter, 5);
}

// Noise on the sonar ids (docs/can-protocol.md, "The sonar scan"). 10^6 random frames of the right
// length on SONAR_RANGES_A, _B and _C at a robot standing still, (a) alone after one scan, and (b)
// among the sensor's scans, one every 10 random frames: how many scans are taken with a random
// part in them. A random part passes its CRC-8 with 1/256 and its Reserved bits 0 with 1/8 (A,
// B) or 1/64 (C); (a) a scan of random parts needs three of one Counter, and the Counter 1..3 past
// the last scan's; (b) a random part with the Counter of the next scan drops that scan, as the
// sensor's copy differs, and takes its place only where the sensor's part was lost (none is,
// here).
static uint32_t xorshift_(uint32_t *x)
{
    *x ^= *x << 13;
    *x ^= *x >> 17;
    *x ^= *x << 5;
    return *x;
}

static void random_sonar_frame_(uint32_t *x, hal_can_frame_t *f)
{
    const unsigned part = xorshift_(x) % RANGES_SONAR_PARTS;
    f->id = DYNAQPC_CAN_SONAR_RANGES_A_FRAME_ID + part;
    f->dlc = part < 2u ? 8u : 4u;
    f->flags = 0;
    for (unsigned b = 0; b < f->dlc; b++) {
        f->data[b] = (uint8_t)xorshift_(x);
    }
}

static void test_random_sonar_frames_take_no_scan(void **state)
{
    (void)state;
    const uint32_t n = 1000000u;
    uint32_t x = 2463534242u;
    for (unsigned among = 0; among < 2u; among++) {
        candev_t bus;
        candev_init(&bus);
        const ranges_t *rg = &bus.ranges;
        uint8_t c = 0;
        hal_can_frame_t s[RANGES_SONAR_PARTS];
        hal_can_frame_t f;
        uint32_t kept = 0, forged = 0, genuine = 0;
        uint64_t t = 0;
        for (uint32_t i = 0; i < n; i++) {
            if (i == 0u || (among != 0u && i % 10u == 0u)) {
                sonar_scan_(&c, 1000u, s);  // the sensor, standing: always the same reading
                for (unsigned p = 0; p < RANGES_SONAR_PARTS; p++) {
                    const int r = candev_rx(&bus, &s[p], ++t, NULL);
                    genuine += r == CANDEV_RX_SONAR ? 1u : 0u;
                }
            }
            random_sonar_frame_(&x, &f);
            const int r = candev_rx(&bus, &f, ++t, NULL);
            kept += r == CANDEV_RX_SONAR_PART ? 1u : 0u;
            forged += r == CANDEV_RX_SONAR ? 1u : 0u;
        }
        printf("random sonar frames%s at a standing robot: %u scans taken with a random part of %u frames "
               "(%u parts kept for a scan; %u Crc or Reserved refused, %u implausible, %u repeated); the sensor's "
               "scans: %u taken of %u (scans dropped, the random parts' own included: %u)\n",
               among != 0u ? " among the sensor's scans" : " alone", forged, n, kept, rg->sonar_rx.malformed,
               rg->sonar_rx.implausible, rg->sonar_rx.repeated, genuine, among != 0u ? n / 10u : 1u,
               rg->sonar_dropped);
        for (unsigned i = 0; i < RANGES_SONAR_COUNT; i++) {
            assert_int_equal(rg->sonar_mm[i], 1000u + 20u * i);  // no random reading in use
        }
        assert_int_equal(forged, 0);
        assert_true((double)kept < 1.3 * n / 256.0 / 8.0);
        if (among != 0u) {
            // A random part of the next scan's Counter (1/256 x 1/8 x 1/16 of them at most) drops it.
            assert_true((double)(n / 10u - genuine) < 1.3 * n / 256.0 / 8.0 / 16.0 + 3.0);
        }
    }
}

// The counter's plausibility: a jump over CAN_LINK_MAX_STEP is refused and counted; the frame
// after it in sequence resynchronises (a sender that rebooted costs one frame). MOTOR_CMD at the
// motor controller likewise, and a repeated MOTOR_CMD (a stuck sender) is ignored.
static void test_counter_jumps_are_refused_then_resynchronised(void **state)
{
    (void)state;
    candev_t bus;
    candev_init(&bus);
    const uint16_t ir[3] = {100, 200, 300};
    const bool valid[3] = {true, true, true};
    uint8_t c = 0;
    hal_can_frame_t f;
    for (unsigned i = 0; i < 3u; i++) {  // 0, 1, 2
        assert_int_equal(ranges_encode_ir(&c, ir, valid, &f), FW_OK);
        assert_int_equal(candev_rx(&bus, &f, 1000u * i, NULL), CANDEV_RX_IR);
    }
    c = (uint8_t)(c + 2u);  // 5: two lost, taken
    assert_int_equal(ranges_encode_ir(&c, ir, valid, &f), FW_OK);
    assert_int_equal(candev_rx(&bus, &f, 5000u, NULL), CANDEV_RX_IR);
    assert_int_equal(bus.ranges.ir_rx.lost, 2);
    c = (uint8_t)(c + 3u);  // 9: a jump of 4, refused
    assert_int_equal(ranges_encode_ir(&c, ir, valid, &f), FW_OK);
    assert_int_equal(candev_rx(&bus, &f, 9000u, NULL), FW_ERR_INVAL);
    assert_int_equal(bus.ranges.ir_rx.implausible, 1);
    assert_int_equal(bus.ranges.ir_rx.counter, 5);
    assert_int_equal(ranges_encode_ir(&c, ir, valid, &f), FW_OK);  // 10 follows 9: resynchronised
    assert_int_equal(candev_rx(&bus, &f, 10000u, NULL), CANDEV_RX_IR);
    assert_int_equal(bus.ranges.ir_rx.counter, 10);
    assert_int_equal(bus.ranges.ir_rx.malformed, 0);

    can_link_rx_t rx;
    can_link_rx_init(&rx);
    motor_t fw;
    motor_init(&fw);
    const motor_cmd_t cmd = {.speed_left_mm_s = 100, .speed_right_mm_s = 100, .enable = true};
    motor_cmd_t got;
    assert_int_equal(motor_encode_cmd(&fw, &cmd, &f), FW_OK);
    assert_int_equal(motor_rx_cmd(&rx, &f, 0u, &got), FW_OK);
    assert_int_equal(motor_rx_cmd(&rx, &f, 1u, &got), FW_ERR_NOENT);  // the same frame again
    fw.tx_counter = 7u;  // the firmware rebooted elsewhere in its count
    assert_int_equal(motor_encode_cmd(&fw, &cmd, &f), FW_OK);
    assert_int_equal(motor_rx_cmd(&rx, &f, 2u, &got), FW_ERR_INVAL);
    assert_int_equal(motor_encode_cmd(&fw, &cmd, &f), FW_OK);
    assert_int_equal(motor_rx_cmd(&rx, &f, 3u, &got), FW_OK);
    assert_int_equal(got.speed_left_mm_s, 100);
    f.data[0] ^= 1u;  // a corrupted one: malformed
    assert_int_equal(motor_rx_cmd(&rx, &f, 4u, &got), FW_ERR_INVAL);
    assert_int_equal(rx.malformed, 1);
    assert_int_equal(rx.implausible, 1);
    assert_int_equal(rx.repeated, 1);
}

// Noise cannot forge a command (docs/can-protocol.md): of 10^7 random TOOL_CMD frames (random
// bytes, the length right) none is accepted. The arithmetic: a random frame passes the 32-bit Crc
// with probability 2^-32, a known Command 7/16 of those and a new Counter 15/16: ~1e-10 a frame.
static void test_random_tool_cmds_are_never_accepted(void **state)
{
    (void)state;
    candev_t bus;
    candev_init(&bus);
    uint64_t x = 0x9E3779B97F4A7C15ull;
    uint32_t accepted = 0;
    tlm_tool_cmd_t got;
    hal_can_frame_t f = {.id = DYNAQPC_CAN_TOOL_CMD_FRAME_ID, .dlc = DYNAQPC_CAN_TOOL_CMD_LENGTH, .flags = 0, .data = {0}};
    for (uint32_t n = 0; n < 10000000u; n++) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        for (unsigned i = 0; i < 8u; i++) {
            f.data[i] = (uint8_t)(x >> (8u * i));
        }
        accepted += tlm_rx_tool_cmd(&bus.tlm, &f, n, &got) == FW_OK ? 1u : 0u;
    }
    printf("random TOOL_CMD frames: %u accepted of 10000000, %u refused as malformed\n", accepted,
           bus.tlm.tool_rx.malformed);
    assert_int_equal(accepted, 0);
    assert_int_equal(bus.tlm.tool_rx.malformed, 10000000u);
}

static void test_malformed_frames_are_refused_and_counted(void **state)
{
    (void)state;
    candev_t bus;
    candev_init(&bus);
    uint8_t c = 0;
    hal_can_frame_t good, f;
    assert_int_equal(gyro_encode_rate(&c, 100, 20, GYRO_STATUS_OK, &good), FW_OK);
    assert_int_equal(candev_rx(&bus, &good, 1u, NULL), CANDEV_RX_GYRO);

    // Wrong dlc, both ways.
    f = good;
    f.dlc = 3;
    assert_int_equal(candev_rx(&bus, &f, 2u, NULL), FW_ERR_INVAL);
    f.dlc = 8;
    assert_int_equal(candev_rx(&bus, &f, 2u, NULL), FW_ERR_INVAL);
    // A remote frame with our id.
    f = good;
    f.flags = HAL_CAN_FLAG_REMOTE;
    assert_int_equal(candev_rx(&bus, &f, 2u, NULL), FW_ERR_INVAL);
    // Rate beyond ±300 deg/s (raw 30001).
    f = good;
    f.data[0] = (uint8_t)(30001 & 0xFF);
    f.data[1] = (uint8_t)(30001 >> 8);
    assert_int_equal(candev_rx(&bus, &f, 2u, NULL), FW_ERR_INVAL);
    // Status 3 is not defined.
    f = good;
    f.data[3] = (uint8_t)((f.data[3] & 0xF0u) | 0x03u);
    assert_int_equal(candev_rx(&bus, &f, 2u, NULL), FW_ERR_INVAL);
    assert_int_equal(bus.gyro.rx.malformed, 5);
    assert_int_equal(bus.gyro.rx.frames, 1);
    assert_int_equal(bus.gyro.rate_cdeg_s, 100);  // unchanged

    // GPS heading 36000 (0.01 deg) is out of range; IR range 2001 mm too.
    const gps_pose_t p = {.x_mm = 0, .y_mm = 0, .heading_cdeg = 0, .fix = GPS_FIX_GOOD};
    assert_int_equal(gps_encode_pose(&c, &p, &f), FW_OK);
    f.data[4] = (uint8_t)(36000 & 0xFF);
    f.data[5] = (uint8_t)(36000 >> 8);
    assert_int_equal(candev_rx(&bus, &f, 3u, NULL), FW_ERR_INVAL);
    const uint16_t ir[3] = {1, 2, 3};
    const bool valid[3] = {true, true, true};
    assert_int_equal(ranges_encode_ir(&c, ir, valid, &f), FW_OK);
    f.data[2] = (uint8_t)(2001 & 0xFF);
    f.data[3] = (uint8_t)(2001 >> 8);
    assert_int_equal(candev_rx(&bus, &f, 3u, NULL), FW_ERR_INVAL);
    assert_int_equal(bus.gps.rx.malformed, 1);
    assert_int_equal(bus.ranges.ir_rx.malformed, 1);

    // Frames not for the firmware are ignored and counted, whatever their content.
    hal_can_frame_t other = good;
    other.id = 0x7FFu;
    assert_int_equal(candev_rx(&bus, &other, 4u, NULL), CANDEV_RX_IGNORED);
    other.id = DYNAQPC_CAN_GYRO_RATE_FRAME_ID;
    other.flags = HAL_CAN_FLAG_EXTENDED;
    assert_int_equal(candev_rx(&bus, &other, 4u, NULL), CANDEV_RX_IGNORED);
    assert_int_equal(bus.ignored, 2);
}

static void test_every_byte_pattern_is_survived(void **state)
{
    (void)state;
    // Every id we receive, every dlc 0..8, pseudo-random bytes: no crash, a defined result.
    candev_t bus;
    candev_init(&bus);
    uint32_t x = 12345u;
    for (unsigned k = 0; k < CANDEV_RX_ID_COUNT; k++) {
        for (uint8_t dlc = 0; dlc <= 8u; dlc++) {
            for (unsigned r = 0; r < 200u; r++) {
                hal_can_frame_t f = {.id = candev_rx_ids[k], .dlc = dlc, .flags = 0, .data = {0}};
                for (unsigned i = 0; i < 8u; i++) {
                    x = x * 1664525u + 1013904223u;
                    f.data[i] = (uint8_t)(x >> 24);
                }
                tlm_tool_cmd_t cmd;
                int rc = candev_rx(&bus, &f, r, &cmd);
                assert_true(rc >= FW_ERR_NOENT && rc <= CANDEV_RX_SONAR_PART);
            }
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_crc8_matches_sae_j1850_check_value),
        cmocka_unit_test(test_motor_cmd_bytes_are_as_documented),
        cmocka_unit_test(test_motor_cmd_round_trip_and_crc_check),
        cmocka_unit_test(test_motor_status_round_trip),
        cmocka_unit_test(test_gyro_gps_ranges_round_trip),
        cmocka_unit_test(test_telemetry_saturates_and_round_trips),
        cmocka_unit_test(test_tool_cmd_crc_and_repeats),
        cmocka_unit_test(test_random_tool_cmds_are_never_accepted),
        cmocka_unit_test(test_e2e_refuses_corruption_and_most_noise),
        cmocka_unit_test(test_physical_bounds_refuse_most_random_frames_that_pass_the_crc),
        cmocka_unit_test(test_sonar_scan_needs_all_parts_of_one_counter),
        cmocka_unit_test(test_random_sonar_frames_take_no_scan),
        cmocka_unit_test(test_counter_jumps_are_refused_then_resynchronised),
        cmocka_unit_test(test_malformed_frames_are_refused_and_counted),
        cmocka_unit_test(test_every_byte_pattern_is_survived),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
