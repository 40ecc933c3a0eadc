// SPDX-License-Identifier: MIT
// Tests of the Q store: dense and hashed layouts, unknown states, a full table.
#include "test_common.h"

#include <math.h>
#include <string.h>

#include "agent/qstore.h"
#include "fw/fw_base.h"

static value16_t q_[256 * FW_CFG_MAX_ACTIONS];
static uint32_t keys_[256];

static void small_spaces_are_dense(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, q_, 2, NULL, 256, 4, 8), FW_OK);
    assert_true(qs.dense);
    const qstore_row_t row = qstore_row_for_update(&qs, 255);
    assert_int_equal(row, 255);  // a dense row is its state
    qstore_set(&qs, row, 2, 3.5f);
    assert_float_equal(qstore_get(&qs, 255, 2), 3.5f, 0.0f);
    assert_float_equal(qstore_max(&qs, 255), 3.5f, 0.0f);
    assert_int_equal(q_[255 * 4 + 2], value16_from_float(3.5f));
}

static void large_spaces_are_hashed_and_unknown_states_read_zero(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, q_, 2, NULL, 256, 4, 18), FW_ERR_INVAL);  // needs keys
    assert_int_equal(qstore_init(&qs, q_, 2, keys_, 256, 4, 18), FW_OK);
    assert_false(qs.dense);
    float unknown[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    qstore_values(&qs, 123456, unknown);
    for (int a = 0; a < 4; a++) {
        assert_float_equal(unknown[a], 0.0f, 0.0f);
    }
    assert_int_equal(qs.rows_used, 0);
    const qstore_row_t row = qstore_row_for_update(&qs, 123456);
    qstore_set(&qs, row, 1, -2.0f);
    qstore_set(&qs, row, 3, -1.0f);
    assert_int_equal(qs.rows_used, 1);
    assert_float_equal(qstore_get(&qs, 123456, 1), -2.0f, 0.0f);
    assert_float_equal(qstore_max(&qs, 123456), 0.0f, 0.0f);
    assert_float_equal(qstore_row_max(&qs, row), 0.0f, 0.0f);
    assert_int_equal(qstore_row_for_update(&qs, 123456), row);  // the same row, not a new one
}

static void distinct_states_keep_distinct_values(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, q_, 2, keys_, 256, 4, 18), FW_OK);
    for (uint32_t s = 0; s < 150; s++) {
        const qstore_row_t row = qstore_row_for_update(&qs, s * 1021u);
        assert_int_not_equal(row, QSTORE_NO_ROW);
        qstore_set(&qs, row, (uint8_t)(s % 4), (float)s);
    }
    assert_int_equal(qs.dropped, 0);
    for (uint32_t s = 0; s < 150; s++) {
        assert_float_equal(qstore_get(&qs, s * 1021u, (uint8_t)(s % 4)), (float)s, 0.0f);
    }
}

static void full_table_forgets_what_it_learned_least(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, q_, 2, keys_, 256, 4, 20), FW_OK);
    // State 7 has learned something big; then 1000 states pass through a 256-row table.
    qstore_set(&qs, qstore_row_for_update(&qs, 7), 2, -50.0f);
    for (uint32_t s = 1000; s < 2000; s++) {
        const qstore_row_t row = qstore_row_for_update(&qs, s);
        assert_int_not_equal(row, QSTORE_NO_ROW);  // a write always finds a row
        qstore_set(&qs, row, 0, -0.5f);            // each visited once
    }
    assert_true(qs.rows_used <= 256 && qs.rows_used > 200);
    assert_true(qs.dropped >= 1000 - 256 + 1);
    assert_float_equal(qstore_get(&qs, 7, 2), -50.0f, 0.0f);  // the well-learned row survives
    assert_float_equal(qstore_get(&qs, 1999, 0), -0.5f, 0.0f);  // the newest is there
    qstore_clear(&qs);
    assert_int_equal(qs.rows_used, 0);
    assert_int_not_equal(qstore_row_for_update(&qs, 999), QSTORE_NO_ROW);
}

