// SPDX-License-Identifier: MIT
// Tests of the CMAC: tiling, exactness, approximation, the learning rule, overflow policy.
#include "test_common.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "agent/cmac.h"
#include "fw/fw_prng.h"
#include "fw/fw_base.h"

#define CELLS 8192u
static uint32_t keys_[CELLS];
static uint8_t counts_[CELLS];
static int16_t weights_[CELLS * CMAC_MAX_OUTPUTS];

static cmac_config_t config_2d(uint8_t bits, uint8_t shift, uint8_t outputs)
{
    cmac_config_t c;
    memset(&c, 0, sizeof c);
    c.n_inputs = 2;
    c.input_bits[0] = bits;
    c.input_bits[1] = bits;
    c.tile_shift[0] = shift;
    c.tile_shift[1] = shift;
    c.n_actions = 4;
    c.n_tilings = 16;
    c.n_outputs = outputs;
    c.learning_rate = 1.0f;
    return c;
}

static void init_rejects_bad_configs(void **state)
{
    (void)state;
    cmac_t m;
    cmac_config_t c = config_2d(5, 1, 1);
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, 1000), FW_ERR_INVAL);
    c.n_tilings = 12;
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_ERR_INVAL);
    c = config_2d(16, 0, 1);
    c.n_inputs = 3;  // 16 + 16 + 16 bits of tile index cannot fit a 31-bit key
    c.input_bits[2] = 16;
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_ERR_INVAL);
    c = config_2d(5, 1, 1);
    c.learning_rate = 0.0f;
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_ERR_INVAL);
    c = config_2d(5, 1, 1);
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
}

static void untrained_predicts_zero_with_no_confidence(void **state)
{
    (void)state;
    cmac_t m;
    cmac_config_t c = config_2d(5, 1, 2);
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
    const uint32_t in[2] = {3, 4};
    cmac_tiles_t t;
    int32_t out[CMAC_MAX_OUTPUTS];
    cmac_tiles_of(&m, in, 1, &t);
    assert_int_equal(cmac_predict(&m, &t, out), 0);
    assert_int_equal(out[0], 0);
    assert_int_equal(out[1], 0);
    assert_false(cmac_predict_trusted(&m, &t, 1, 1, out));
}

// Fig. 7 with rate 1: one training makes the output equal the target (to rounding).
static void one_training_at_rate_one_hits_the_target(void **state)
{
    (void)state;
    cmac_t m;
    cmac_config_t c = config_2d(5, 1, 3);
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
    const uint32_t in[2] = {10, 20};
    const int32_t desired[3] = {3 * CMAC_ONE, -100 * CMAC_ONE, CMAC_ONE / 2};
    cmac_tiles_t t;
    int32_t out[CMAC_MAX_OUTPUTS];
    cmac_tiles_of(&m, in, 2, &t);
    cmac_train(&m, &t, desired);
    assert_int_equal(cmac_predict(&m, &t, out), 1);
    for (int j = 0; j < 3; j++) {
        assert_true(labs((long)(out[j] - desired[j])) <= 16);  // one rounding per tiling
    }
    // Two inputs two values wide: of the 16 tilings only 2 x 2 are distinct.
    assert_int_equal(m.n_patterns, 4);
    assert_int_equal(m.stats.cells_used, 4);
    assert_true(cmac_predict_trusted(&m, &t, 2, 1, out));
    assert_false(cmac_predict_trusted(&m, &t, 2, 2, out));
}

