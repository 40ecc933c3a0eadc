// SPDX-License-Identifier: MIT
// Trilateration: exact ranges give the position to well under 1 mm; ±1 cm range noise stays
// within a bound measured here; near-collinear beacons are refused.
#include "test_common.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fw/fw_prng.h"
#include "drivers/trilat.h"
#include "fw/fw_base.h"

// Four ceiling beacons over the paper's 4.3 m x 3.2 m lab, at slightly different heights.
static const float bx[4] = {300.0f, 4000.0f, 4000.0f, 300.0f};
static const float by[4] = {300.0f, 300.0f, 2900.0f, 2900.0f};
static const float bz[4] = {2500.0f, 2450.0f, 2550.0f, 2400.0f};
#define LISTENER_Z 150.0f

static const struct trilat_params params = {
    .listener_z = LISTENER_Z, .min_spread = 300.0f, .max_residual = 60.0f, .iterations = 8};

static void make_anchors(trilat_anchor_t *a, size_t n, float x, float y)
{
    for (size_t i = 0; i < n; i++) {
        a[i].x = bx[i];
        a[i].y = by[i];
        a[i].z = bz[i];
        float dx = x - bx[i], dy = y - by[i], dz = LISTENER_Z - bz[i];
        a[i].range = sqrtf(dx * dx + dy * dy + dz * dz);
    }
}

// The shared vectors: docs/cricket-fixes.tsv, which dynaqpc-cricket's trilat_solve is tested against too.
static void test_shared_vectors(void **state)
{
    (void)state;
    FILE *f = fopen(CRICKET_FIXES_TSV, "r");
    assert_non_null(f);
    char row[1024];
    unsigned vectors = 0, refused = 0;
    while (fgets(row, sizeof row, f) != NULL) {
        if (row[0] == '#' || row[0] == '\n') continue;
        char *verdict = strtok(row, "\t"), *par = strtok(NULL, "\t"), *anchors = strtok(NULL, "\t\n");
        assert_non_null(verdict);
        assert_non_null(par);
        assert_non_null(anchors);
        struct trilat_params p = {0};
        p.iterations = 8;
        assert_int_equal(sscanf(par, "%f %f %f", &p.listener_z, &p.min_spread, &p.max_residual), 3);
        trilat_anchor_t a[8];
        size_t n = 0;
        for (char *tok = strtok(anchors, ";"); tok != NULL && n < 8; tok = strtok(NULL, ";")) {
            assert_int_equal(sscanf(tok, "%f,%f,%f,%f", &a[n].x, &a[n].y, &a[n].z, &a[n].range), 4);
            n++;
        }
        trilat_result_t r;
        const int err = trilat_solve(a, n, &p, &r);
        float x = 0.0f, y = 0.0f;
        if (sscanf(verdict, "ok %f %f", &x, &y) == 2) {
            if (err != FW_OK) fail_msg("refused (%d), want %s", err, verdict);
            if (fabsf(r.x - x) > 1.0f || fabsf(r.y - y) > 1.0f) fail_msg("fix %.1f %.1f, want %s", r.x, r.y, verdict);
        } else if (strcmp(verdict, "invalid") == 0) {
            assert_int_equal(err, FW_ERR_INVAL);
            refused++;
        } else {
            assert_string_equal(verdict, "inconsistent");
            assert_int_equal(err, FW_ERR_CORRUPT);
            refused++;
        }
        vectors++;
    }
    fclose(f);
    assert_true(vectors >= 10u && refused >= 4u);  // the file was read, not skipped
}

static void test_exact_ranges_give_the_position(void **state)
{
    (void)state;
    float worst = 0.0f;
    for (float x = 0.0f; x <= 4300.0f; x += 430.0f) {
        for (float y = 0.0f; y <= 3200.0f; y += 320.0f) {
            for (size_t n = 3; n <= 4u; n++) {
                trilat_anchor_t a[4];
                make_anchors(a, n, x, y);
                trilat_result_t r;
                assert_int_equal(trilat_solve(a, n, &params, &r), FW_OK);
                float err = hypotf(r.x - x, r.y - y);
                worst = err > worst ? err : worst;
            }
        }
    }
    printf("noise-free worst error over the lab: %.4f mm\n", (double)worst);
    assert_true(worst < 1.0f);
}

static void test_one_cm_noise_stays_within_bound(void **state)
{
    (void)state;
    prng_t rng;
    prng_seed(&rng, 42u);
    float worst = 0.0f, sum2 = 0.0f;
    unsigned trials = 0;
    for (unsigned k = 0; k < 2000u; k++) {
        float x = 200.0f + 3900.0f * prng_unit(&rng);
        float y = 200.0f + 2800.0f * prng_unit(&rng);
        trilat_anchor_t a[4];
        make_anchors(a, 4, x, y);
        for (unsigned i = 0; i < 4u; i++) {
            a[i].range += 20.0f * prng_unit(&rng) - 10.0f;  // uniform ±1 cm
        }
        trilat_result_t r;
        assert_int_equal(trilat_solve(a, 4, &params, &r), FW_OK);
        float err = hypotf(r.x - x, r.y - y);
        worst = err > worst ? err : worst;
        sum2 += err * err;
        trials++;
    }
    printf("±1 cm uniform range noise, 4 ceiling beacons, %u positions: RMS %.1f mm, worst %.1f mm\n",
           trials, (double)sqrtf(sum2 / (float)trials), (double)worst);
    // Ceiling beacons 2.3 m above the listener see horizontal motion at a grazing angle, which
    // magnifies range noise (horizontal dilution of precision); 40 mm is the stated bound.
    assert_true(worst < 40.0f);
}

