// SPDX-License-Identifier: MIT
// Tests of the open-addressing index: find, insert, the eviction window scan, backward-shift
// deletion, and the restore-time probe-path check.
#include "test_common.h"

#include <stdbool.h>
#include <string.h>

#include "agent/oa_table.h"
#include "fw/fw_base.h"
#include "fw/fw_prng.h"

#define SLOTS 64u
static uint32_t keys_[SLOTS];
static uint32_t image_[SLOTS];

static void init_(oa_table_t *t, uint32_t limit, oa_home_t home)
{
    memset(keys_, 0x5A, sizeof keys_);
    assert_int_equal(oa_init(t, keys_, SLOTS, limit, home), FW_OK);
    oa_clear(t);
}

// The first `n` keys from `start` on whose home is `home`.
static void keys_at_(const oa_table_t *t, uint32_t home, uint32_t start, uint32_t *out, uint32_t n)
{
    for (uint32_t k = start, found = 0; found < n; k++) {
        if (oa_home(t, k) == home) {
            out[found++] = k;
        }
    }
}

static void init_refuses_bad_shapes(void **state)
{
    (void)state;
    oa_table_t t;
    assert_int_equal(oa_init(&t, NULL, 16, 16, OA_HOME_HIGH), FW_ERR_INVAL);
    assert_int_equal(oa_init(&t, keys_, 0, 1, OA_HOME_HIGH), FW_ERR_INVAL);
    assert_int_equal(oa_init(&t, keys_, 24, 16, OA_HOME_HIGH), FW_ERR_INVAL);
    assert_int_equal(oa_init(&t, keys_, 16, 0, OA_HOME_HIGH), FW_ERR_INVAL);
    assert_int_equal(oa_init(&t, keys_, 16, 17, OA_HOME_HIGH), FW_ERR_INVAL);
    assert_int_equal(oa_init(&t, keys_, 16, 16, (oa_home_t)2), FW_ERR_INVAL);
    assert_int_equal(oa_init(&t, keys_, 1, 1, OA_HOME_HIGH), FW_OK);
    oa_clear(&t);
    assert_int_equal(oa_home(&t, 12345u), 0);  // one slot: every key's home
    assert_int_equal(oa_insert(&t, 7u), 0);
    assert_int_equal(oa_lookup(&t, 7u, true), 0);
    assert_int_equal(oa_insert(&t, 8u), OA_NONE);
}

static void homes_are_the_top_or_the_low_bits_of_the_hash(void **state)
{
    (void)state;
    oa_table_t t;
    init_(&t, SLOTS, OA_HOME_HIGH);
    for (uint32_t k = 0; k < 1000u; k++) {
        assert_int_equal(oa_home(&t, k), fw_fib_mix(k) >> 26);
    }
    init_(&t, SLOTS, OA_HOME_LOW);
    for (uint32_t k = 0; k < 1000u; k++) {
        assert_int_equal(oa_home(&t, k), fw_fib_mix(k) & (SLOTS - 1u));
    }
}

static void keys_of_one_home_fill_its_run_in_order(void **state)
{
    (void)state;
    oa_table_t t;
    init_(&t, FW_CFG_MAX_PROBE, OA_HOME_HIGH);
    const uint32_t home = SLOTS - 2u;  // the run wraps past the array's end
    uint32_t k[4];
    keys_at_(&t, home, 0, k, 4);
    for (uint32_t i = 0; i < 4u; i++) {
        assert_int_equal(oa_lookup(&t, k[i], false), OA_NONE);
        assert_int_equal(oa_find(&t, k[i]), (home + i) & (SLOTS - 1u));  // the first empty slot
        assert_int_equal(oa_insert(&t, k[i]), (home + i) & (SLOTS - 1u));
    }
    for (uint32_t i = 0; i < 4u; i++) {
        assert_int_equal(oa_find(&t, k[i]), (home + i) & (SLOTS - 1u));
        assert_int_equal(oa_lookup(&t, k[i], false), (home + i) & (SLOTS - 1u));
        assert_true(oa_path_ok(&t, keys_, (home + i) & (SLOTS - 1u)));
    }
    assert_int_equal(oa_count(&t, keys_), 4);
}

static void a_bounded_window_refuses_past_its_limit(void **state)
{
    (void)state;
    oa_table_t t;
    init_(&t, FW_CFG_MAX_PROBE, OA_HOME_HIGH);
    const uint32_t home = 5u;  // a window that lies within the array: scanned by pointer
    uint32_t k[FW_CFG_MAX_PROBE + 1u];
    keys_at_(&t, home, 0, k, FW_CFG_MAX_PROBE + 1u);
    for (uint32_t i = 0; i < FW_CFG_MAX_PROBE; i++) {
        assert_int_equal(oa_insert(&t, k[i]), home + i);
    }
    assert_int_equal(oa_find(&t, k[FW_CFG_MAX_PROBE]), OA_NONE);
    assert_int_equal(oa_insert(&t, k[FW_CFG_MAX_PROBE]), OA_NONE);
    assert_int_equal(oa_count(&t, keys_), FW_CFG_MAX_PROBE);  // nothing stored
    assert_int_equal(oa_lookup(&t, k[FW_CFG_MAX_PROBE], false), OA_NONE);
    for (uint32_t i = 0; i < FW_CFG_MAX_PROBE; i++) {
        assert_int_equal(oa_lookup(&t, k[i], false), home + i);
    }
}

