// SPDX-License-Identifier: MIT
// dynaqpc: CMAC tile coding over an exact, bounded open-addressing table.
#include "agent/cmac.h"

#include <stddef.h>
#include <string.h>

#include "fw/fw_base.h"
#include "fw/fw_util.h"
#include "inline.h"
#include "agent/oa_table.h"

static bool config_ok_(const cmac_config_t *cfg, uint32_t capacity)
{
    if (cfg->n_inputs < 1u || cfg->n_inputs > FW_CFG_MAX_COMPONENTS ||  //
        cfg->n_actions < 1u || cfg->n_actions > FW_CFG_MAX_ACTIONS ||     //
        !FW_IS_POW2(cfg->n_tilings) || cfg->n_tilings > FW_CFG_MAX_TILINGS ||
        cfg->n_outputs < 1u || cfg->n_outputs > CMAC_MAX_OUTPUTS ||  //
        !(cfg->learning_rate > 0.0f && cfg->learning_rate <= 1.0f) ||    //
        !FW_IS_POW2(capacity) || capacity < 16u || (cfg->circular_mask >> cfg->n_inputs)) {
        return false;
    }
    for (uint32_t k = 0; k < cfg->n_inputs; k++) {
        if (cfg->input_bits[k] < 1u || cfg->input_bits[k] > 16u ||
            cfg->tile_shift[k] > cfg->input_bits[k]) {
            return false;
        }
    }
    return true;
}

// Tiling t is displaced along input k by ((t * (2k + 1)) mod T) / T of a tile: the odd
// factors (Miller and Glanz's asymmetric displacement) keep the tilings from sliding along
// the diagonal together. On integer inputs that is a whole number of values, and tilings
// with equal displacements are the same tiling: keep one pattern per distinct displacement.
static void init_patterns_(cmac_t *cmac, uint32_t tiling_bits)
{
    const cmac_config_t *cfg = &cmac->cfg;
    cmac->n_patterns = 0;
    for (uint32_t t = 0; t < cfg->n_tilings; t++) {
        uint8_t off[FW_CFG_MAX_COMPONENTS];
        for (uint32_t k = 0; k < cfg->n_inputs; k++) {
            const uint32_t step = (t * (2u * k + 1u)) & (cfg->n_tilings - 1u);
            off[k] = (uint8_t)((step << cfg->tile_shift[k]) >> tiling_bits);
        }
        uint32_t p = 0;
        for (; p < cmac->n_patterns; p++) {
            uint32_t k = 0;
            while (k < cfg->n_inputs && cmac->offset[k][p] == off[k]) {
                k++;
            }
            if (k == cfg->n_inputs) {
                break;
            }
        }
        if (p == cmac->n_patterns) {
            for (uint32_t k = 0; k < cfg->n_inputs; k++) {
                cmac->offset[k][p] = off[k];
            }
            cmac->copies[p] = 0;
            cmac->n_patterns++;
        }
        cmac->copies[p]++;
    }
}

// Key layout, low bits first: pattern number, action, then each input's tile index. A
// circular input of b bits and tile width 2^w has 2^(b-w) tiles; an ordinal one has one more,
// because the displacements push the last values into an extra tile. False if the key needs
// more than 31 bits.
static bool init_key_layout_(cmac_t *cmac, uint32_t tiling_bits)
{
    const cmac_config_t *cfg = &cmac->cfg;
    uint32_t shift = tiling_bits;
    cmac->action_shift = (uint8_t)shift;
    shift += fw_log2_ceil(cfg->n_actions);
    for (uint32_t k = 0; k < cfg->n_inputs; k++) {
        cmac->key_shift[k] = (uint8_t)shift;
        const uint32_t tile_bits = (uint32_t)(cfg->input_bits[k] - cfg->tile_shift[k]);
        if ((cfg->circular_mask >> k) & 1u) {
            cmac->tile_mask[k] = (1u << tile_bits) - 1u;
            shift += tile_bits;
        } else {
            cmac->tile_mask[k] = UINT32_MAX;
            shift += cfg->tile_shift[k] == 0u ? tile_bits : tile_bits + 1u;
        }
    }
    if (shift > 31u) {
        return false;
    }
    cmac->action_field = ((1u << (cmac->key_shift[0] - cmac->action_shift)) - 1u)
                         << cmac->action_shift;
    cmac->n_tiled = 0;
    for (uint32_t k = 0; k < cfg->n_inputs; k++) {
        if (cfg->tile_shift[k] != 0u) {
            cmac->tiled[cmac->n_tiled++] = (uint8_t)k;
        }
    }
    return true;
}

