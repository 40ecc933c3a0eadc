// SPDX-License-Identifier: MIT
// dynaqpc: unit tests of the bounded max-priority queue, including a long run against a model.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "agent/pqueue.h"
#include "fw/fw_base.h"

#define MAX_CAP 64u

static pq_item_t heap_[MAX_CAP];
static uint32_t index_keys_[PQ_INDEX_SLOTS(MAX_CAP)];
static uint32_t index_pos_[PQ_INDEX_SLOTS(MAX_CAP)];
static pqueue_t pq_;

// A fresh queue of `cap` items over the static arrays, checked.
static pqueue_t *make_queue(uint32_t cap)
{
    assert_true(cap <= MAX_CAP);
    // Garbage in the arrays must not matter to pq_init.
    memset(heap_, 0xA5, sizeof heap_);
    memset(index_keys_, 0x5A, sizeof index_keys_);
    memset(index_pos_, 0x77, sizeof index_pos_);
    assert_int_equal(pq_init(&pq_, heap_, index_keys_, index_pos_, cap), FW_OK);
    assert_true(pq_check(&pq_));
    assert_int_equal(pq_size(&pq_), 0);
    return &pq_;
}

// xorshift32: the test's own generator, so it does not depend on the module under test's peers.
static uint32_t xs_state_;

static void xs_seed(uint32_t seed)
{
    xs_state_ = seed != 0u ? seed : 0x12345678u;
}

static uint32_t xs_next(void)
{
    uint32_t x = xs_state_;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    xs_state_ = x;
    return x;
}

static uint32_t xs_below(uint32_t n)
{
    return xs_next() % n;
}

// ---- Fixed scenarios ----------------------------------------------------------------------------

static void test_init_rejects_bad_capacity(void **state)
{
    (void)state;
    assert_int_equal(pq_init(&pq_, heap_, index_keys_, index_pos_, 0), FW_ERR_INVAL);
    assert_int_equal(pq_init(&pq_, heap_, index_keys_, index_pos_, 1), FW_ERR_INVAL);
    assert_int_equal(pq_init(&pq_, heap_, index_keys_, index_pos_, 3), FW_ERR_INVAL);
    assert_int_equal(pq_init(&pq_, heap_, index_keys_, index_pos_, 6), FW_ERR_INVAL);
    assert_int_equal(pq_init(&pq_, heap_, index_keys_, index_pos_, 48), FW_ERR_INVAL);
    assert_int_equal(pq_init(&pq_, heap_, index_keys_, index_pos_, UINT32_MAX), FW_ERR_INVAL);
    assert_int_equal(pq_init(&pq_, heap_, index_keys_, index_pos_, 0x80000000u), FW_ERR_INVAL);
    assert_int_equal(pq_init(NULL, heap_, index_keys_, index_pos_, 8), FW_ERR_INVAL);
    assert_int_equal(pq_init(&pq_, NULL, index_keys_, index_pos_, 8), FW_ERR_INVAL);
    assert_int_equal(pq_init(&pq_, heap_, NULL, index_pos_, 8), FW_ERR_INVAL);
    assert_int_equal(pq_init(&pq_, heap_, index_keys_, NULL, 8), FW_ERR_INVAL);
    assert_int_equal(pq_init(&pq_, heap_, index_keys_, index_pos_, 2), FW_OK);
    assert_true(pq_check(&pq_));
    assert_int_equal(pq_init(&pq_, heap_, index_keys_, index_pos_, MAX_CAP), FW_OK);
    assert_true(pq_check(&pq_));
}

static void test_empty_pop_fails(void **state)
{
    pqueue_t *pq = make_queue(8);
    uint32_t key = 123;
    float pri = 4.5f;
    (void)state;

    assert_false(pq_pop(pq, &key, &pri));
    assert_int_equal(key, 123);  // outputs untouched
    assert_true(pri == 4.5f);
    assert_int_equal(pq->stats.popped, 0);

    // Empty again after a push and a pop.
    assert_true(pq_push(pq, 7, 1.0f));
    assert_true(pq_pop(pq, &key, &pri));
    assert_false(pq_pop(pq, &key, &pri));
    assert_int_equal(pq_size(pq), 0);
    assert_true(pq_check(pq));
}