static void test_collinear_beacons_are_refused(void **state)
{
    (void)state;
    trilat_anchor_t a[3] = {
        {0.0f, 0.0f, 2500.0f, 0.0f}, {2000.0f, 0.0f, 2500.0f, 0.0f}, {4000.0f, 50.0f, 2500.0f, 0.0f}};
    for (unsigned i = 0; i < 3u; i++) {
        float dx = 1000.0f - a[i].x, dy = 1500.0f - a[i].y, dz = LISTENER_Z - a[i].z;
        a[i].range = sqrtf(dx * dx + dy * dy + dz * dz);
    }
    trilat_result_t r;
    assert_int_equal(trilat_solve(a, 3, &params, &r), FW_ERR_INVAL);
    // Exactly collinear, and all at one point.
    a[2].y = 0.0f;
    assert_int_equal(trilat_solve(a, 3, &params, &r), FW_ERR_INVAL);
    a[1].x = a[2].x = 0.0f;
    assert_int_equal(trilat_solve(a, 3, &params, &r), FW_ERR_INVAL);
}

// trilat_geometry_ok() is the rule trilat_solve() refuses geometry by (what dynaqpc-sim's loader
// asks of a scenario's beacons): five beacons along a 9 m corridor, staggered either side of its
// middle by a little less and a little more than min_spread, and in one line.
static void test_geometry_check_is_the_solver_rule(void **state)
{
    (void)state;
    const float offsets[] = {0.0f, 290.0f, 300.0f, 310.0f, 600.0f};
    for (size_t k = 0; k < sizeof offsets / sizeof offsets[0]; k++) {
        trilat_anchor_t a[5];
        for (unsigned i = 0; i < 5u; i++) {
            a[i].x = 900.0f + 1800.0f * (float)i;
            a[i].y = 800.0f + ((i & 1u) ? offsets[k] : -offsets[k]);
            a[i].z = 2500.0f;
            float dx = 4000.0f - a[i].x, dy = 800.0f - a[i].y, dz = LISTENER_Z - a[i].z;
            a[i].range = sqrtf(dx * dx + dy * dy + dz * dz);
        }
        float spread = -1.0f;
        const bool ok = trilat_geometry_ok(a, 5, params.min_spread, &spread);
        trilat_result_t r;
        const int err = trilat_solve(a, 5, &params, &r);
        assert_int_equal(ok, err != FW_ERR_INVAL);
        // Alternate sides, 3 one way and 2 the other: the spread is 0.98 of the offset.
        assert_true(fabsf(spread - offsets[k] * sqrtf(24.0f) / 5.0f) < 1.0f);
        assert_int_equal(ok, offsets[k] * sqrtf(24.0f) / 5.0f >= params.min_spread);
    }
    trilat_anchor_t a[4];
    make_anchors(a, 4, 1000.0f, 1000.0f);
    float spread = -1.0f;
    assert_true(trilat_geometry_ok(a, 4, params.min_spread, &spread));
    assert_true(spread > 1000.0f);
    assert_false(trilat_geometry_ok(a, 2, params.min_spread, &spread));  // two beacons fix nothing
    assert_true(spread == 0.0f);
    assert_true(trilat_geometry_ok(a, 3, params.min_spread, NULL));
}

static void test_bad_inputs_are_refused(void **state)
{
    (void)state;
    trilat_anchor_t a[4];
    make_anchors(a, 4, 1000.0f, 1000.0f);
    trilat_result_t r;
    assert_int_equal(trilat_solve(a, 2, &params, &r), FW_ERR_INVAL);
    a[1].range = -1.0f;
    assert_int_equal(trilat_solve(a, 4, &params, &r), FW_ERR_INVAL);
    a[1].range = NAN;
    assert_int_equal(trilat_solve(a, 4, &params, &r), FW_ERR_INVAL);
    make_anchors(a, 4, 1000.0f, 1000.0f);
    a[2].range += 500.0f;  // one range half a metre off: inconsistent
    assert_int_equal(trilat_solve(a, 4, &params, &r), FW_ERR_CORRUPT);
    assert_true(r.residual_rms > 60.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shared_vectors),
        cmocka_unit_test(test_exact_ranges_give_the_position),
        cmocka_unit_test(test_one_cm_noise_stays_within_bound),
        cmocka_unit_test(test_collinear_beacons_are_refused),
        cmocka_unit_test(test_geometry_check_is_the_solver_rule),
        cmocka_unit_test(test_bad_inputs_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
