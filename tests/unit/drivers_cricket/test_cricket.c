// SPDX-License-Identifier: MIT
// Cricket listener: line assembly over a byte stream, parsing by key, ranges per beacon, and the
// fix states (fresh, stale, moving, lost).
#include "test_common.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "drivers/cricket.h"
#include "fw/fw_base.h"

// The lab of the paper: 4.3 m x 3.2 m, four beacons on the ceiling (2.5 m), listener at 0.15 m.
static const cricket_beacon_t beacons[4] = {
    {0x01AAE48A0B0000ACu, 300.0f, 300.0f, 2500.0f},
    {0x01AAE48A0B0000ADu, 4000.0f, 300.0f, 2500.0f},
    {0x01AAE48A0B0000AEu, 4000.0f, 2900.0f, 2500.0f},
    {0x01AAE48A0B0000AFu, 300.0f, 2900.0f, 2500.0f},
};
static const char *const beacon_ids[4] = {
    "01:aa:e4:8a:0b:00:00:ac", "01:aa:e4:8a:0b:00:00:ad", "01:aa:e4:8a:0b:00:00:ae",
    "01:AA:E4:8A:0B:00:00:AF",
};

static void setup_listener(cricket_t *ck)
{
    struct cricket_config cfg;
    cricket_default_config(&cfg);
    cfg.beacons = beacons;
    cfg.n_beacons = 4;
    cfg.listener_z_mm = 150.0f;
    assert_int_equal(cricket_init(ck, &cfg), FW_OK);
}

static size_t feed_str(cricket_t *ck, const char *s, uint64_t now_us)
{
    return cricket_feed(ck, (const uint8_t *)s, strlen(s), now_us);
}

/// A line the listener would print for beacon b seen from (x, y), DR from the true distance.
static void format_line(char *buf, size_t cap, unsigned b, float x, float y)
{
    float dx = x - beacons[b].x_mm, dy = y - beacons[b].y_mm, dz = 150.0f - beacons[b].z_mm;
    float mm = sqrtf(dx * dx + dy * dy + dz * dz);
    unsigned dr = (unsigned)lroundf(mm / 0.343f);
    snprintf(buf, cap, "VR=2.0,ID=%s,SP=lab,DB=%u,DR=%u,TM=%u,TS=%u\r\n", beacon_ids[b],
             (unsigned)lroundf(mm / 10.0f), dr, dr + 811u, 40000u + b);
}

/// What the parser read, in the notation of docs/cricket-lines.tsv ("ok fields=... id=...").
static void describe_line(const cricket_line_t *l, char *buf, size_t cap)
{
    static const char *const keys[] = {"VR", "ID", "SP", "DB", "DR", "TM", "TS"};
    size_t n = (size_t)snprintf(buf, cap, "ok fields=");
    const char *sep = "";
    for (unsigned i = 0; i < 7u; i++) {
        if (l->fields & (1u << i)) {
            n += (size_t)snprintf(buf + n, cap - n, "%s%s", sep, keys[i]);
            sep = ",";
        }
    }
    if (l->fields & CRICKET_FIELD_ID) n += (size_t)snprintf(buf + n, cap - n, " id=%016llx", (unsigned long long)l->id);
    if (l->fields & CRICKET_FIELD_SP) n += (size_t)snprintf(buf + n, cap - n, " sp=%s", l->space);
    if (l->fields & CRICKET_FIELD_DB) n += (size_t)snprintf(buf + n, cap - n, " db=%g", (double)l->db);
    if (l->fields & CRICKET_FIELD_DR) n += (size_t)snprintf(buf + n, cap - n, " dr=%u", (unsigned)l->dr_us);
    if (l->fields & CRICKET_FIELD_TM) n += (size_t)snprintf(buf + n, cap - n, " tm=%u", (unsigned)l->tm);
    if (l->fields & CRICKET_FIELD_TS) (void)snprintf(buf + n, cap - n, " ts=%u", (unsigned)l->ts);
}