// The fast path of cmac_tiles_of() adds every tiled input's displacement at once, in a word
// where input k's low bits (v mod 2^sh) and displacement sit just below bit key_shift[k], so
// that their carry lands on bit key_shift[k], the lowest bit of k's tile index. That needs
// the inputs' sh + 1 bit wide places in the word not to overlap, and no tiled input to wrap
// (a carry into a circular tile index would have to wrap around).
static void init_fast_path_(cmac_t *cmac)
{
    const cmac_config_t *cfg = &cmac->cfg;
    cmac->carry_bits = 0;
    uint32_t low = 0;  // the lowest bit still free in the word
    bool fits = true;
    for (uint32_t j = 0; j < cmac->n_tiled; j++) {
        const uint32_t k = cmac->tiled[j];
        const uint32_t ks = cmac->key_shift[k];
        fits = fits && !((cfg->circular_mask >> k) & 1u) && ks >= low + cfg->tile_shift[k];
        low = ks + 1u;
    }
    if (fits && cmac->n_tiled > 0u) {
        for (uint32_t p = 0; p < cmac->n_patterns; p++) {
            uint32_t word = 0;
            for (uint32_t j = 0; j < cmac->n_tiled; j++) {
                const uint32_t k = cmac->tiled[j];
                word += (uint32_t)cmac->offset[k][p] << (cmac->key_shift[k] - cfg->tile_shift[k]);
            }
            cmac->pattern_offsets[p] = word;
        }
        for (uint32_t j = 0; j < cmac->n_tiled; j++) {
            cmac->carry_bits |= 1u << cmac->key_shift[cmac->tiled[j]];
        }
    }
    for (uint32_t k = 0; k < cfg->n_inputs; k++) {
        cmac->low_shift[k] = (uint8_t)(cmac->key_shift[k] - cfg->tile_shift[k]);
        cmac->low_field[k] = ((1u << cfg->tile_shift[k]) - 1u) << cmac->low_shift[k];
    }
}

int cmac_init(cmac_t *cmac, const cmac_config_t *cfg, uint32_t *keys, uint8_t *counts,
              int16_t *weights, uint32_t capacity)
{
    if (cmac == NULL || cfg == NULL || keys == NULL || counts == NULL || weights == NULL ||
        !config_ok_(cfg, capacity)) {
        return FW_ERR_INVAL;
    }
    cmac->cfg = *cfg;
    // The cells' keys: bounded windows of FW_CFG_MAX_PROBE cells, homes from the top bits of the
    // key's hash.
    if (oa_init(&cmac->index, keys, capacity, oa_probe_limit(capacity), OA_HOME_HIGH) != FW_OK) {
        return FW_ERR_INVAL;
    }
    cmac->counts = counts;
    cmac->weights = weights;
    cmac->capacity = capacity;
    const uint32_t tiling_bits = fw_log2_ceil(cfg->n_tilings);
    init_patterns_(cmac, tiling_bits);
    if (!init_key_layout_(cmac, tiling_bits)) {
        return FW_ERR_INVAL;
    }
    init_fast_path_(cmac);
    cmac->rate_q = (int32_t)(cfg->learning_rate * (float)CMAC_ONE + 0.5f);
    cmac_clear(cmac);
    return FW_OK;
}

void cmac_clear(cmac_t *cmac)
{
    FW_ASSERT(cmac != NULL);
    oa_clear(&cmac->index);
    // Integers whose empty value is 0 (see model_clear).
    if (cmac->capacity > 0u) {
        memset(cmac->counts, 0, cmac->capacity * sizeof *cmac->counts);
        memset(cmac->weights, 0, cmac->capacity * cmac->cfg.n_outputs * sizeof *cmac->weights);
    }
    cmac->stats = (cmac_stats_t){0};
}