// A contradiction lowers the count of every cell of the tiles and leaves the weights alone, down
// to a count of 1; then it refuses and changes nothing, and the caller trains instead.
static void contradictions_lower_counts_down_to_one(void **state)
{
    (void)state;
    cmac_t m;
    cmac_config_t c = config_2d(5, 1, 2);
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
    const uint32_t in[2] = {10, 20};
    const int32_t desired[2] = {3 * CMAC_ONE, -CMAC_ONE};
    cmac_tiles_t t;
    int32_t before[CMAC_MAX_OUTPUTS];
    int32_t out[CMAC_MAX_OUTPUTS];
    cmac_tiles_of(&m, in, 1, &t);
    const uint32_t other[2] = {0, 0};
    cmac_tiles_t untrained;
    cmac_tiles_of(&m, other, 1, &untrained);
    assert_false(cmac_contradict(&m, &untrained));  // no cells: nothing to keep
    for (int i = 0; i < 3; i++) {
        cmac_train(&m, &t, desired);
    }
    assert_int_equal(cmac_predict(&m, &t, before), 3);
    assert_true(cmac_contradict(&m, &t));
    assert_true(cmac_contradict(&m, &t));
    assert_int_equal(cmac_predict(&m, &t, out), 1);
    assert_memory_equal(out, before, 2 * sizeof out[0]);
    assert_false(cmac_contradict(&m, &t));  // the last count: the outcome has lost its majority
    assert_int_equal(cmac_predict(&m, &t, out), 1);
    assert_int_equal(m.stats.contradicted, 2);
    assert_int_equal(m.stats.trained, 3);
}

// The rule moves every hit cell by rate / T of the error: at rate 1/2 the error halves.
static void learning_rule_scales_the_error(void **state)
{
    (void)state;
    cmac_t m;
    cmac_config_t c = config_2d(5, 1, 1);
    c.learning_rate = 0.5f;
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
    const uint32_t in[2] = {1, 2};
    const int32_t desired[1] = {64 * CMAC_ONE};
    cmac_tiles_t t;
    int32_t out[CMAC_MAX_OUTPUTS];
    cmac_tiles_of(&m, in, 0, &t);
    cmac_train(&m, &t, desired);
    cmac_predict(&m, &t, out);
    assert_int_equal(out[0], 32 * CMAC_ONE);
    cmac_train(&m, &t, desired);
    cmac_predict(&m, &t, out);
    assert_int_equal(out[0], 48 * CMAC_ONE);
}

// f(x, y) = x * y / 64 + x / 4 on a 32 x 32 grid, tiles 4 wide: after training on random
// samples the CMAC is within 0.25 everywhere and within 0.08 RMS.
static void approximates_a_smooth_function(void **state)
{
    (void)state;
    cmac_t m;
    cmac_config_t c = config_2d(5, 2, 1);
    c.learning_rate = 0.5f;
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
    prng_t r;
    prng_seed(&r, 11);
    cmac_tiles_t t;
    for (int i = 0; i < 60000; i++) {
        const uint32_t in[2] = {prng_below(&r, 32), prng_below(&r, 32)};
        const float f = (float)(in[0] * in[1]) / 64.0f + (float)in[0] / 4.0f;
        const int32_t desired[1] = {(int32_t)(f * CMAC_ONE)};
        cmac_tiles_of(&m, in, 0, &t);
        cmac_train(&m, &t, desired);
    }
    double worst = 0.0;
    double sq = 0.0;
    for (uint32_t x = 0; x < 32; x++) {
        for (uint32_t y = 0; y < 32; y++) {
            const uint32_t in[2] = {x, y};
            int32_t out[CMAC_MAX_OUTPUTS];
            cmac_tiles_of(&m, in, 0, &t);
            assert_true(cmac_predict(&m, &t, out) > 0);
            const double err = fabs((double)out[0] / CMAC_ONE - (x * y / 64.0 + x / 4.0));
            worst = err > worst ? err : worst;
            sq += err * err;
        }
    }
    print_message("max error %.3f, rms %.3f, cells %u\n", worst, sqrt(sq / 1024), m.stats.cells_used);
    assert_true(worst < 0.25);
    assert_true(sqrt(sq / 1024) < 0.08);
    assert_int_equal(m.stats.dropped, 0);
}