// The shared vectors: docs/cricket-lines.tsv, which dynaqpc-cricket's parser is tested against too.
static void test_parse_shared_vectors(void **state)
{
    (void)state;
    FILE *f = fopen(CRICKET_LINES_TSV, "r");
    assert_non_null(f);
    char row[512], got[256];
    unsigned vectors = 0, bad = 0;
    while (fgets(row, sizeof row, f) != NULL) {
        size_t n = strcspn(row, "\r\n");
        row[n] = '\0';
        if (row[0] == '#' || n == 0u) continue;
        char *tab = strchr(row, '\t');
        assert_non_null(tab);
        *tab = '\0';
        const char *want = row, *line = tab + 1;
        cricket_line_t l;
        const int err = cricket_parse_line(line, strlen(line), &l);
        if (strcmp(want, "bad") == 0) {
            if (err != FW_ERR_INVAL) fail_msg("accepted a bad line: %s", line);
            bad++;
        } else {
            if (err != FW_OK) fail_msg("refused: %s", line);
            describe_line(&l, got, sizeof got);
            if (strcmp(got, want) != 0) fail_msg("%s\n  read: %s\n  want: %s", line, got, want);
        }
        vectors++;
    }
    fclose(f);
    assert_true(vectors >= 40u && bad >= 20u);  // the file was read, not skipped
}

static void test_parse_full_line(void **state)
{
    (void)state;
    const char *s = "VR=2.0,ID=01:2a:e4:8a:0b:00:00:ac,SP=MIT-1,DB=210,DR=6174,TM=7012,TS=32457";
    cricket_line_t l;
    assert_int_equal(cricket_parse_line(s, strlen(s), &l), FW_OK);
    assert_int_equal(l.fields, 0x7Fu);
    assert_true(l.id == 0x012AE48A0B0000ACu);
    assert_string_equal(l.space, "MIT-1");
    assert_float_equal(l.db, 210.0f, 0.0f);
    assert_int_equal(l.dr_us, 6174);
    assert_int_equal(l.tm, 7012);
    assert_int_equal(l.ts, 32457);
}

static void test_parse_by_key_with_fields_off_and_unknown_keys(void **state)
{
    (void)state;
    cricket_line_t l;
    const char *no_db = "ID=01:2a:e4:8a:0b:00:00:ac,DR=6174";
    assert_int_equal(cricket_parse_line(no_db, strlen(no_db), &l), FW_OK);
    assert_int_equal(l.fields, CRICKET_FIELD_ID | CRICKET_FIELD_DR);
    const char *reordered = "DB=14.5,XX=whatever,ID=1:2:3:4:5:6:7:8";
    assert_int_equal(cricket_parse_line(reordered, strlen(reordered), &l), FW_OK);
    assert_int_equal(l.fields, CRICKET_FIELD_ID | CRICKET_FIELD_DB);
    assert_float_equal(l.db, 14.5f, 1e-6f);
    assert_true(l.id == 0x0102030405060708u);
}

static void test_parse_rejects_malformed_lines(void **state)
{
    (void)state;
    static const char *const bad[] = {
        "DR=12a",                                   // not a number
        "DR=-5",                                    // no sign allowed
        "DR=99999999999",                           // overflows 32 bits
        "DB=1.2.3",                                 // two dots
        "DB=.",                                     // no digits
        "ID=01:2a:e4:8a:0b:00:00",                  // 7 bytes
        "ID=01:2a:e4:8a:0b:00:00:ac:01",            // 9 bytes
        "ID=01:2a:e4:8a:0b:00:00:acc",              // 3 digits
        "ID=01:2a:e4:8a:0b:00:00:zz",               // not hex
        "ID=01:2a:e4:8a:0b:00:00:",                 // trailing colon
        "DR=100,DR=200",                            // duplicate key
        "DR=100,garbage",                           // field without '='
        "DR=100,",                                  // empty trailing field
        "=5",                                       // no key
        "DR=",                                      // empty value
        "SP=abcdefghijklmnopq",                     // space id longer than 16
        "VR=",                                      // empty version
    };
    for (unsigned i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        cricket_line_t l;
        if (cricket_parse_line(bad[i], strlen(bad[i]), &l) != FW_ERR_INVAL) {
            fail_msg("accepted: %s", bad[i]);
        }
    }
}