static void planning_never_forgets_a_state(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, q_, 2, keys_, 256, 4, 20), FW_OK);
    for (uint32_t s = 1000; s < 2000; s++) {  // real steps fill the table
        qstore_set(&qs, qstore_row_for_update(&qs, s), 0, -1.0f);
    }
    uint32_t known[256];
    uint32_t n_known = 0;
    for (uint32_t i = 0; i < 256; i++) {
        if (keys_[i] != QSTORE_EMPTY) {
            known[n_known++] = keys_[i];
        }
    }
    const uint32_t dropped = qs.dropped;
    assert_int_not_equal(qstore_row_for_plan(&qs, known[0]), QSTORE_NO_ROW);  // a known state plans in its row
    uint32_t refused = 0;
    for (uint32_t s = 5000; s < 6000; s++) {  // unknown states find no free row, or take one
        refused += qstore_row_for_plan(&qs, s) == QSTORE_NO_ROW;
    }
    assert_true(refused > 0);
    assert_int_equal(qs.plan_refused, refused);
    assert_int_equal(qs.dropped, dropped);  // planning forgot nothing
    for (uint32_t i = 0; i < n_known; i++) {
        assert_float_equal(qstore_get(&qs, known[i], 0), -1.0f, 0.0f);
    }
    qstore_clear(&qs);
    assert_int_not_equal(qstore_row_for_plan(&qs, 5000), QSTORE_NO_ROW);  // a free row is taken
    assert_int_equal(qs.rows_used, 1);
}

// A prior: what a state never written reads, where its row starts, what a full window measures
// learning against; a dense store's every row starts there.
static void unknown_states_read_the_prior(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, q_, 2, keys_, 256, 4, 20), FW_OK);
    qstore_set_prior(&qs, -20.0f);
    assert_float_equal(qstore_get(&qs, 4242, 3), -20.0f, 0.0f);
    assert_float_equal(qstore_max(&qs, 4242), -20.0f, 0.0f);
    const qstore_row_t row = qstore_row_for_update(&qs, 4242);
    float q;
    assert_true(qstore_learn(&qs, row, 1, -10.0f, 0.5f, &q));
    assert_float_equal(q, -15.0f, 0.0f);  // learning starts from the prior, not from 0
    assert_float_equal(qstore_get(&qs, 4242, 0), -20.0f, 0.0f);  // the row's other actions too
    assert_float_equal(qstore_row_max(&qs, row), -15.0f, 0.0f);
    // One lookup for several values: the row of a known state, none of an unknown one.
    assert_int_equal(qstore_row_of(&qs, 4242), row);
    assert_float_equal(qstore_row_get(&qs, row, 1), -15.0f, 0.0f);
    assert_float_equal(qstore_row_get(&qs, row, 0), -20.0f, 0.0f);
    assert_int_equal(qstore_row_of(&qs, 4243), QSTORE_NO_ROW);
    assert_float_equal(qstore_row_get(&qs, QSTORE_NO_ROW, 2), -20.0f, 0.0f);
    assert_float_equal(qstore_row_max(&qs, QSTORE_NO_ROW), -20.0f, 0.0f);
    // A full table forgets the row nearest the prior: a row at -20 has learned nothing, one
    // at 0 has learned 20 in each action.
    qstore_set(&qs, qstore_row_for_update(&qs, 7), 2, 0.0f);
    for (uint32_t s = 1000; s < 2000; s++) {
        qstore_set(&qs, qstore_row_for_update(&qs, s), 0, -20.5f);
    }
    assert_true(qs.dropped > 0);
    assert_float_equal(qstore_get(&qs, 7, 2), 0.0f, 0.0f);
    assert_float_equal(qstore_get(&qs, 7, 1), -20.0f, 0.0f);
    qstore_clear(&qs);  // a cleared store keeps its prior; its empty rows are zeros
    assert_float_equal(qstore_get(&qs, 7, 2), -20.0f, 0.0f);
    for (uint32_t i = 0; i < 256 * 4; i++) {
        assert_int_equal(q_[i], 0);
    }
    // Dense: every row exists from the start, at the prior.
    assert_int_equal(qstore_init(&qs, q_, 2, NULL, 256, 4, 8), FW_OK);
    assert_float_equal(qstore_get(&qs, 200, 1), 0.0f, 0.0f);
    qstore_set_prior(&qs, -5.0f);
    for (uint32_t s = 0; s < 256; s++) {
        assert_float_equal(qstore_max(&qs, s), -5.0f, 0.0f);
    }
}