// Neighbours inside a tile share cells: training one point moves its neighbour's output, but the
// neighbour is not trusted until all of its own cells are trained.
static void neighbours_generalise_but_are_not_trusted(void **state)
{
    (void)state;
    cmac_t m;
    cmac_config_t c = config_2d(5, 2, 1);
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
    const uint32_t a[2] = {8, 8};
    const uint32_t b[2] = {9, 8};
    const int32_t desired[1] = {16 * CMAC_ONE};
    cmac_tiles_t ta;
    cmac_tiles_t tb;
    int32_t out[CMAC_MAX_OUTPUTS];
    cmac_tiles_of(&m, a, 0, &ta);
    cmac_tiles_of(&m, b, 0, &tb);
    cmac_train(&m, &ta, desired);
    assert_int_equal(cmac_predict(&m, &tb, out), 0);
    assert_true(out[0] > 0 && out[0] < desired[0]);
}

// With tile width 1 every input has its own cells: a table, exact, with no collisions at all.
static void exact_inputs_never_collide(void **state)
{
    (void)state;
    cmac_t m;
    cmac_config_t c = config_2d(5, 0, 1);
    c.n_tilings = 1;
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
    cmac_tiles_t t;
    for (uint32_t a = 0; a < 4; a++) {
        for (uint32_t i = 0; i < 1024; i++) {
            const uint32_t in[2] = {i & 31u, i >> 5};
            const int32_t desired[1] = {(int32_t)(i * 4 + a)};
            cmac_tiles_of(&m, in, a, &t);
            cmac_train(&m, &t, desired);
        }
    }
    assert_int_equal(m.stats.cells_used, 4096);
    assert_int_equal(m.stats.dropped, 0);
    for (uint32_t a = 0; a < 4; a++) {
        for (uint32_t i = 0; i < 1024; i++) {
            const uint32_t in[2] = {i & 31u, i >> 5};
            int32_t out[CMAC_MAX_OUTPUTS];
            cmac_tiles_of(&m, in, a, &t);
            assert_int_equal(cmac_predict(&m, &t, out), 1);
            assert_int_equal(out[0], (int32_t)(i * 4 + a));
        }
    }
}

// A full table makes room: new tiles are stored, the least-trained cells forgotten and counted.
static void full_table_evicts_and_counts(void **state)
{
    (void)state;
    cmac_t m;
    cmac_config_t c = config_2d(5, 0, 1);
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, 64), FW_OK);
    cmac_tiles_t t;
    int32_t out[CMAC_MAX_OUTPUTS];
    const uint32_t first[2] = {0, 0};
    const int32_t desired[1] = {5 * CMAC_ONE};
    cmac_tiles_of(&m, first, 0, &t);
    cmac_train(&m, &t, desired);
    for (uint32_t i = 1; i < 200; i++) {
        const uint32_t in[2] = {i & 31u, (i >> 5) & 31u};
        cmac_tiles_of(&m, in, 0, &t);
        cmac_train(&m, &t, desired);
    }
    assert_true(m.stats.cells_used <= 64);
    assert_int_equal(m.n_patterns, 1);  // exact inputs: the CMAC is a table
    // A full window reuses its least-trained cell: every new tile is stored, old ones forgotten.
    assert_int_equal(m.stats.dropped, 0);
    assert_true(m.stats.evicted > 0);
    assert_int_equal(m.stats.cells_used + m.stats.evicted, 200u);
    cmac_tiles_of(&m, first, 0, &t);
    (void)cmac_predict(&m, &t, out);  // long forgotten, or still there: either is allowed
    const uint32_t last[2] = {199u & 31u, (199u >> 5) & 31u};
    cmac_tiles_of(&m, last, 0, &t);
    assert_true(cmac_predict(&m, &t, out) >= 1);  // the newest is there
    assert_true(labs((long)(out[0] - desired[0])) <= 16);
}