static void test_stream_split_across_reads_and_line_ends(void **state)
{
    (void)state;
    cricket_t ck;
    setup_listener(&ck);
    char line[128];
    format_line(line, sizeof line, 0, 1000.0f, 1000.0f);
    // Byte by byte: the range is stored exactly when the line ends.
    size_t stored = 0;
    for (size_t i = 0; i < strlen(line); i++) {
        stored += cricket_feed(&ck, (const uint8_t *)&line[i], 1, 100u);
        if (i + 2u < strlen(line)) {
            assert_int_equal(stored, 0);
        }
    }
    assert_int_equal(stored, 1);
    assert_true(ck.range[0].valid && ck.range[0].from_dr);
    // LF only, CR only, and Xon/Xoff bytes in the middle all work; empty lines are nothing.
    assert_int_equal(feed_str(&ck, "ID=01:aa:e4:8a:0b:00:00:ad,DR=5000\n", 200u), 1);
    assert_int_equal(feed_str(&ck, "\n\r\n\r\rID=01:aa:e4:8a:0b:00:00:ae,D\x13R=5\x11" "000\r", 300u), 1);
    assert_float_equal(ck.range[2].range_mm, 5000.0f * 0.343f, 1e-3f);
    assert_int_equal(ck.stats.lines, 3);
    assert_int_equal(ck.stats.malformed + ck.stats.garbage + ck.stats.overlong, 0);
}

static void test_garbage_and_overlong_lines_are_dropped_and_counted(void **state)
{
    (void)state;
    cricket_t ck;
    setup_listener(&ck);
    // Binary noise (a listener reset), then a good line: only the good one counts.
    const uint8_t noise[] = {0x00, 0xFF, 0x80, 'D', 'R', 0x1B, '=', '5', '\n'};
    assert_int_equal(cricket_feed(&ck, noise, sizeof noise, 1u), 0);
    assert_int_equal(ck.stats.garbage, 1);
    // A line longer than the buffer: dropped whole, including its tail after the overflow.
    char longline[400];
    memset(longline, 'A', sizeof longline);
    memcpy(longline, "DR=1,XX=", 8);
    longline[sizeof longline - 1] = '\n';
    assert_int_equal(cricket_feed(&ck, (const uint8_t *)longline, sizeof longline, 2u), 0);
    assert_int_equal(ck.stats.overlong, 1);
    assert_int_equal(feed_str(&ck, "ID=01:aa:e4:8a:0b:00:00:ac,DR=6000\r\n", 3u), 1);
    // Parse errors, lines without a range, unknown beacons, absurd ranges.
    assert_int_equal(feed_str(&ck, "ID=01:aa:e4:8a:0b:00:00:ac,DR=6x00\n", 4u), 0);
    assert_int_equal(feed_str(&ck, "VR=2.0,ID=01:aa:e4:8a:0b:00:00:ac,TS=1\n", 4u), 0);
    assert_int_equal(feed_str(&ck, "ID=99:aa:e4:8a:0b:00:00:ac,DR=6000\n", 4u), 0);
    assert_int_equal(feed_str(&ck, "ID=01:aa:e4:8a:0b:00:00:ac,DR=0\n", 4u), 0);
    assert_int_equal(feed_str(&ck, "ID=01:aa:e4:8a:0b:00:00:ac,DR=100000\n", 4u), 0);
    assert_int_equal(ck.stats.malformed, 1);
    assert_int_equal(ck.stats.no_range, 1);
    assert_int_equal(ck.stats.unknown_beacon, 1);
    assert_int_equal(ck.stats.bad_range, 2);
    assert_int_equal(ck.stats.ranges, 1);
    assert_float_equal(ck.range[0].range_mm, 6000.0f * 0.343f, 1e-3f);
}