static void init_rejects_bad_arguments(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, q_, 2, keys_, 100, 4, 8), FW_ERR_INVAL);
    assert_int_equal(qstore_init(&qs, q_, 3, keys_, 256, 4, 8), FW_ERR_INVAL);  // 2 or 4 bytes
    assert_int_equal(qstore_init(&qs, q_, 2, keys_, 256, 0, 8), FW_ERR_INVAL);
    assert_int_equal(qstore_init(&qs, q_, 2, keys_, 256, FW_CFG_MAX_ACTIONS + 1, 8), FW_ERR_INVAL);
}

static value16_t q2_[256 * FW_CFG_MAX_ACTIONS];
static uint32_t keys2_[256];
static uint32_t image_keys_[256];

// The store's own save regions, checked and restored into a second store over other arrays,
// give the same values and fill; a saved key a search cannot reach is refused.
static void saved_regions_check_and_restore_themselves(void **state)
{
    (void)state;
    qstore_t qs;
    qstore_t back;
    assert_int_equal(qstore_init(&qs, q_, 2, keys_, 256, 4, 18), FW_OK);
    for (uint32_t s = 0; s < 1000; s++) {  // more states than rows: some are forgotten
        qstore_set(&qs, qstore_row_for_update(&qs, s * 613u % 262144u), (uint8_t)(s % 4),
                   (float)(s + 1u));
    }
    assert_true(qs.dropped > 0);
    agent_region_t r[QSTORE_MAX_REGIONS];
    assert_int_equal(qstore_regions(&qs, r), 2);
    assert_ptr_equal(r[0].data, q_);
    assert_int_equal(r[0].size, 256 * 4 * sizeof(value16_t));
    assert_ptr_equal(r[1].data, keys_);
    assert_int_equal(r[1].size, 256 * sizeof(uint32_t));
    const void *image[QSTORE_MAX_REGIONS] = {r[0].data, r[1].data};
    assert_int_equal(qstore_check(&qs, image, 18), FW_OK);

    assert_int_equal(qstore_init(&back, q2_, 2, keys2_, 256, 4, 18), FW_OK);
    agent_region_t rb[QSTORE_MAX_REGIONS];
    assert_int_equal(qstore_regions(&back, rb), 2);
    for (uint32_t i = 0; i < 2; i++) {
        memcpy(rb[i].data, r[i].data, r[i].size);
    }
    qstore_restored(&back);
    assert_int_equal(back.rows_used, qs.rows_used);
    for (uint32_t s = 0; s < 1000; s++) {
        const agent_state_t st = s * 613u % 262144u;
        float a[4];
        float b[4];
        qstore_values(&back, st, a);
        qstore_values(&qs, st, b);
        assert_memory_equal(a, b, sizeof a);
    }

    // A stored key copied FW_CFG_MAX_PROBE slots on: past its window, where no search looks.
    uint32_t slot = 0;
    while (keys_[slot] == QSTORE_EMPTY) {
        slot++;
    }
    const uint32_t far = (slot + FW_CFG_MAX_PROBE) % 256u;
    memcpy(image_keys_, keys_, sizeof image_keys_);
    image_keys_[far] = keys_[slot];
    const void *bad[QSTORE_MAX_REGIONS] = {q_, image_keys_};
    assert_int_equal(qstore_check(&qs, bad, 18), FW_ERR_CORRUPT);
    // A key of more bits than a state has.
    memcpy(image_keys_, keys_, sizeof image_keys_);
    image_keys_[slot] = keys_[slot] | (1u << 18);
    assert_int_equal(qstore_check(&qs, bad, 18), FW_ERR_CORRUPT);
    memcpy(image_keys_, keys_, sizeof image_keys_);
    assert_int_equal(qstore_check(&qs, bad, 18), FW_OK);

    // A dense store saves its values only.
    assert_int_equal(qstore_init(&qs, q_, 2, NULL, 256, 4, 8), FW_OK);
    assert_int_equal(qstore_regions(&qs, r), 1);
}