void cmac_tiles_of(const cmac_t *cmac, const uint32_t *inputs, uint32_t action, cmac_tiles_t *tiles)
{
    FW_ASSERT(cmac != NULL && inputs != NULL && tiles != NULL && action < cmac->cfg.n_actions);
    // An exact input (tiles one value wide) is displaced by 0 in every tiling: its field is the
    // same in every pattern. A tiled input v, 2^sh values per tile, falls in tile
    // hi = v >> sh, or hi + 1 when its displacement reaches past the tile's end
    // (off >= 2^sh - (v mod 2^sh)). So every field of the undisplaced tiles goes into a common
    // part once, and a pattern only flips the fields its displacements carry into the next tile.
    const uint32_t n = cmac->n_patterns;
    const uint32_t n_in = cmac->cfg.n_inputs;
    uint32_t common = action << cmac->action_shift;
    tiles->action_bits = common;
    if (cmac->carry_bits != 0u) {
        // Every tiled input's low bits (v mod 2^sh) go into a word of their own, placed so that
        // adding a pattern's displacements carries exactly into the tile indices that move to
        // the next tile (see cmac_init()); an exact input adds nothing there. One shift places
        // both parts of v: its tile index on its field of the key, its low bits just below. No
        // tiled input is circular on this path, and an exact one's value is within its range,
        // so no field needs its tile mask.
        uint32_t low = 0;
        for (uint32_t k = 0; k < n_in; k++) {
            const uint32_t placed = inputs[k] << cmac->low_shift[k];
            common |= placed & ~cmac->low_field[k];
            low += placed & cmac->low_field[k];
        }
        // Pattern p's key: the common part with p in its lowest bits (where the common part has
        // none), plus its carries.
        const uint32_t carries = cmac->carry_bits;
        const uint32_t *offset = cmac->pattern_offsets;
        uint32_t *key = tiles->key;
        uint32_t *const end = key + n;
        for (; key != end; key++, common++) {
            *key = common + ((low + *offset++) & carries);
        }
        return;
    }
    for (uint32_t k = 0; k < n_in; k++) {
        common |= ((inputs[k] >> cmac->cfg.tile_shift[k]) & cmac->tile_mask[k]) << cmac->key_shift[k];
    }
    for (uint32_t p = 0; p < n; p++) {
        tiles->key[p] = p | common;
    }
    // Every input exact (the shipped configurations): no pattern flips anything, and the loop's
    // set-up is not worth paying.
    const uint32_t n_tiled = cmac->n_tiled;
    if (n_tiled == 0u) {
        return;
    }
    for (uint32_t j = 0; j < n_tiled; j++) {
        const uint32_t k = cmac->tiled[j];
        const uint32_t sh = cmac->cfg.tile_shift[k];
        const uint32_t mask = cmac->tile_mask[k];
        const uint32_t hi = inputs[k] >> sh;
        const uint32_t flip = ((hi & mask) ^ ((hi + 1u) & mask)) << cmac->key_shift[k];
        const uint32_t reach = (1u << sh) - (inputs[k] & ((1u << sh) - 1u));
        const uint8_t *off = cmac->offset[k];
        for (uint32_t p = 0; p < n; p++) {
            if (off[p] >= reach) {
                tiles->key[p] ^= flip;
            }
        }
    }
}

uint32_t cmac_predict(const cmac_t *cmac, const cmac_tiles_t *tiles, int32_t *out)
{
    FW_ASSERT(cmac != NULL && tiles != NULL && out != NULL);
    const uint32_t n_out = cmac->cfg.n_outputs;
    uint32_t confidence = UINT32_MAX;
    for (uint32_t j = 0; j < n_out; j++) {
        out[j] = 0;
    }
    for (uint32_t t = 0; t < cmac->n_patterns; t++) {
        const uint32_t slot = oa_lookup(&cmac->index, tiles->key[t], false);
        if (slot == OA_NONE) {
            confidence = 0;
            continue;
        }
        const int16_t *w = &cmac->weights[slot * n_out];
        for (uint32_t j = 0; j < n_out; j++) {
            out[j] += w[j];
        }
        if (cmac->counts[slot] < confidence) {
            confidence = cmac->counts[slot];
        }
    }
    return confidence;
}