static void test_pop_order_is_descending(void **state)
{
    static const float pris[] = {3.0f, 9.5f, 0.25f, 7.0f, 7.0f, 1.0f, 12.0f, 0.0f,
                                 5.5f, 2.0f, 8.0f, 4.0f, 6.0f, 10.0f, 11.0f, 0.5f};
    pqueue_t *pq = make_queue(16);
    uint32_t i;
    float last = 1e30f;
    (void)state;

    for (i = 0; i < 16u; ++i) {
        assert_true(pq_push(pq, 100u + i * 4u, pris[i]));
        assert_true(pq_check(pq));
    }
    assert_int_equal(pq_size(pq), 16);
    assert_int_equal(pq->stats.pushed, 16);
    assert_int_equal(pq->stats.high_water, 16);
    for (i = 0; i < 16u; ++i) {
        uint32_t key;
        float pri;
        assert_true(pq_pop(pq, &key, &pri));
        assert_true(pq_check(pq));
        assert_true(pri <= last);
        assert_true(pri == pris[(key - 100u) / 4u]);  // the pair comes out together
        assert_true(pq_priority_of(pq, key) < 0.0f);  // and is gone
        last = pri;
    }
    assert_true(last == 0.0f);
    assert_int_equal(pq->stats.popped, 16);
    assert_false(pq_pop(pq, NULL, NULL));
}

static void test_push_queued_key_raises(void **state)
{
    pqueue_t *pq = make_queue(8);
    uint32_t key;
    float pri;
    (void)state;

    assert_true(pq_push(pq, 1, 5.0f));
    assert_true(pq_push(pq, 2, 3.0f));
    assert_true(pq_push(pq, 3, 1.0f));
    assert_true(pq_push(pq, 3, 6.0f));  // lowest becomes highest
    assert_true(pq_check(pq));
    assert_int_equal(pq_size(pq), 3);
    assert_int_equal(pq->stats.pushed, 3);
    assert_int_equal(pq->stats.raised, 1);
    assert_int_equal(pq->stats.kept, 0);
    assert_true(pq_priority_of(pq, 3) == 6.0f);

    assert_true(pq_pop(pq, &key, &pri));
    assert_int_equal(key, 3);
    assert_true(pri == 6.0f);
    assert_true(pq_pop(pq, &key, &pri));
    assert_int_equal(key, 1);
    assert_true(pq_pop(pq, &key, &pri));
    assert_int_equal(key, 2);
    assert_false(pq_pop(pq, &key, &pri));  // no duplicate of key 3 left behind
    assert_int_equal(pq->stats.popped, 3);
}

static void test_push_lower_priority_is_kept(void **state)
{
    pqueue_t *pq = make_queue(8);
    uint32_t key;
    float pri;
    (void)state;

    assert_true(pq_push(pq, 10, 5.0f));
    assert_true(pq_push(pq, 11, 4.0f));
    assert_true(pq_push(pq, 10, 2.0f));  // lower: unchanged
    assert_true(pq_push(pq, 10, 5.0f));  // equal: unchanged, also "kept"
    assert_true(pq_check(pq));
    assert_int_equal(pq_size(pq), 2);
    assert_int_equal(pq->stats.pushed, 2);
    assert_int_equal(pq->stats.raised, 0);
    assert_int_equal(pq->stats.kept, 2);
    assert_true(pq_priority_of(pq, 10) == 5.0f);

    assert_true(pq_pop(pq, &key, &pri));
    assert_int_equal(key, 10);
    assert_true(pri == 5.0f);
}

static void test_full_queue_drops_new_lowest(void **state)
{
    pqueue_t *pq = make_queue(4);
    uint32_t i;
    (void)state;

    for (i = 0; i < 4u; ++i) {
        assert_true(pq_push(pq, i, 2.0f + (float)i));  // 2, 3, 4, 5
    }
    assert_false(pq_push(pq, 99, 1.0f));  // below the minimum
    assert_true(pq_check(pq));
    assert_int_equal(pq->stats.dropped, 1);
    assert_false(pq_push(pq, 98, 2.0f));  // a tie with the minimum keeps the queued item
    assert_true(pq_check(pq));
    assert_int_equal(pq->stats.dropped, 2);
    assert_int_equal(pq->stats.pushed, 4);
    assert_int_equal(pq_size(pq), 4);
    assert_true(pq_priority_of(pq, 99) < 0.0f);
    assert_true(pq_priority_of(pq, 98) < 0.0f);
    for (i = 0; i < 4u; ++i) {
        assert_true(pq_priority_of(pq, i) == 2.0f + (float)i);
    }
    // Raising a queued key on a full queue drops nothing.
    assert_true(pq_push(pq, 0, 9.0f));
    assert_int_equal(pq->stats.dropped, 2);
    assert_int_equal(pq->stats.raised, 1);
    assert_true(pq_check(pq));
}