static void a_full_table_is_searched_without_the_empty_test(void **state)
{
    (void)state;
    oa_table_t t;
    init_(&t, FW_CFG_MAX_PROBE, OA_HOME_HIGH);
    uint32_t stored[SLOTS];
    uint32_t n = 0;
    for (uint32_t k = 0; n < SLOTS && k < 100000u; k++) {
        if (oa_insert(&t, k) != OA_NONE) {
            stored[n++] = k;
        }
    }
    assert_int_equal(n, SLOTS);
    for (uint32_t i = 0; i < SLOTS; i++) {
        const uint32_t slot = oa_lookup(&t, stored[i], true);
        assert_int_not_equal(slot, OA_NONE);
        assert_int_equal(keys_[slot], stored[i]);
        assert_int_equal(oa_lookup(&t, stored[i], false), slot);
        assert_true(oa_path_ok(&t, keys_, slot));
    }
    assert_int_equal(oa_lookup(&t, 200000u, true), OA_NONE);
}

typedef struct scores {
    uint32_t score[SLOTS];
    uint32_t seen[SLOTS];  // the slots scored, in order
    uint32_t n_seen;
} scores_t;

static uint32_t score_(void *ctx, uint32_t slot)
{
    scores_t *s = ctx;
    s->seen[s->n_seen++] = slot;
    return s->score[slot];
}

static void the_window_scan_picks_the_first_lowest_score(void **state)
{
    (void)state;
    oa_table_t t;
    init_(&t, 8u, OA_HOME_HIGH);
    const uint32_t home = SLOTS - 3u;
    uint32_t key;
    keys_at_(&t, home, 0, &key, 1);
    scores_t s = {{0}, {0}, 0};
    for (uint32_t i = 0; i < SLOTS; i++) {
        s.score[i] = 100u;
    }
    s.score[1] = 7u;  // the window is 61, 62, 63, 0, 1, 2, 3, 4
    s.score[3] = 7u;
    s.score[2] = 3u;
    s.score[4] = 3u;
    assert_int_equal(oa_least(&t, key, score_, &s), 2);  // lowest, then the first of equals
    assert_int_equal(s.n_seen, 8);
    for (uint32_t i = 0; i < 8u; i++) {
        assert_int_equal(s.seen[i], (home + i) & (SLOTS - 1u));  // once each, in probe order
    }
    s.score[2] = OA_SKIP;  // a skipped slot is never picked
    s.n_seen = 0;
    assert_int_equal(oa_least(&t, key, score_, &s), 4);
    for (uint32_t i = 0; i < SLOTS; i++) {
        s.score[i] = OA_SKIP;
    }
    s.n_seen = 0;
    assert_int_equal(oa_least(&t, key, score_, &s), OA_NONE);
}

typedef struct moves {
    uint32_t payload[SLOTS];
    uint32_t n;
} moves_t;

static void moved_(void *ctx, uint32_t from, uint32_t to)
{
    moves_t *m = ctx;
    m->payload[to] = m->payload[from];
    m->n++;
}

static void removal_shifts_the_run_back(void **state)
{
    (void)state;
    oa_table_t t;
    init_(&t, SLOTS, OA_HOME_HIGH);
    const uint32_t home = SLOTS - 2u;
    uint32_t a[3];
    uint32_t b;
    keys_at_(&t, home, 0, a, 3);          // slots 62, 63, 0
    keys_at_(&t, SLOTS - 1u, 0, &b, 1);   // home 63, lands in 1
    moves_t m = {{0}, 0};
    for (uint32_t i = 0; i < 3u; i++) {
        m.payload[oa_insert(&t, a[i])] = a[i];
    }
    m.payload[oa_insert(&t, b)] = b;
    assert_int_equal(oa_lookup(&t, b, false), 1);
    oa_remove(&t, oa_lookup(&t, a[0], false), moved_, &m);
    assert_int_equal(m.n, 3);  // a[1], a[2] and b each move back one slot
    assert_int_equal(oa_lookup(&t, a[0], false), OA_NONE);
    assert_int_equal(oa_lookup(&t, a[1], false), 62);
    assert_int_equal(oa_lookup(&t, a[2], false), 63);
    assert_int_equal(oa_lookup(&t, b, false), 0);
    assert_int_equal(keys_[1], OA_EMPTY);
    for (uint32_t slot = 62; slot != 1u; slot = (slot + 1u) & (SLOTS - 1u)) {
        assert_int_equal(m.payload[slot], keys_[slot]);  // payload followed its key
    }
    // Removing a[1] (62) moves a[2] back to 62 and b back to its home, 63.
    m.n = 0;
    oa_remove(&t, 62, moved_, &m);
    assert_int_equal(oa_lookup(&t, a[2], false), 62);
    assert_int_equal(oa_lookup(&t, b, false), 63);
    assert_int_equal(m.n, 2);
    // Keys at their homes stay: removing a[2] moves neither b (63) nor c (0).
    uint32_t c;
    keys_at_(&t, 0, 0, &c, 1);
    assert_int_equal(oa_insert(&t, c), 0);
    m.n = 0;
    oa_remove(&t, 62, moved_, &m);
    assert_int_equal(m.n, 0);
    assert_int_equal(keys_[62], OA_EMPTY);
    assert_int_equal(oa_lookup(&t, b, false), 63);
    assert_int_equal(oa_lookup(&t, c, false), 0);
}