// Every value16 converts to a float and back to itself; negative zero keeps its sign bit.
static void every_value16_round_trips(void **state)
{
    (void)state;
    uint32_t values = 0;
    for (uint32_t v = 0; v <= 0xffffu; v++) {
        if (!value16_ok((value16_t)v)) {
            continue;  // exponent 63 is never stored
        }
        values++;
        assert_int_equal(value16_from_float(value16_to_float((value16_t)v)), v);
    }
    assert_int_equal(values, 2u * 63u * 512u);
    assert_float_equal(value16_to_float(0x3e00u), 1.0f, 0.0f);
    assert_float_equal(value16_to_float(0xc280u), -5.0f, 0.0f);
    assert_float_equal(value16_to_float(0x7dffu), VALUE16_MAX, 0.0f);
    assert_float_equal(value16_to_float(0x0001u), 0x1p-39f, 0.0f);  // the smallest subnormal
    assert_float_equal(value16_to_float(0x0200u), 0x1p-30f, 0.0f);  // the smallest normal
}

// The store reads every value16 as value16_to_float() gives it, bit for bit (the host's builds
// read them by a multiplication: fw_config.h, FW_CFG_VALUE16_BY_SCALING), the signed zeros and
// the subnormal values included.
static void the_store_reads_every_value16_exactly(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, q_, 2, NULL, 256, 4, 8), FW_OK);
    for (uint32_t v = 0; v <= 0xffffu; v++) {
        if (!value16_ok((value16_t)v)) {
            continue;
        }
        q_[5u * 4u + 2u] = (value16_t)v;
        const float want = value16_to_float((value16_t)v);
        const float got = qstore_get(&qs, 5, 2);
        assert_memory_equal(&got, &want, sizeof want);
    }
}

// Rounding is to nearest with ties to even, in the normal and the subnormal range; beyond the
// largest value16 a value saturates; a gridworld's far values keep their 10 bits.
static void conversion_rounds_to_nearest_even_and_saturates(void **state)
{
    (void)state;
    // 1 + 2^-10 lies halfway between 1 and 1 + 2^-9: to the even one, 1.
    assert_int_equal(value16_from_float(1.0f + 0x1p-10f), 0x3e00u);
    // 1 + 3 * 2^-10 lies halfway between 1 + 2^-9 (odd) and 1 + 2^-8 (even).
    assert_int_equal(value16_from_float(1.0f + 3.0f * 0x1p-10f), 0x3e02u);
    // Just above halfway rounds up.
    assert_int_equal(value16_from_float(1.0f + 0x1p-10f + 0x1p-20f), 0x3e01u);
    // Subnormal: 1.5 * 2^-39 ties to 2 * 2^-39 (even); 0.5 * 2^-39 ties to 0.
    assert_int_equal(value16_from_float(1.5f * 0x1p-39f), 0x0002u);
    assert_int_equal(value16_from_float(0.5f * 0x1p-39f), 0x0000u);
    assert_int_equal(value16_from_float(-0.75f * 0x1p-39f), 0x8001u);
    // A carry out of the fraction moves to the next binade: 1023.5 rounds to 1024.
    assert_int_equal(value16_from_float(1023.5f), value16_from_float(1024.0f));
    // The values a robot's Q takes, and a gridworld's 240 steps from its goal.
    assert_float_equal(value16_to_float(value16_from_float(-100.0f)), -100.0f, 0.0f);
    assert_float_equal(value16_to_float(value16_from_float(-1.9f)), -1.9f, 1.9f * 0x1p-10f);
    assert_float_equal(value16_to_float(value16_from_float(87.654f)), 87.654f, 87.654f * 0x1p-10f);
    const float far = powf(0.95f, 240.0f);
    assert_float_equal(value16_to_float(value16_from_float(far)), far, far * 0x1p-10f);
    assert_int_equal(value16_from_float(1e10f), 0x7dffu);
    assert_int_equal(value16_from_float(-1e30f), 0xfdffu);
}