static void test_full_queue_drops_existing_lowest(void **state)
{
    pqueue_t *pq = make_queue(4);
    uint32_t i;
    uint32_t key;
    float pri;
    (void)state;

    assert_true(pq_push(pq, 0, 5.0f));
    assert_true(pq_push(pq, 1, 3.0f));
    assert_true(pq_push(pq, 2, 4.0f));
    assert_true(pq_push(pq, 3, 1.0f));
    assert_true(pq_push(pq, 4, 2.0f));  // evicts key 3 (priority 1)
    assert_true(pq_check(pq));
    assert_int_equal(pq_size(pq), 4);
    assert_int_equal(pq->stats.dropped, 1);
    assert_int_equal(pq->stats.pushed, 5);
    assert_true(pq_priority_of(pq, 3) < 0.0f);
    assert_true(pq_priority_of(pq, 4) == 2.0f);

    assert_true(pq_push(pq, 5, 100.0f));  // evicts key 4, then goes to the top
    assert_true(pq_check(pq));
    assert_int_equal(pq->stats.dropped, 2);
    assert_true(pq_priority_of(pq, 4) < 0.0f);

    {
        static const uint32_t want_keys[] = {5, 0, 2, 1};
        for (i = 0; i < 4u; ++i) {
            assert_true(pq_pop(pq, &key, &pri));
            assert_int_equal(key, want_keys[i]);
        }
    }
    assert_int_equal(pq->stats.high_water, 4);
}

static void test_priority_of_absent_and_reserved(void **state)
{
    pqueue_t *pq = make_queue(8);
    (void)state;

    assert_true(pq_priority_of(pq, 0) < 0.0f);
    assert_true(pq_priority_of(pq, PQ_NO_KEY) < 0.0f);
    assert_true(pq_push(pq, 0, 0.0f));  // key 0 and priority 0 are ordinary
    assert_true(pq_priority_of(pq, 0) == 0.0f);
    assert_true(pq_push(pq, PQ_NO_KEY - 1u, 1.0f));
    assert_true(pq_priority_of(pq, PQ_NO_KEY - 1u) == 1.0f);

    // The reserved key and a NaN priority are refused without a trace.
    assert_false(pq_push(pq, PQ_NO_KEY, 1.0f));
    assert_false(pq_push(pq, 5, (float)NAN));
    assert_false(pq_push(pq, 0, (float)NAN));
    assert_true(pq_priority_of(pq, PQ_NO_KEY) < 0.0f);
    assert_true(pq_priority_of(pq, 5) < 0.0f);
    assert_true(pq_priority_of(pq, 0) == 0.0f);
    assert_int_equal(pq_size(pq), 2);
    assert_int_equal(pq->stats.pushed, 2);
    assert_int_equal(pq->stats.raised, 0);
    assert_int_equal(pq->stats.kept, 0);
    assert_int_equal(pq->stats.dropped, 0);
    assert_true(pq_check(pq));
}

static void test_clear_resets(void **state)
{
    pqueue_t *pq = make_queue(8);
    uint32_t i;
    uint32_t key;
    float pri;
    (void)state;

    for (i = 0; i < 12u; ++i) {
        (void)pq_push(pq, i, (float)i);
    }
    (void)pq_push(pq, 11, 50.0f);
    assert_true(pq_pop(pq, &key, &pri));
    assert_true(pq->stats.dropped > 0u);

    pq_clear(pq);
    assert_true(pq_check(pq));
    assert_int_equal(pq_size(pq), 0);
    assert_int_equal(pq->stats.pushed, 0);
    assert_int_equal(pq->stats.raised, 0);
    assert_int_equal(pq->stats.kept, 0);
    assert_int_equal(pq->stats.dropped, 0);
    assert_int_equal(pq->stats.popped, 0);
    assert_int_equal(pq->stats.high_water, 0);
    for (i = 0; i < 12u; ++i) {
        assert_true(pq_priority_of(pq, i) < 0.0f);
    }
    assert_false(pq_pop(pq, &key, &pri));

    // Usable as new afterwards.
    assert_true(pq_push(pq, 3, 1.0f));
    assert_int_equal(pq->stats.pushed, 1);
    assert_int_equal(pq->stats.high_water, 1);
    assert_true(pq_check(pq));
}

