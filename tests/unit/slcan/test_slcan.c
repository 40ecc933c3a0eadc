// SPDX-License-Identifier: MIT
// SLCAN (Lawicel) framing of the emulated board: lines as python-can's slcan interface writes and
// reads them, round trips, commands, and bad lines.
#include "test_common.h"

#include <string.h>

#include "netduinoplus2/slcan.h"

static slcan_result_t feed_line_(slcan_parser_t *p, const char *s, hal_can_frame_t *f)
{
    slcan_result_t r = SLCAN_NONE;
    for (const char *c = s; *c != '\0'; c++) {
        r = slcan_feed(p, (uint8_t)*c, f);
        if (c[1] != '\0') {
            assert_int_equal(r, SLCAN_NONE);
        }
    }
    return r;
}

static void encodes_as_python_can_reads(void **state)
{
    (void)state;
    uint8_t out[SLCAN_MAX_LINE];
    const hal_can_frame_t f = {0x182, 8, 0, {0x01, 0x23, 0x45, 0x67, 0x89, 0xAB, 0xCD, 0xEF}};
    const size_t n = slcan_encode(&f, out);
    assert_int_equal(n, 22);
    assert_memory_equal(out, "t18280123456789ABCDEF\r", n);
    const hal_can_frame_t e = {0x1ABCDEF0, 2, HAL_CAN_FLAG_EXTENDED, {0xFF, 0x00}};
    assert_int_equal(slcan_encode(&e, out), 15);
    assert_memory_equal(out, "T1ABCDEF02FF00\r", 15);
    const hal_can_frame_t r = {0x040, 3, HAL_CAN_FLAG_REMOTE, {0}};
    assert_int_equal(slcan_encode(&r, out), 6);
    assert_memory_equal(out, "r0403\r", 6);
    const hal_can_frame_t empty = {0x7FF, 0, 0, {0}};
    assert_int_equal(slcan_encode(&empty, out), 6);
    assert_memory_equal(out, "t7FF0\r", 6);
    const hal_can_frame_t bad = {0x100, 9, 0, {0}};
    assert_int_equal(slcan_encode(&bad, out), 0);
}

static void decodes_what_python_can_sends(void **state)
{
    (void)state;
    slcan_parser_t p;
    slcan_parser_init(&p);
    hal_can_frame_t f;
    // python-can writes upper-case hex: f"t{id:03X}{dlc:d}" + data.hex().upper() + "\r".
    assert_int_equal(feed_line_(&p, "t0A0401020304\r", &f), SLCAN_FRAME);
    assert_int_equal(f.id, 0x0A0);
    assert_int_equal(f.dlc, 4);
    assert_int_equal(f.flags, 0);
    assert_memory_equal(f.data, "\x01\x02\x03\x04", 4);
    assert_int_equal(feed_line_(&p, "T1ABCDEF02ff00\r", &f), SLCAN_FRAME);  // lower case too
    assert_int_equal(f.id, 0x1ABCDEF0);
    assert_int_equal(f.flags, HAL_CAN_FLAG_EXTENDED);
    assert_int_equal(feed_line_(&p, "r0403\r", &f), SLCAN_FRAME);
    assert_int_equal(f.flags, HAL_CAN_FLAG_REMOTE);
    assert_int_equal(f.dlc, 3);
}

static void round_trips(void **state)
{
    (void)state;
    slcan_parser_t p;
    slcan_parser_init(&p);
    for (uint32_t i = 0; i < 200; i++) {
        hal_can_frame_t f = {0};
        f.flags = (uint8_t)(i % 3u == 0u ? HAL_CAN_FLAG_EXTENDED : 0u);
        f.id = f.flags ? (i * 2654435761u) & 0x1FFFFFFFu : (i * 37u) & 0x7FFu;
        f.dlc = (uint8_t)(i % 9u);
        for (uint32_t k = 0; k < f.dlc; k++) {
            f.data[k] = (uint8_t)(i * 7u + k);
        }
        uint8_t line[SLCAN_MAX_LINE];
        const size_t n = slcan_encode(&f, line);
        hal_can_frame_t g;
        slcan_result_t r = SLCAN_NONE;
        for (size_t k = 0; k < n; k++) {
            r = slcan_feed(&p, line[k], &g);
        }
        assert_int_equal(r, SLCAN_FRAME);
        assert_int_equal(g.id, f.id);
        assert_int_equal(g.dlc, f.dlc);
        assert_int_equal(g.flags, f.flags);
        assert_memory_equal(g.data, f.data, f.dlc);
    }
}

static void commands_and_bad_lines(void **state)
{
    (void)state;
    slcan_parser_t p;
    slcan_parser_init(&p);
    hal_can_frame_t f;
    // python-can's Bus(interface="slcan", bitrate=500000) opens with "S6\r" then "O\r".
    assert_int_equal(feed_line_(&p, "S6\r", &f), SLCAN_COMMAND);
    assert_int_equal(feed_line_(&p, "O\r", &f), SLCAN_COMMAND);
    assert_int_equal(feed_line_(&p, "C\r", &f), SLCAN_COMMAND);
    assert_int_equal(slcan_feed(&p, '\r', &f), SLCAN_NONE);  // an empty line
    assert_int_equal(feed_line_(&p, "t0A04010203\r", &f), SLCAN_ERROR);     // too few data digits
    assert_int_equal(feed_line_(&p, "t0A0401020304FF\r", &f), SLCAN_ERROR); // too many
    assert_int_equal(feed_line_(&p, "t8000\r", &f), SLCAN_ERROR);           // an 11-bit id > 0x7FF
    assert_int_equal(feed_line_(&p, "t0A09\r", &f), SLCAN_ERROR);           // dlc 9
    assert_int_equal(feed_line_(&p, "t0G00\r", &f), SLCAN_ERROR);           // not hex
    assert_int_equal(feed_line_(&p, "q\r", &f), SLCAN_ERROR);               // unknown
    // An over-long line ends as one error, and the next line is read afresh.
    for (int i = 0; i < 100; i++) {
        assert_int_equal(slcan_feed(&p, 'A', &f), SLCAN_NONE);
    }
    assert_int_equal(slcan_feed(&p, '\r', &f), SLCAN_ERROR);
    assert_int_equal(feed_line_(&p, "t1001AA\r", &f), SLCAN_FRAME);
    assert_int_equal(f.data[0], 0xAA);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(encodes_as_python_can_reads),
        cmocka_unit_test(decodes_what_python_can_sends),
        cmocka_unit_test(round_trips),
        cmocka_unit_test(commands_and_bad_lines),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