// A learning write is computed in float and stored rounded; a restored image holding exponent
// 63 is refused.
static void learning_rounds_each_write_and_bad_values_are_refused(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, q_, 2, keys_, 256, 4, 18), FW_OK);
    const qstore_row_t row = qstore_row_for_update(&qs, 42);
    // From 0 towards 100 with alpha 0.9, then 0.1: each stored value is the nearest half.
    float q = -1.0f;
    assert_true(qstore_learn(&qs, row, 1, 100.0f, 0.9f, &q));
    assert_float_equal(q, 90.0f, 0.0f);
    assert_true(qstore_learn(&qs, row, 1, 93.7f, 0.1f, &q));
    assert_float_equal(q, value16_to_float(value16_from_float(90.0f + 0.1f * 3.7f)), 0.0f);
    assert_float_equal(qstore_get(&qs, 42, 1), q, 0.0f);
    // Many updates towards a target come within one half step of it (no drift, no stall far off).
    int changed = 0;
    for (int i = 0; i < 200; i++) {
        changed += qstore_learn(&qs, row, 2, -37.3f, 0.5f, &q);
    }
    assert_float_equal(q, -37.3f, 37.3f * 0x1p-9f);
    assert_in_range(changed, 10, 20);  // then the value rounds back to itself: no change
    assert_false(qstore_moves(&qs, q, -37.3f, 0.5f));
    assert_true(qstore_moves(&qs, q, -30.0f, 0.5f));

    agent_region_t r[QSTORE_MAX_REGIONS];
    assert_int_equal(qstore_regions(&qs, r), 2);
    memcpy(q2_, q_, sizeof q2_);
    const void *image[QSTORE_MAX_REGIONS] = {q2_, r[1].data};
    assert_int_equal(qstore_check(&qs, image, 18), FW_OK);
    q2_[row * 4 + 1] = 0x7e00u;  // exponent 63
    assert_int_equal(qstore_check(&qs, image, 18), FW_ERR_CORRUPT);
    q2_[row * 4 + 1] = 0xffffu;  // exponent 63, negative
    assert_int_equal(qstore_check(&qs, image, 18), FW_ERR_CORRUPT);
}

static float qf_[256 * FW_CFG_MAX_ACTIONS];

// A store of floats keeps what it is given exactly (no rounding), forgets and saves as the
// 16-bit one does, and refuses a restored NaN or a value beyond its limit.
static void a_float_store_keeps_floats(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, qf_, 4, keys_, 256, 4, 18), FW_OK);
    const qstore_row_t row = qstore_row_for_update(&qs, 4321);
    float q = 0.0f;
    assert_true(qstore_learn(&qs, row, 3, 1.0f + 0x1p-20f, 1.0f, &q));
    assert_float_equal(q, 1.0f + 0x1p-20f, 0.0f);  // a value16 would round this to 1
    assert_true(qstore_moves(&qs, 1.0f, 1.0f + 0x1p-20f, 1.0f));
    assert_float_equal(qstore_max(&qs, 4321), 1.0f + 0x1p-20f, 0.0f);
    assert_float_equal(qstore_get(&qs, 1234, 0), 0.0f, 0.0f);  // unknown: zeros
    agent_region_t r[QSTORE_MAX_REGIONS];
    assert_int_equal(qstore_regions(&qs, r), 2);
    assert_int_equal(r[0].size, 256 * 4 * sizeof(float));
    const void *image[QSTORE_MAX_REGIONS] = {r[0].data, r[1].data};
    assert_int_equal(qstore_check(&qs, image, 18), FW_OK);
    qf_[row * 4 + 3] = 2e9f;  // beyond QSTORE_VALUE_LIMIT
    assert_int_equal(qstore_check(&qs, image, 18), FW_ERR_CORRUPT);
    qf_[row * 4 + 3] = 0.0f / 0.0f;
    assert_int_equal(qstore_check(&qs, image, 18), FW_ERR_CORRUPT);
    qstore_clear(&qs);
    assert_int_equal(qstore_check(&qs, image, 18), FW_OK);
}