static void eviction_keeps_the_well_trained_cells(void **state)
{
    (void)state;
    cmac_t m;
    cmac_config_t c = config_2d(5, 0, 1);
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, 64), FW_OK);
    cmac_tiles_t t;
    int32_t out[CMAC_MAX_OUTPUTS];
    const int32_t desired[1] = {3 * CMAC_ONE};
    const uint32_t kept[2] = {4, 4};
    cmac_tiles_of(&m, kept, 0, &t);
    for (int k = 0; k < 200; k++) {  // trained often: count saturates
        cmac_train(&m, &t, desired);
    }
    for (uint32_t i = 0; i < 300; i++) {  // many tiles trained once pass through
        const uint32_t in[2] = {(i * 7u) & 31u, ((i * 7u) >> 5) & 31u};
        if (in[0] == 4 && in[1] == 4) continue;
        cmac_tiles_of(&m, in, 0, &t);
        cmac_train(&m, &t, desired);
    }
    cmac_tiles_of(&m, kept, 0, &t);
    assert_true(cmac_predict(&m, &t, out) >= 1);
    assert_true(labs((long)(out[0] - desired[0])) <= 16);
}

static void circular_inputs_wrap(void **state)
{
    (void)state;
    cmac_t m;
    cmac_config_t c = config_2d(4, 2, 1);
    c.circular_mask = 2;  // input 1 is a heading
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
    cmac_tiles_t t15;
    cmac_tiles_t t0;
    const uint32_t a[2] = {5, 15};
    const uint32_t b[2] = {5, 0};
    cmac_tiles_of(&m, a, 0, &t15);
    cmac_tiles_of(&m, b, 0, &t0);
    int shared = 0;
    for (int i = 0; i < m.n_patterns; i++) {
        shared += t15.key[i] == t0.key[i];
    }
    assert_true(shared > 0 && shared < m.n_patterns);  // 15 and 0 are neighbours on a circle
}

static void set_action_matches_recomputing(void **state)
{
    (void)state;
    cmac_t m;
    cmac_config_t c = config_2d(5, 1, 1);
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
    const uint32_t in[2] = {17, 30};
    cmac_tiles_t a;
    cmac_tiles_t b;
    cmac_tiles_of(&m, in, 0, &a);
    for (uint32_t act = 0; act < 4; act++) {
        cmac_tiles_set_action(&m, &a, act);
        cmac_tiles_of(&m, in, act, &b);
        assert_memory_equal(a.key, b.key, m.n_patterns * sizeof a.key[0]);
    }
}

static void weights_saturate_and_count(void **state)
{
    (void)state;
    cmac_t m;
    cmac_config_t c = config_2d(5, 0, 1);
    c.n_tilings = 1;
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
    const uint32_t in[2] = {1, 1};
    const int32_t desired[1] = {1000 * CMAC_ONE};  // beyond what one int16 cell holds
    cmac_tiles_t t;
    int32_t out[CMAC_MAX_OUTPUTS];
    cmac_tiles_of(&m, in, 0, &t);
    for (int i = 0; i < 300; i++) {
        cmac_train(&m, &t, desired);
    }
    assert_true(m.stats.saturated > 0);
    assert_int_equal(cmac_predict(&m, &t, out), 255);  // the count saturates too
    assert_int_equal(out[0], INT16_MAX);
}

// Merging duplicate tilings changes nothing a caller can see. Over inputs four values wide
// 12 of the 16 tilings are distinct; over exact inputs only one is, and it learns as far as 16
// separate tilings would.
static void duplicate_tilings_are_merged_exactly(void **state)
{
    (void)state;
    cmac_t wide;
    cmac_t exact;
    cmac_config_t c = config_2d(5, 2, 1);
    assert_int_equal(cmac_init(&wide, &c, keys_, counts_, weights_, 4096), FW_OK);
    assert_int_equal(wide.n_patterns, 12);
    c = config_2d(5, 0, 1);
    c.learning_rate = 0.5f;
    assert_int_equal(cmac_init(&exact, &c, keys_ + 4096, counts_ + 4096, weights_ + 4096, 4096),
                     FW_OK);
    assert_int_equal(exact.n_patterns, 1);
    assert_int_equal(exact.copies[0], 16);
    const uint32_t in[2] = {3, 9};
    const int32_t desired[1] = {40 * CMAC_ONE};
    cmac_tiles_t t;
    int32_t out[CMAC_MAX_OUTPUTS];
    cmac_tiles_of(&exact, in, 1, &t);
    cmac_train(&exact, &t, desired);  // rate 1/2: half way, as 16 separate tilings would go
    assert_int_equal(cmac_predict(&exact, &t, out), 1);
    assert_int_equal(out[0], 20 * CMAC_ONE);
}

