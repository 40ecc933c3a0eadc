// SPDX-License-Identifier: MIT
// Tests of the Q store: dense and hashed layouts, unknown states, a full table.
#include "test_common.h"

#include <string.h>

#include "agent/qstore.h"
#include "fw/fw_base.h"

static float q_[256 * FW_CFG_MAX_ACTIONS];
static uint32_t keys_[256];

static void small_spaces_are_dense(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, q_, NULL, 256, 4, 8), FW_OK);
    assert_true(qs.dense);
    float *row = qstore_row_for_update(&qs, 255);
    assert_non_null(row);
    row[2] = 3.5f;
    assert_float_equal(qstore_row(&qs, 255)[2], 3.5f, 0.0f);
    assert_float_equal(qstore_max(&qs, 255), 3.5f, 0.0f);
    assert_ptr_equal(row, &q_[255 * 4]);
}

static void large_spaces_are_hashed_and_unknown_states_read_zero(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, q_, NULL, 256, 4, 18), FW_ERR_INVAL);  // needs keys
    assert_int_equal(qstore_init(&qs, q_, keys_, 256, 4, 18), FW_OK);
    assert_false(qs.dense);
    const float *unknown = qstore_row(&qs, 123456);
    for (int a = 0; a < 4; a++) {
        assert_float_equal(unknown[a], 0.0f, 0.0f);
    }
    assert_int_equal(qs.rows_used, 0);
    float *row = qstore_row_for_update(&qs, 123456);
    row[1] = -2.0f;
    row[3] = -1.0f;
    assert_int_equal(qs.rows_used, 1);
    assert_float_equal(qstore_row(&qs, 123456)[1], -2.0f, 0.0f);
    assert_float_equal(qstore_max(&qs, 123456), 0.0f, 0.0f);
    assert_ptr_equal(qstore_row_for_update(&qs, 123456), row);  // the same row, not a new one
}

static void distinct_states_keep_distinct_values(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, q_, keys_, 256, 4, 18), FW_OK);
    for (uint32_t s = 0; s < 150; s++) {
        float *row = qstore_row_for_update(&qs, s * 1021u);
        assert_non_null(row);
        row[s % 4] = (float)s;
    }
    assert_int_equal(qs.dropped, 0);
    for (uint32_t s = 0; s < 150; s++) {
        assert_float_equal(qstore_row(&qs, s * 1021u)[s % 4], (float)s, 0.0f);
    }
}

static void full_table_forgets_what_it_learned_least(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, q_, keys_, 256, 4, 20), FW_OK);
    // State 7 has learned something big; then 1000 states pass through a 256-row table.
    qstore_row_for_update(&qs, 7)[2] = -50.0f;
    for (uint32_t s = 1000; s < 2000; s++) {
        float *row = qstore_row_for_update(&qs, s);
        assert_non_null(row);  // a write always finds a row
        row[0] = -0.5f;        // each visited once
    }
    assert_true(qs.rows_used <= 256 && qs.rows_used > 200);
    assert_true(qs.dropped >= 1000 - 256 + 1);
    assert_float_equal(qstore_row(&qs, 7)[2], -50.0f, 0.0f);  // the well-learned row survives
    assert_float_equal(qstore_row(&qs, 1999)[0], -0.5f, 0.0f);  // the newest is there
    qstore_clear(&qs);
    assert_int_equal(qs.rows_used, 0);
    assert_non_null(qstore_row_for_update(&qs, 999));
}