// Keys chosen to share home slots: whatever the hash, many keys that differ only in high bits
// or only by multiples of the table size exercise long probe runs and wrap-around deletion.
static void test_clustered_keys_survive_deletion(void **state)
{
    pqueue_t *pq = make_queue(32);
    uint32_t round;
    uint32_t i;
    uint32_t key;
    float pri;
    (void)state;

    for (round = 0; round < 3u; ++round) {
        for (i = 0; i < 32u; ++i) {
            uint32_t k = round == 0u ? i << 26 : round == 1u ? i * 64u : (i << 16) | i;
            assert_true(pq_push(pq, k, (float)((i * 7u) % 32u)));
            assert_true(pq_check(pq));
        }
        // Take items out from the middle of runs by popping half, then re-check the rest.
        for (i = 0; i < 16u; ++i) {
            assert_true(pq_pop(pq, &key, &pri));
            assert_true(pq_check(pq));
        }
        for (i = 0; i < 32u; ++i) {
            uint32_t k = round == 0u ? i << 26 : round == 1u ? i * 64u : (i << 16) | i;
            float want = (float)((i * 7u) % 32u);
            float got = pq_priority_of(pq, k);
            assert_true(want < 16.0f ? got == want : got < 0.0f);
        }
        while (pq_pop(pq, &key, &pri)) {
            assert_true(pq_check(pq));
        }
    }
}

// ---- Random operations against a reference model -----------------------------------------------

typedef struct ref_item {
    uint32_t key;
    float priority;
} ref_item_t;

typedef struct ref_queue {
    ref_item_t items[MAX_CAP];
    uint32_t size;
    uint32_t capacity;
    pq_stats_t stats;
} ref_queue_t;

static ref_queue_t ref_;

static int ref_find(const ref_queue_t *r, uint32_t key)
{
    uint32_t i;
    for (i = 0; i < r->size; ++i) {
        if (r->items[i].key == key) {
            return (int)i;
        }
    }
    return -1;
}

static void ref_remove_at(ref_queue_t *r, uint32_t i)
{
    r->items[i] = r->items[--r->size];
}

// The same semantics as pq_push. When a full queue evicts its minimum and several items share
// it, which one goes is the heap's business: `pq` (already pushed) names the victim.
static bool ref_push(ref_queue_t *r, const pqueue_t *pq, uint32_t key, float priority)
{
    int at = ref_find(r, key);
    uint32_t i;
    float min;
    int victim = -1;

    if (at >= 0) {
        if (priority > r->items[at].priority) {
            r->items[at].priority = priority;
            ++r->stats.raised;
        } else {
            ++r->stats.kept;
        }
        return true;
    }
    if (r->size < r->capacity) {
        r->items[r->size].key = key;
        r->items[r->size].priority = priority;
        ++r->size;
        ++r->stats.pushed;
        if (r->size > r->stats.high_water) {
            r->stats.high_water = r->size;
        }
        return true;
    }
    ++r->stats.dropped;
    min = r->items[0].priority;
    for (i = 1; i < r->size; ++i) {
        if (r->items[i].priority < min) {
            min = r->items[i].priority;
        }
    }
    if (!(priority > min)) {
        return false;
    }
    for (i = 0; i < r->size; ++i) {
        if (r->items[i].priority == min && pq_priority_of(pq, r->items[i].key) < 0.0f) {
            assert_int_equal(victim, -1);  // exactly one minimum went
            victim = (int)i;
        }
    }
    assert_true(victim >= 0);
    r->items[victim].key = key;
    r->items[victim].priority = priority;
    ++r->stats.pushed;
    return true;
}

static void check_against_ref(const pqueue_t *pq, const ref_queue_t *r, const uint32_t *universe,
                              uint32_t universe_size)
{
    uint32_t i;

    assert_true(pq_check(pq));
    assert_int_equal(pq_size(pq), r->size);
    assert_int_equal(pq->stats.pushed, r->stats.pushed);
    assert_int_equal(pq->stats.raised, r->stats.raised);
    assert_int_equal(pq->stats.kept, r->stats.kept);
    assert_int_equal(pq->stats.dropped, r->stats.dropped);
    assert_int_equal(pq->stats.popped, r->stats.popped);
    assert_int_equal(pq->stats.high_water, r->stats.high_water);
    for (i = 0; i < universe_size; ++i) {
        int at = ref_find(r, universe[i]);
        float got = pq_priority_of(pq, universe[i]);
        if (at >= 0) {
            assert_true(got == r->items[at].priority);
        } else {
            assert_true(got < 0.0f);
        }
    }
}