// The tile keys by their definition: pattern p, the action, and per input
// ((v + offset) >> tile_shift) & mask at its key position.
static void check_keys_by_definition_(const cmac_t *m, prng_t *rng)
{
    for (uint32_t trial = 0; trial < 500; trial++) {
        uint32_t in[FW_CFG_MAX_COMPONENTS];
        for (uint32_t k = 0; k < m->cfg.n_inputs; k++) {
            in[k] = prng_below(rng, 1u << m->cfg.input_bits[k]);
        }
        const uint32_t action = prng_below(rng, m->cfg.n_actions);
        uint32_t packed = 0;  // as space_pack() packs a state: input 0 lowest
        uint32_t shift = 0;
        for (uint32_t k = 0; k < m->cfg.n_inputs; k++) {
            packed |= in[k] << shift;
            shift += m->cfg.input_bits[k];
        }
        cmac_tiles_t t;
        cmac_tiles_t from_packed;
        cmac_tiles_of(m, in, action, &t);
        cmac_tiles_of_packed(m, packed, in, action, &from_packed);
        assert_int_equal(from_packed.action_bits, t.action_bits);
        for (uint32_t p = 0; p < m->n_patterns; p++) {
            uint32_t key = p | (action << m->action_shift);
            for (uint32_t k = 0; k < m->cfg.n_inputs; k++) {
                key |= (((in[k] + m->offset[k][p]) >> m->cfg.tile_shift[k]) & m->tile_mask[k])
                       << m->key_shift[k];
            }
            assert_int_equal(t.key[p], key);
            assert_int_equal(from_packed.key[p], key);
        }
    }
}

// The grid robot's inputs: x and y of 3 bits, tiles 2^xy_shift wide, a circular 4-bit heading
// and a 3-bit range code, both exact.
static cmac_config_t grid_robot_config_(uint8_t xy_shift)
{
    cmac_config_t c = config_2d(3, xy_shift, 1);
    c.n_inputs = 4;
    c.input_bits[2] = 4;
    c.input_bits[3] = 3;
    c.circular_mask = 4;
    return c;
}

static void tile_keys_match_their_definition(void **state)
{
    (void)state;
    prng_t rng;
    prng_seed(&rng, 99);
    cmac_t m;
    // The grid robot's shape (x, y tiled, a circular heading and a range exact): the fast path.
    cmac_config_t c = grid_robot_config_(1);
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
    assert_int_equal(m.n_patterns, 4);
    assert_true(m.carry_bits != 0u);
    check_keys_by_definition_(&m, &rng);
    // Wide tiles everywhere, 16 patterns.
    c = config_2d(6, 3, 1);
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
    assert_true(m.carry_bits != 0u);
    check_keys_by_definition_(&m, &rng);
    // A tiled circular input: the general path.
    c = config_2d(4, 2, 1);
    c.circular_mask = 2;
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
    assert_int_equal(m.carry_bits, 0u);
    check_keys_by_definition_(&m, &rng);
    // Tiles almost as wide as the input: the places of the carries would overlap.
    c = config_2d(4, 3, 1);
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
    assert_int_equal(m.carry_bits, 0u);
    check_keys_by_definition_(&m, &rng);
    // Every input exact, as shipped (x, y, a circular heading, a range code): one pattern, and
    // cmac_tiles_of_packed() takes its key from the packed state.
    c = grid_robot_config_(0);
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, CELLS), FW_OK);
    assert_int_equal(m.n_patterns, 1);
    assert_int_equal(m.n_tiled, 0);
    check_keys_by_definition_(&m, &rng);
}