// ---- 16-bit keys (qstore_init16) ----------------------------------------------------------------

#define K16_ROWS 4096u
static value16_t q32_[K16_ROWS * FW_CFG_MAX_ACTIONS];
static value16_t q16_[K16_ROWS * FW_CFG_MAX_ACTIONS];
static uint32_t k32_[K16_ROWS];
static uint32_t k16_words_[K16_ROWS / 2];  // 16-bit keys, 4-byte aligned

// The claim behind qstore_keys16_exact(): for 2^12..2^16 rows, two states of up to 20 bits with
// the same low 15 bits have homes at least a probe window apart (the home depends on the state
// and the rows alone, so 20 bits covers every narrower state).
static void keys16_windows_never_overlap(void **state)
{
    (void)state;
    for (uint32_t bits = 12; bits <= 16; bits++) {
        oa_table_t t;
        assert_int_equal(oa_init(&t, k32_, 1u << bits, oa_probe_limit(1u << bits), OA_HOME_HIGH), FW_OK);
        uint32_t least = UINT32_MAX;
        for (uint32_t lo = 0; lo < (1u << QSTORE_KEY16_BITS); lo++) {
            uint32_t home[32];
            for (uint32_t hi = 0; hi < 32u; hi++) {
                home[hi] = oa_home(&t, lo | (hi << QSTORE_KEY16_BITS));
                for (uint32_t j = 0; j < hi; j++) {
                    const uint32_t d = (home[hi] - home[j]) & t.mask;
                    const uint32_t e = (home[j] - home[hi]) & t.mask;
                    const uint32_t near = d < e ? d : e;
                    least = near < least ? near : least;
                }
            }
        }
        assert_true(least >= FW_CFG_MAX_PROBE);
        assert_true(qstore_keys16_exact(1u << bits, 20));
    }
    assert_false(qstore_keys16_exact(1u << 14, 21));
    assert_false(qstore_keys16_exact(1u << 11, 20));
    assert_true(qstore_keys16_exact(1u << 8, 15));
}