// `ops` random pushes and pops over `universe_size` keys (more keys than capacity, so the queue
// fills and drops, few enough that raises and kept pushes are common). Priorities come from a
// small grid so ties are frequent; phases alternate between filling and draining.
static void run_random_ops(uint32_t cap, const uint32_t *universe, uint32_t universe_size,
                           uint32_t ops, uint32_t seed)
{
    pqueue_t *pq = make_queue(cap);
    uint32_t op;
    uint32_t push_pct = 75;

    memset(&ref_, 0, sizeof ref_);
    ref_.capacity = cap;
    xs_seed(seed);

    for (op = 0; op < ops; ++op) {
        if (op % 997u == 0u) {
            push_pct = push_pct == 75u ? 35u : 75u;
        }
        if (xs_below(100) < push_pct) {
            uint32_t key = universe[xs_below(universe_size)];
            float pri = xs_below(8) == 0u ? (float)(xs_next() >> 8) * (1.0f / 65536.0f)
                                          : (float)xs_below(32) * 0.125f;
            bool got = pq_push(pq, key, pri);
            bool want = ref_push(&ref_, pq, key, pri);
            assert_int_equal(got, want);
        } else {
            uint32_t key = PQ_NO_KEY;
            float pri = -1.0f;
            bool got = pq_pop(pq, &key, &pri);
            assert_int_equal(got, ref_.size > 0u);
            if (got) {
                uint32_t i;
                float max = ref_.items[0].priority;
                int at = ref_find(&ref_, key);
                for (i = 1; i < ref_.size; ++i) {
                    if (ref_.items[i].priority > max) {
                        max = ref_.items[i].priority;
                    }
                }
                // On ties any maximal key may come out: compare priorities, not keys.
                assert_true(pri == max);
                assert_true(at >= 0);
                assert_true(ref_.items[at].priority == pri);
                ref_remove_at(&ref_, (uint32_t)at);
                ++ref_.stats.popped;
            }
        }
        check_against_ref(pq, &ref_, universe, universe_size);
    }
    // Drain: still descending and consistent to the end.
    {
        uint32_t key;
        float pri;
        float last = 1e30f;
        while (pq_pop(pq, &key, &pri)) {
            assert_true(pri <= last);
            last = pri;
            assert_true(pq_check(pq));
        }
    }
}

static void test_random_ops_sequential_keys(void **state)
{
    uint32_t universe[96];
    uint32_t i;
    (void)state;

    // The agent's packing: state * actions + action.
    for (i = 0; i < 96u; ++i) {
        universe[i] = i;
    }
    run_random_ops(64, universe, 96, 200000, 0xC0FFEEu);
}

static void test_random_ops_scattered_keys(void **state)
{
    uint32_t universe[40];
    uint32_t i;
    (void)state;

    xs_seed(0xBADC0DEu);
    for (i = 0; i < 40u; ++i) {
        uint32_t k;
        do {
            k = xs_next();
        } while (k == PQ_NO_KEY);
        universe[i] = k;
    }
    universe[0] = 0;
    universe[1] = PQ_NO_KEY - 1u;
    universe[2] = 0x80000000u;
    universe[3] = 1u << 20;
    universe[4] = 2u << 20;
    universe[5] = 3u << 20;
    run_random_ops(16, universe, 40, 50000, 0x5EED5u);
}

static void test_random_ops_smallest_queue(void **state)
{
    static const uint32_t universe[] = {0, 1, 2, 7};
    (void)state;
    run_random_ops(2, universe, 4, 50000, 42u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_rejects_bad_capacity),
        cmocka_unit_test(test_empty_pop_fails),
        cmocka_unit_test(test_pop_order_is_descending),
        cmocka_unit_test(test_push_queued_key_raises),
        cmocka_unit_test(test_push_lower_priority_is_kept),
        cmocka_unit_test(test_full_queue_drops_new_lowest),
        cmocka_unit_test(test_full_queue_drops_existing_lowest),
        cmocka_unit_test(test_priority_of_absent_and_reserved),
        cmocka_unit_test(test_clear_resets),
        cmocka_unit_test(test_clustered_keys_survive_deletion),
        cmocka_unit_test(test_random_ops_sequential_keys),
        cmocka_unit_test(test_random_ops_scattered_keys),
        cmocka_unit_test(test_random_ops_smallest_queue),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