static void train_reports_tiles_stored_in_a_full_table(void **state)
{
    (void)state;
    cmac_t m;
    cmac_config_t c = config_2d(5, 0, 1);
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, 16), FW_OK);
    cmac_tiles_t t;
    int32_t out[CMAC_MAX_OUTPUTS];
    const int32_t desired[1] = {CMAC_ONE};
    for (uint32_t i = 0; i < 40; i++) {
        const uint32_t in[2] = {i & 31u, i >> 5};
        cmac_tiles_of(&m, in, 0, &t);
        // A full table makes room (the least-trained cell goes): every tile is stored, and is
        // trusted right after its training.
        assert_true(cmac_train(&m, &t, desired));
        assert_true(cmac_predict_trusted(&m, &t, 0, 1, out));
    }
    assert_int_equal(m.stats.cells_used, 16u);
    assert_int_equal(m.stats.evicted, 24u);
    assert_int_equal(m.stats.dropped, 0u);
}

// The planner's lookup, cmac_predict_trusted() on tiles of another action, against
// cmac_predict() on tiles computed for the action asked: trusted exactly when every cell was
// trained min_count times, and then the same sums. In a table with room, in one that training
// has filled (no probe stops at an empty cell, and a table this small has many probe windows
// that wrap around its end), for the output counts the sums are specialised for (6 and 4) and
// for others.
static void trusted_prediction_for_any_action_agrees_with_predict(void **state)
{
    (void)state;
    static const uint8_t outputs[] = {6, 4, 3, 1};
    static const uint32_t capacities[] = {128, 4096};
    prng_t rng;
    prng_seed(&rng, 7);
    for (uint32_t o = 0; o < sizeof outputs; o++) {
        for (uint32_t cap = 0; cap < 2; cap++) {
            cmac_t m;
            cmac_config_t c = config_2d(4, 1, outputs[o]);
            assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, capacities[cap]), FW_OK);
            for (uint32_t i = 0; i < 300; i++) {
                const uint32_t in[2] = {prng_below(&rng, 6), prng_below(&rng, 6)};
                int32_t desired[CMAC_MAX_OUTPUTS];
                for (uint32_t j = 0; j < outputs[o]; j++) {
                    desired[j] = (int32_t)prng_below(&rng, 20 * CMAC_ONE) - 10 * CMAC_ONE;
                }
                cmac_tiles_t t;
                cmac_tiles_of(&m, in, prng_below(&rng, 4), &t);
                cmac_train(&m, &t, desired);
            }
            assert_int_equal(m.stats.cells_used == m.capacity, cap == 0);
            uint32_t trusted = 0;
            for (uint32_t i = 0; i < 400; i++) {
                const uint32_t in[2] = {prng_below(&rng, 6), prng_below(&rng, 6)};
                const uint32_t action = prng_below(&rng, 4);
                const uint32_t min_count = 1u + prng_below(&rng, 2);
                cmac_tiles_t any;
                cmac_tiles_t asked;
                cmac_tiles_of(&m, in, prng_below(&rng, 4), &any);
                cmac_tiles_of(&m, in, action, &asked);
                int32_t fast[CMAC_MAX_OUTPUTS];
                int32_t plain[CMAC_MAX_OUTPUTS];
                const bool ok = cmac_predict_trusted(&m, &any, action, min_count, fast);
                assert_int_equal(ok, cmac_predict(&m, &asked, plain) >= min_count);
                if (ok) {
                    assert_memory_equal(fast, plain, outputs[o] * sizeof fast[0]);
                    trusted++;
                }
            }
            assert_true(trusted > 20);  // both answers were exercised
            assert_true(trusted < 400);
        }
    }
}

static uint32_t keys2_[64];
static uint8_t counts2_[64];
static int16_t weights2_[64 * CMAC_MAX_OUTPUTS];