FW_STATIC_ASSERT(CMAC_MAX_OUTPUTS <= 6, predict_sums_at_most_six_outputs);
// The second pass of cmac_predict_trusted(): adds the found cells' weights, one register per
// output. Inlined with a constant `n_out` the switch folds away, and a CMAC of four outputs needs
// no register for the other two.
AGENT_ALWAYS_INLINE void add_cells_(const cmac_t *cmac, const uint32_t *slot, int32_t *out,
                               const uint32_t n_out)
{
    const int16_t *const weights = cmac->weights;
    const uint32_t *const end = slot + cmac->n_patterns;
    int32_t s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, s5 = 0;
    for (; slot != end; slot++) {
        const int16_t *w = &weights[*slot * n_out];
        switch (n_out) {
        case 6: s5 += w[5]; /* fall through */
        case 5: s4 += w[4]; /* fall through */
        case 4: s3 += w[3]; /* fall through */
        case 3: s2 += w[2]; /* fall through */
        case 2: s1 += w[1]; /* fall through */
        default: s0 += w[0];
        }
    }
    switch (n_out) {
    case 6: out[5] = s5; /* fall through */
    case 5: out[4] = s4; /* fall through */
    case 4: out[3] = s3; /* fall through */
    case 3: out[2] = s2; /* fall through */
    case 2: out[1] = s1; /* fall through */
    default: out[0] = s0;
    }
}

// What cmac_predict_trusted() does in its first pass: the cell of every tile, its key changed by
// `change` (to another action), into slot[]. False at the first tile without a cell. Two passes
// keep few values live at once (the Cortex-M4 has 13 registers to spare): the cells are found
// first, so a missing one ends the search early, and their weights are added after. Inlined once
// for a full table and once for one with empty cells (oa_lookup() then skips or makes the test
// for empty cells).
AGENT_ALWAYS_INLINE bool find_cells_(const cmac_t *cmac, const cmac_tiles_t *tiles, uint32_t change,
                                uint32_t *slot, const bool full)
{
    // oa_lookup() by its parts, in locals the stores to slot[] cannot alias (so they stay in
    // registers), and a window's hit tested as a pointer.
    const oa_table_t *const index = &cmac->index;
    const uint32_t *const keys = index->keys;
    const uint32_t mul = index->mul;
    const uint32_t shift = index->shift;
    const uint32_t scan_below = index->scan_below;
    const uint32_t *const end = slot + cmac->n_patterns;
    const uint32_t *tile = tiles->key;
    for (; slot != end; slot++, tile++) {
        const uint32_t key = *tile ^ change;
        const uint32_t home = (key * mul) >> shift;  // oa_home()
        if (home < scan_below) {
            const uint32_t *const cell = oa_scan_window(keys + home, key, full);
            if (cell == NULL) {
                return false;
            }
            *slot = (uint32_t)(cell - keys);
        } else {
            *slot = oa_lookup(index, key, full);
            if (*slot == OA_NONE) {
                return false;
            }
        }
    }
    return true;
}

// The second pass: out[] = the found cells' weights added up.
AGENT_ALWAYS_INLINE void sum_cells_(const cmac_t *cmac, const uint32_t *slot, int32_t *out)
{
    // The robot's CMAC-Model has 6 outputs and its CMAC-R 4 (the maze's 4 and 2).
    switch (cmac->cfg.n_outputs) {
    case 6: add_cells_(cmac, slot, out, 6); break;
    case 4: add_cells_(cmac, slot, out, 4); break;
    default: add_cells_(cmac, slot, out, cmac->cfg.n_outputs); break;
    }
}