static void test_dr_is_preferred_over_db(void **state)
{
    (void)state;
    cricket_t ck;
    setup_listener(&ck);
    assert_int_equal(feed_str(&ck, "ID=01:aa:e4:8a:0b:00:00:ac,DB=300,DR=6000\n", 1u), 1);
    assert_float_equal(ck.range[0].range_mm, 2058.0f, 1e-2f);
    assert_int_equal(feed_str(&ck, "ID=01:aa:e4:8a:0b:00:00:ac,DB=300\n", 2u), 1);
    assert_float_equal(ck.range[0].range_mm, 3000.0f, 1e-3f);
    assert_false(ck.range[0].from_dr);
}

static void feed_all(cricket_t *ck, float x, float y, uint64_t t0, uint64_t step)
{
    char line[128];
    for (unsigned b = 0; b < 4u; b++) {
        format_line(line, sizeof line, b, x, y);
        assert_int_equal(feed_str(ck, line, t0 + b * step), 1);
    }
}

static void test_fix_states_follow_motion_and_age(void **state)
{
    (void)state;
    cricket_t ck;
    setup_listener(&ck);
    cricket_fix_t fix;
    assert_int_equal(cricket_get_fix(&ck, 0u, &fix), CRICKET_FIX_LOST);

    // Standing at (1200, 2100): four beacons within 4 s -> fresh, about 1 mm (DR is rounded
    // to whole µs = 0.34 mm).
    feed_all(&ck, 1200.0f, 2100.0f, 1000000u, 1000000u);
    assert_int_equal(cricket_get_fix(&ck, 4000000u, &fix), CRICKET_FIX_FRESH);
    assert_float_equal(fix.x_mm, 1200.0f, 2.0f);
    assert_float_equal(fix.y_mm, 2100.0f, 2.0f);
    assert_int_equal(fix.n_ranges, 4);  // the 1 s range is 3 s old: still within max_age

    // Standing still but the listener hears nothing: the ranges age -> stale, then lost.
    assert_int_equal(cricket_get_fix(&ck, 7500000u, &fix), CRICKET_FIX_STALE);
    assert_int_equal(cricket_get_fix(&ck, 20000000u, &fix), CRICKET_FIX_LOST);

    // A nudge of 36 mm to (1230, 2120); one beacon heard after the motion: the fix mixes ranges
    // from before and after, and says so (MOVING).
    feed_all(&ck, 1200.0f, 2100.0f, 21000000u, 100000u);
    cricket_note_motion(&ck, 21500000u);
    char line[128];
    format_line(line, sizeof line, 0, 1230.0f, 2120.0f);
    assert_int_equal(feed_str(&ck, line, 22000000u), 1);
    assert_int_equal(cricket_get_fix(&ck, 22000000u, &fix), CRICKET_FIX_MOVING);
    format_line(line, sizeof line, 1, 1230.0f, 2120.0f);
    feed_str(&ck, line, 23000000u);
    assert_int_equal(cricket_get_fix(&ck, 23000000u, &fix), CRICKET_FIX_MOVING);
    // The third post-motion range fixes the position from the post-motion beacons only.
    format_line(line, sizeof line, 2, 1230.0f, 2120.0f);
    feed_str(&ck, line, 24000000u);
    assert_int_equal(cricket_get_fix(&ck, 24000000u, &fix), CRICKET_FIX_FRESH);
    assert_int_equal(fix.n_ranges, 3);
    assert_float_equal(fix.x_mm, 1230.0f, 2.0f);
    assert_float_equal(fix.y_mm, 2120.0f, 2.0f);

    // A real step (25 cm) with one beacon heard since: never FRESH until three beacons have
    // been heard after the step; with three, a room of four beacons waits for the fourth up to
    // 1.5 s after the motion (three ranges cannot show which one is wrong).
    cricket_note_motion(&ck, 24500000u);
    format_line(line, sizeof line, 3, 1480.0f, 2120.0f);
    feed_str(&ck, line, 25000000u);
    assert_int_not_equal(cricket_get_fix(&ck, 25000000u, &fix), CRICKET_FIX_FRESH);
    for (unsigned b = 0; b < 2u; b++) {
        format_line(line, sizeof line, b, 1480.0f, 2120.0f);
        feed_str(&ck, line, 25100000u + b * 100000u);
    }
    assert_int_not_equal(cricket_get_fix(&ck, 25300000u, &fix), CRICKET_FIX_FRESH);
    assert_int_equal(cricket_get_fix(&ck, 26000000u, &fix), CRICKET_FIX_FRESH);
    assert_int_equal(fix.n_ranges, 3);
    assert_float_equal(fix.x_mm, 1480.0f, 2.0f);
    // The fourth beacon heard: a fix from four at once.
    format_line(line, sizeof line, 2, 1480.0f, 2120.0f);
    feed_str(&ck, line, 27000000u);
    cricket_note_motion(&ck, 27100000u);
    for (unsigned b = 0; b < 4u; b++) {
        format_line(line, sizeof line, b, 1500.0f, 2120.0f);
        feed_str(&ck, line, 27200000u + b * 100000u);
    }
    assert_int_equal(cricket_get_fix(&ck, 27500000u, &fix), CRICKET_FIX_FRESH);
    assert_int_equal(fix.n_ranges, 4);
    assert_float_equal(fix.x_mm, 1500.0f, 2.0f);
}