// The CMAC's own save regions, checked and restored into a second CMAC over other arrays, give
// the same predictions and fill; a cell that was never trained, or a key a search cannot reach,
// is refused.
static void saved_regions_check_and_restore_themselves(void **state)
{
    (void)state;
    cmac_t m;
    cmac_t back;
    const cmac_config_t c = config_2d(5, 0, 3);
    assert_int_equal(cmac_init(&m, &c, keys_, counts_, weights_, 64), FW_OK);
    cmac_tiles_t t;
    for (uint32_t i = 0; i < 200; i++) {  // more pairs than cells: some are evicted
        const uint32_t in[2] = {i % 32u, i / 32u};
        const int32_t want[3] = {(int32_t)i, -(int32_t)i, 5};
        cmac_tiles_of(&m, in, i % 4u, &t);
        (void)cmac_train(&m, &t, want);
    }
    assert_true(m.stats.evicted > 0);
    agent_region_t r[CMAC_REGIONS];
    assert_int_equal(cmac_regions(&m, r), CMAC_REGIONS);
    assert_int_equal(r[0].size, 64 * sizeof(uint32_t));
    assert_int_equal(r[1].size, 64);
    assert_int_equal(r[2].size, 64 * 3 * sizeof(int16_t));
    const void *image[CMAC_REGIONS] = {r[0].data, r[1].data, r[2].data};
    assert_int_equal(cmac_check(&m, image), FW_OK);

    assert_int_equal(cmac_init(&back, &c, keys2_, counts2_, weights2_, 64), FW_OK);
    agent_region_t rb[CMAC_REGIONS];
    assert_int_equal(cmac_regions(&back, rb), CMAC_REGIONS);
    for (uint32_t i = 0; i < CMAC_REGIONS; i++) {
        memcpy(rb[i].data, r[i].data, r[i].size);
    }
    cmac_restored(&back);
    assert_int_equal(back.stats.cells_used, m.stats.cells_used);
    for (uint32_t i = 0; i < 200; i++) {
        const uint32_t in[2] = {i % 32u, i / 32u};
        int32_t a[3];
        int32_t b[3];
        cmac_tiles_of(&m, in, i % 4u, &t);
        const uint32_t conf = cmac_predict(&m, &t, a);
        assert_int_equal(cmac_predict(&back, &t, b), conf);
        assert_memory_equal(a, b, sizeof a);
    }

    uint32_t slot = 0;
    while (keys_[slot] == CMAC_EMPTY) {
        slot++;
    }
    const uint8_t count = counts2_[slot];
    counts2_[slot] = 0;  // a stored cell never trained
    const void *bad[CMAC_REGIONS] = {keys2_, counts2_, weights2_};
    assert_int_equal(cmac_check(&m, bad), FW_ERR_CORRUPT);
    counts2_[slot] = count;
    const uint32_t far = (slot + FW_CFG_MAX_PROBE) % 64u;  // past the key's window
    const uint32_t was = keys2_[far];
    keys2_[far] = keys2_[slot];
    counts2_[far] = counts2_[far] == 0u ? 1u : counts2_[far];
    assert_int_equal(cmac_check(&m, bad), FW_ERR_CORRUPT);
    keys2_[far] = was;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(init_rejects_bad_configs),
        cmocka_unit_test(untrained_predicts_zero_with_no_confidence),
        cmocka_unit_test(one_training_at_rate_one_hits_the_target),
        cmocka_unit_test(contradictions_lower_counts_down_to_one),
        cmocka_unit_test(learning_rule_scales_the_error),
        cmocka_unit_test(approximates_a_smooth_function),
        cmocka_unit_test(neighbours_generalise_but_are_not_trusted),
        cmocka_unit_test(exact_inputs_never_collide),
        cmocka_unit_test(full_table_evicts_and_counts),
        cmocka_unit_test(eviction_keeps_the_well_trained_cells),
        cmocka_unit_test(circular_inputs_wrap),
        cmocka_unit_test(set_action_matches_recomputing),
        cmocka_unit_test(weights_saturate_and_count),
        cmocka_unit_test(duplicate_tilings_are_merged_exactly),
        cmocka_unit_test(tile_keys_match_their_definition),
        cmocka_unit_test(train_reports_tiles_stored_in_a_full_table),
        cmocka_unit_test(trusted_prediction_for_any_action_agrees_with_predict),
        cmocka_unit_test(saved_regions_check_and_restore_themselves),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