// The same calls give the same rows, values and counts with 16-bit keys as with 32-bit ones, on
// a table kept full (states share their low bits often, and evictions are frequent).
static void keys16_give_the_table_of_32_bit_keys(void **state)
{
    (void)state;
    qstore_t a;
    qstore_t b;
    uint16_t *const k16 = (uint16_t *)(void *)k16_words_;
    assert_int_equal(qstore_init(&a, q32_, 2, k32_, K16_ROWS, 4, 20), FW_OK);
    assert_int_equal(qstore_init16(&b, q16_, 2, k16, K16_ROWS, 4, 20), FW_OK);
    assert_int_equal(qstore_init16(&b, q16_, 2, k16 + 1, K16_ROWS, 4, 20), FW_ERR_INVAL);  // alignment
    assert_int_equal(qstore_init16(&b, q16_, 2, k16, K16_ROWS, 4, 21), FW_ERR_INVAL);  // not exact
    assert_int_equal(qstore_init16(&b, q16_, 2, k16, K16_ROWS, 4, 20), FW_OK);
    qstore_set_prior(&a, -20.0f);
    qstore_set_prior(&b, -20.0f);
    uint32_t x = 12345u;
    for (uint32_t i = 0; i < 200000u; i++) {
        x = x * 1664525u + 1013904223u;
        // 2,048 low parts, each with any of 32 high parts: 65,536 states for 4,096 rows.
        const agent_state_t s = ((x >> 8) & 2047u) * 7u | (((x >> 20) & 31u) << QSTORE_KEY16_BITS);
        const uint8_t act = (uint8_t)(x >> 30);
        const bool plan = (x & 3u) == 0u;
        const qstore_row_t ra = plan ? qstore_row_for_plan(&a, s) : qstore_row_for_update(&a, s);
        const qstore_row_t rb = plan ? qstore_row_for_plan(&b, s) : qstore_row_for_update(&b, s);
        assert_int_equal(ra, rb);
        if (ra != QSTORE_NO_ROW) {
            assert_int_equal(qstore_learn(&a, ra, act, (float)(x % 200u) - 100.0f, 0.5f, NULL),
                             qstore_learn(&b, rb, act, (float)(x % 200u) - 100.0f, 0.5f, NULL));
        }
        assert_float_equal(qstore_max(&a, s ^ 1u), qstore_max(&b, s ^ 1u), 0.0f);
        assert_int_equal(qstore_has_row(&a, s ^ (1u << 16)), qstore_has_row(&b, s ^ (1u << 16)));
    }
    assert_true(a.dropped > 1000u && a.plan_refused > 0u);
    assert_int_equal(a.dropped, b.dropped);
    assert_int_equal(a.plan_refused, b.plan_refused);
    assert_int_equal(a.rows_used, b.rows_used);
    assert_memory_equal(q32_, q16_, sizeof q32_);
    for (uint32_t i = 0; i < K16_ROWS; i++) {
        assert_int_equal(k32_[i] == QSTORE_EMPTY ? QSTORE_EMPTY16 : (k32_[i] & 0x7FFFu), k16[i]);
    }

    // Saved and checked: the regions are 2 bytes a key; a key moved out of its window is refused.
    agent_region_t r[QSTORE_MAX_REGIONS];
    assert_int_equal(qstore_regions(&b, r), 2);
    assert_int_equal(r[1].size, K16_ROWS * sizeof(uint16_t));
    const void *image[QSTORE_MAX_REGIONS] = {r[0].data, r[1].data};
    assert_int_equal(qstore_check(&b, image, 20), FW_OK);
    const uint32_t used = b.rows_used;
    qstore_restored(&b);
    assert_int_equal(b.rows_used, used);
    uint32_t slot = 0;
    while (k16[slot] == QSTORE_EMPTY16) {
        slot++;
    }
    const uint16_t saved = k16[(slot + 100u) % K16_ROWS];
    k16[(slot + 100u) % K16_ROWS] = k16[slot];
    assert_int_equal(qstore_check(&b, image, 20), FW_ERR_CORRUPT);
    k16[(slot + 100u) % K16_ROWS] = saved;
    const uint16_t key = k16[slot];
    k16[slot] = 0x8001u;  // top bit set: not a key
    assert_int_equal(qstore_check(&b, image, 20), FW_ERR_CORRUPT);
    k16[slot] = key;
    assert_int_equal(qstore_check(&b, image, 20), FW_OK);
    qstore_clear(&b);
    assert_int_equal(b.rows_used, 0);
    assert_int_equal(k16[slot], QSTORE_EMPTY16);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(small_spaces_are_dense),
        cmocka_unit_test(large_spaces_are_hashed_and_unknown_states_read_zero),
        cmocka_unit_test(distinct_states_keep_distinct_values),
        cmocka_unit_test(full_table_forgets_what_it_learned_least),
        cmocka_unit_test(planning_never_forgets_a_state),
        cmocka_unit_test(unknown_states_read_the_prior),
        cmocka_unit_test(init_rejects_bad_arguments),
        cmocka_unit_test(saved_regions_check_and_restore_themselves),
        cmocka_unit_test(every_value16_round_trips),
        cmocka_unit_test(the_store_reads_every_value16_exactly),
        cmocka_unit_test(a_float_store_keeps_floats),
        cmocka_unit_test(conversion_rounds_to_nearest_even_and_saturates),
        cmocka_unit_test(learning_rounds_each_write_and_bad_values_are_refused),
        cmocka_unit_test(keys16_windows_never_overlap),
        cmocka_unit_test(keys16_give_the_table_of_32_bit_keys),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