bool cmac_predict_trusted(const cmac_t *cmac, const cmac_tiles_t *tiles, uint32_t action,
                          uint32_t min_count, int32_t *out)
{
    FW_ASSERT(cmac != NULL && tiles != NULL);
    // The planner's inner loop: about 17 cells per planning update, most of them in a full
    // table.
    const uint32_t change = tiles->action_bits ^ (action << cmac->action_shift);
    uint32_t slot[FW_CFG_MAX_TILINGS];
    const bool found = cmac->stats.cells_used == cmac->capacity
                           ? find_cells_(cmac, tiles, change, slot, true)
                           : find_cells_(cmac, tiles, change, slot, false);
    if (!found) {
        return false;
    }
    // Every stored cell has been trained at least once (cmac_train() counts a new cell's first
    // training at once, and evict_() ages no count below 1): only a higher bar needs a look.
    if (min_count > 1u) {
        for (uint32_t t = 0; t < cmac->n_patterns; t++) {
            if (cmac->counts[slot[t]] < min_count) {
                return false;
            }
        }
    }
    sum_cells_(cmac, slot, out);
    return true;
}

// num / den rounded to nearest, halves away from zero (den > 0).
static int32_t round_div_(int32_t num, int32_t den)
{
    return (num >= 0 ? num + den / 2 : num - den / 2) / den;
}

static int16_t saturate_(cmac_t *cmac, int32_t v)
{
    if (v > INT16_MAX) {
        cmac->stats.saturated++;
        return INT16_MAX;
    }
    if (v < INT16_MIN) {
        cmac->stats.saturated++;
        return INT16_MIN;
    }
    return (int16_t)v;
}

// What a full window's eviction scan needs: the cells this training already holds, which it may
// not take.
typedef struct evict_scan {
    cmac_t *cmac;
    const uint32_t *taken;
    uint32_t n_taken;
} evict_scan_t;

// oa_least()'s score of a cell: its training count, which ages by one as it is scored (never
// below 1, so what was trusted stays trusted); a cell of this training scores OA_SKIP.
static uint32_t least_trained_(void *ctx, uint32_t slot)
{
    const evict_scan_t *scan = ctx;
    for (uint32_t i = 0; i < scan->n_taken; i++) {
        if (scan->taken[i] == slot) {
            return OA_SKIP;
        }
    }
    uint8_t *const count = &scan->cmac->counts[slot];
    const uint32_t score = *count;
    if (*count > 1u) {
        (*count)--;
    }
    return score;
}

// A full probe window: the new tile takes the least-trained cell of its window (not one this
// training already holds), which is emptied. The other cells of the window age by one count:
// knowledge that is no longer used makes room for where the robot is now, and a cell trained once
// does not keep out everything new. Returns the emptied cell, or OA_NONE if every candidate is
// taken by this training.
static uint32_t evict_(cmac_t *cmac, uint32_t key, const uint32_t *taken, uint32_t n_taken)
{
    evict_scan_t scan = {cmac, taken, n_taken};
    const uint32_t victim = oa_least(&cmac->index, key, least_trained_, &scan);
    if (victim != OA_NONE) {
        int16_t *w = &cmac->weights[victim * cmac->cfg.n_outputs];
        for (uint32_t j = 0; j < cmac->cfg.n_outputs; j++) {
            w[j] = 0;
        }
        cmac->counts[victim] = 0;
        cmac->stats.cells_used--;
        cmac->stats.evicted++;
    }
    return victim;
}

bool cmac_contradict(cmac_t *cmac, const cmac_tiles_t *tiles)
{
    FW_ASSERT(cmac != NULL && tiles != NULL);
    uint32_t slots[FW_CFG_MAX_TILINGS];
    for (uint32_t t = 0; t < cmac->n_patterns; t++) {
        slots[t] = oa_lookup(&cmac->index, tiles->key[t], false);
        if (slots[t] == OA_NONE || cmac->counts[slots[t]] <= 1u) {
            return false;
        }
    }
    for (uint32_t t = 0; t < cmac->n_patterns; t++) {
        cmac->counts[slots[t]]--;
    }
    cmac->stats.contradicted++;
    return true;
}