// Half-empty use as the queue and Dyna-Q make of it: random inserts and removes against a list
// of what should be held; every key stays reachable and the payload follows it.
static void random_inserts_and_removes_keep_every_path(void **state)
{
    (void)state;
    for (int h = 0; h < 2; h++) {
        oa_table_t t;
        init_(&t, SLOTS, h ? OA_HOME_LOW : OA_HOME_HIGH);
        moves_t m = {{0}, 0};
        uint32_t held[SLOTS / 2u];
        uint32_t n = 0;
        prng_t rng;
        prng_seed(&rng, 77u + (uint32_t)h);
        for (uint32_t step = 0; step < 20000u; step++) {
            const uint32_t key = prng_below(&rng, 200u);
            bool in = false;
            uint32_t at = 0;
            for (uint32_t i = 0; i < n; i++) {
                if (held[i] == key) {
                    in = true;
                    at = i;
                }
            }
            const uint32_t slot = oa_find(&t, key);
            assert_int_not_equal(slot, OA_NONE);
            assert_int_equal(keys_[slot] == key, in);
            if (in) {
                oa_remove(&t, slot, moved_, &m);
                held[at] = held[--n];
            } else if (n < SLOTS / 2u) {
                oa_put(&t, slot, key);
                m.payload[slot] = key;
                held[n++] = key;
            }
            assert_int_equal(oa_count(&t, keys_), n);
            for (uint32_t i = 0; i < n; i++) {
                const uint32_t s = oa_lookup(&t, held[i], false);
                assert_int_not_equal(s, OA_NONE);
                assert_int_equal(m.payload[s], held[i]);
                assert_true(oa_path_ok(&t, keys_, s));
            }
        }
        assert_true(m.n > 1000u);
    }
}

static void the_path_check_refuses_unreachable_keys(void **state)
{
    (void)state;
    oa_table_t t;
    init_(&t, 4u, OA_HOME_HIGH);
    uint32_t k[5];
    keys_at_(&t, 10u, 0, k, 5);
    for (uint32_t i = 0; i < 4u; i++) {
        (void)oa_insert(&t, k[i]);
    }
    memcpy(image_, keys_, sizeof image_);
    for (uint32_t slot = 10; slot < 14u; slot++) {
        assert_true(oa_path_ok(&t, image_, slot));
    }
    image_[11] = OA_EMPTY;  // a search for k[2] or k[3] stops at 11
    assert_false(oa_path_ok(&t, image_, 12));
    assert_false(oa_path_ok(&t, image_, 13));
    memcpy(image_, keys_, sizeof image_);
    image_[12] = k[1];  // a second copy: a search finds the one in 11
    assert_false(oa_path_ok(&t, image_, 12));
    memcpy(image_, keys_, sizeof image_);
    image_[14] = k[4];  // 4 slots past its home: beyond the limit
    assert_false(oa_path_ok(&t, image_, 14));
    image_[9] = k[4];  // before its home: the distance wraps to 63
    assert_false(oa_path_ok(&t, image_, 9));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(init_refuses_bad_shapes),
        cmocka_unit_test(homes_are_the_top_or_the_low_bits_of_the_hash),
        cmocka_unit_test(keys_of_one_home_fill_its_run_in_order),
        cmocka_unit_test(a_bounded_window_refuses_past_its_limit),
        cmocka_unit_test(a_full_table_is_searched_without_the_empty_test),
        cmocka_unit_test(the_window_scan_picks_the_first_lowest_score),
        cmocka_unit_test(removal_shifts_the_run_back),
        cmocka_unit_test(random_inserts_and_removes_keep_every_path),
        cmocka_unit_test(the_path_check_refuses_unreachable_keys),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