static void test_inconsistent_ranges_are_refused(void **state)
{
    (void)state;
    cricket_t ck;
    setup_listener(&ck);
    feed_all(&ck, 2000.0f, 1500.0f, 1000u, 1000u);
    // A reflection: beacon 3 reports 80 cm too long. The three others agree: it is dropped.
    char line[128];
    snprintf(line, sizeof line, "ID=%s,DR=%u\n", beacon_ids[3],
             (unsigned)lroundf((ck.range[3].range_mm + 800.0f) / 0.343f));
    assert_int_equal(feed_str(&ck, line, 5000u), 1);
    cricket_fix_t fix;
    assert_int_equal(cricket_get_fix(&ck, 6000u, &fix), CRICKET_FIX_FRESH);
    assert_int_equal(fix.n_ranges, 3);
    assert_float_equal(fix.x_mm, 2000.0f, 2.0f);
    assert_float_equal(fix.y_mm, 1500.0f, 2.0f);
    // A second range 50 cm off: no three agree, the fix is refused.
    snprintf(line, sizeof line, "ID=%s,DR=%u\n", beacon_ids[2],
             (unsigned)lroundf((ck.range[2].range_mm + 500.0f) / 0.343f));
    assert_int_equal(feed_str(&ck, line, 7000u), 1);
    assert_int_equal(cricket_get_fix(&ck, 8000u, &fix), CRICKET_FIX_LOST);
    assert_true(ck.stats.inconsistent >= 1u);
}

static void test_config_is_checked(void **state)
{
    (void)state;
    cricket_t ck;
    struct cricket_config cfg;
    cricket_default_config(&cfg);
    cfg.beacons = beacons;
    cfg.n_beacons = 2;
    assert_int_equal(cricket_init(&ck, &cfg), FW_ERR_INVAL);
    cfg.n_beacons = FW_CFG_CRICKET_MAX_BEACONS + 1u;
    assert_int_equal(cricket_init(&ck, &cfg), FW_ERR_INVAL);
    cricket_beacon_t dup[3] = {beacons[0], beacons[1], beacons[0]};
    cfg.beacons = dup;
    cfg.n_beacons = 3;
    assert_int_equal(cricket_init(&ck, &cfg), FW_ERR_INVAL);
    cfg.beacons = beacons;
    cfg.max_line = FW_CFG_CRICKET_LINE_MAX + 1u;
    assert_int_equal(cricket_init(&ck, &cfg), FW_ERR_INVAL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parse_shared_vectors),
        cmocka_unit_test(test_parse_full_line),
        cmocka_unit_test(test_parse_by_key_with_fields_off_and_unknown_keys),
        cmocka_unit_test(test_parse_rejects_malformed_lines),
        cmocka_unit_test(test_stream_split_across_reads_and_line_ends),
        cmocka_unit_test(test_garbage_and_overlong_lines_are_dropped_and_counted),
        cmocka_unit_test(test_dr_is_preferred_over_db),
        cmocka_unit_test(test_fix_states_follow_motion_and_age),
        cmocka_unit_test(test_inconsistent_ranges_are_refused),
        cmocka_unit_test(test_config_is_checked),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