bool cmac_train(cmac_t *cmac, const cmac_tiles_t *tiles, const int32_t *desired)
{
    FW_ASSERT(cmac != NULL && tiles != NULL && desired != NULL);
    const uint32_t n_out = cmac->cfg.n_outputs;
    const uint32_t n_tiles = cmac->n_patterns;
    uint32_t slots[FW_CFG_MAX_TILINGS];
    int32_t actual[CMAC_MAX_OUTPUTS] = {0};
    bool stored = true;

    cmac->stats.trained++;
    for (uint32_t t = 0; t < n_tiles; t++) {
        const uint32_t key = tiles->key[t];
        uint32_t slot = oa_find(&cmac->index, key);
        if (slot == OA_NONE) {
            slot = evict_(cmac, key, slots, t);
        }
        if (slot == OA_NONE) {
            cmac->stats.dropped++;
            stored = false;
        } else if (cmac->index.keys[slot] != key) {  // an empty cell, or the one just emptied
            oa_put(&cmac->index, slot, key);  // weights and count of an empty cell are zero
            cmac->stats.cells_used++;
        } else {
            const int16_t *w = &cmac->weights[slot * n_out];
            for (uint32_t j = 0; j < n_out; j++) {
                actual[j] += w[j];
            }
        }
        slots[t] = slot;
    }

    // Fig. 7 (d): every one of the T cells moves by rate / T of the output error; a pattern
    // standing for c tilings moves c times as far. Both steps round to nearest so that small
    // errors are not lost to truncation, and neither can overflow 32 bits.
    int32_t step[CMAC_MAX_OUTPUTS];
    for (uint32_t j = 0; j < n_out; j++) {
        step[j] = round_div_((desired[j] - actual[j]) * cmac->rate_q, CMAC_ONE);
    }
    const int32_t n_tilings = cmac->cfg.n_tilings;
    for (uint32_t t = 0; t < n_tiles; t++) {
        const uint32_t slot = slots[t];
        if (slot == OA_NONE) {
            continue;
        }
        int16_t *w = &cmac->weights[slot * n_out];
        for (uint32_t j = 0; j < n_out; j++) {
            const int32_t delta = round_div_(step[j] * cmac->copies[t], n_tilings);
            w[j] = saturate_(cmac, (int32_t)w[j] + delta);
        }
        if (cmac->counts[slot] < UINT8_MAX) {
            cmac->counts[slot]++;
        }
    }
    return stored;
}

uint32_t cmac_regions(const cmac_t *cmac, agent_region_t *out)
{
    FW_ASSERT(cmac != NULL);
    uint32_t n = agent_region_add(out, 0, cmac->index.keys, cmac->capacity * (uint32_t)sizeof(uint32_t));
    n = agent_region_add(out, n, cmac->counts, cmac->capacity);
    return agent_region_add(out, n, cmac->weights,
                            cmac->capacity * cmac->cfg.n_outputs * (uint32_t)sizeof(int16_t));
}

int cmac_check(const cmac_t *cmac, const void *const *image)
{
    FW_ASSERT(cmac != NULL && image != NULL);
    const uint32_t *const keys = image[0];
    const uint8_t *const counts = image[1];
    const int16_t *const weights = image[2];
    const uint32_t n_out = cmac->cfg.n_outputs;
    for (uint32_t slot = 0; slot < cmac->capacity; slot++) {
        const uint32_t key = keys[slot];
        if (key == CMAC_EMPTY) {
            if (counts[slot] != 0u) {
                return FW_ERR_CORRUPT;
            }
            for (uint32_t j = 0; j < n_out; j++) {
                if (weights[slot * n_out + j] != 0) {
                    return FW_ERR_CORRUPT;
                }
            }
        } else if ((key >> 31) != 0u || counts[slot] == 0u ||
                   !oa_path_ok(&cmac->index, keys, slot)) {
            return FW_ERR_CORRUPT;
        }
    }
    return FW_OK;
}

void cmac_restored(cmac_t *cmac)
{
    FW_ASSERT(cmac != NULL);
    cmac->stats.cells_used = oa_count(&cmac->index, cmac->index.keys);
}