static void planning_never_forgets_a_state(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, q_, keys_, 256, 4, 20), FW_OK);
    for (uint32_t s = 1000; s < 2000; s++) {  // real steps fill the table
        qstore_row_for_update(&qs, s)[0] = -1.0f;
    }
    uint32_t known[256];
    uint32_t n_known = 0;
    for (uint32_t i = 0; i < 256; i++) {
        if (keys_[i] != QSTORE_EMPTY) {
            known[n_known++] = keys_[i];
        }
    }
    const uint32_t dropped = qs.dropped;
    assert_non_null(qstore_row_for_plan(&qs, known[0]));  // a known state plans in its row
    uint32_t refused = 0;
    for (uint32_t s = 5000; s < 6000; s++) {  // unknown states find no free row, or take one
        refused += qstore_row_for_plan(&qs, s) == NULL;
    }
    assert_true(refused > 0);
    assert_int_equal(qs.plan_refused, refused);
    assert_int_equal(qs.dropped, dropped);  // planning forgot nothing
    for (uint32_t i = 0; i < n_known; i++) {
        assert_float_equal(qstore_row(&qs, known[i])[0], -1.0f, 0.0f);
    }
    qstore_clear(&qs);
    assert_non_null(qstore_row_for_plan(&qs, 5000));  // a free row is taken
    assert_int_equal(qs.rows_used, 1);
}

static void init_rejects_bad_arguments(void **state)
{
    (void)state;
    qstore_t qs;
    assert_int_equal(qstore_init(&qs, q_, keys_, 100, 4, 8), FW_ERR_INVAL);
    assert_int_equal(qstore_init(&qs, q_, keys_, 256, 0, 8), FW_ERR_INVAL);
    assert_int_equal(qstore_init(&qs, q_, keys_, 256, FW_CFG_MAX_ACTIONS + 1, 8), FW_ERR_INVAL);
}

static float q2_[256 * FW_CFG_MAX_ACTIONS];
static uint32_t keys2_[256];
static uint32_t image_keys_[256];

// The store's own save regions, checked and restored into a second store over other arrays,
// give the same values and fill; a saved key a search cannot reach is refused.
static void saved_regions_check_and_restore_themselves(void **state)
{
    (void)state;
    qstore_t qs;
    qstore_t back;
    assert_int_equal(qstore_init(&qs, q_, keys_, 256, 4, 18), FW_OK);
    for (uint32_t s = 0; s < 1000; s++) {  // more states than rows: some are forgotten
        qstore_row_for_update(&qs, s * 613u % 262144u)[s % 4] = (float)(s + 1u);
    }
    assert_true(qs.dropped > 0);
    agent_region_t r[QSTORE_MAX_REGIONS];
    assert_int_equal(qstore_regions(&qs, r), 2);
    assert_ptr_equal(r[0].data, q_);
    assert_int_equal(r[0].size, 256 * 4 * sizeof(float));
    assert_ptr_equal(r[1].data, keys_);
    assert_int_equal(r[1].size, 256 * sizeof(uint32_t));
    const void *image[QSTORE_MAX_REGIONS] = {r[0].data, r[1].data};
    assert_int_equal(qstore_check(&qs, image, 18), FW_OK);

    assert_int_equal(qstore_init(&back, q2_, keys2_, 256, 4, 18), FW_OK);
    agent_region_t rb[QSTORE_MAX_REGIONS];
    assert_int_equal(qstore_regions(&back, rb), 2);
    for (uint32_t i = 0; i < 2; i++) {
        memcpy(rb[i].data, r[i].data, r[i].size);
    }
    qstore_restored(&back);
    assert_int_equal(back.rows_used, qs.rows_used);
    for (uint32_t s = 0; s < 1000; s++) {
        const agent_state_t st = s * 613u % 262144u;
        assert_memory_equal(qstore_row(&back, st), qstore_row(&qs, st), 4 * sizeof(float));
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
    assert_int_equal(qstore_init(&qs, q_, NULL, 256, 4, 8), FW_OK);
    assert_int_equal(qstore_regions(&qs, r), 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(small_spaces_are_dense),
        cmocka_unit_test(large_spaces_are_hashed_and_unknown_states_read_zero),
        cmocka_unit_test(distinct_states_keep_distinct_values),
        cmocka_unit_test(full_table_forgets_what_it_learned_least),
        cmocka_unit_test(planning_never_forgets_a_state),
        cmocka_unit_test(init_rejects_bad_arguments),
        cmocka_unit_test(saved_regions_check_and_restore_themselves),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
