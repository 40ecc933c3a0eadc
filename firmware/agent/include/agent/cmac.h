// SPDX-License-Identifier: MIT
// dynaqpc: a CMAC (tile-coding) function approximator over a static, exact hash table.
#ifndef AGENT_CMAC_H
#define AGENT_CMAC_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/oa_table.h"
#include "agent/region.h"
#include "fw_config.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Weights and outputs are fixed point with this many fractional bits: 1.0 is 256.
#define CMAC_FRAC_BITS 8
#define CMAC_ONE (1 << CMAC_FRAC_BITS)
/// The most outputs one CMAC predicts (the forward model: every component, reward, terminal).
#define CMAC_MAX_OUTPUTS (FW_CFG_MAX_COMPONENTS + 2)
/// Marks an empty cell. No tile key can take this value (keys use at most 31 bits).
#define CMAC_EMPTY OA_EMPTY

/// What a CMAC approximates: a function of a few small integer inputs and an action.
typedef struct cmac_config {
    uint8_t n_inputs;                           ///< 1..FW_CFG_MAX_COMPONENTS
    uint8_t input_bits[FW_CFG_MAX_COMPONENTS];  ///< input k takes values 0 .. 2^bits - 1
    /// Tile width of input k is 2^tile_shift[k] values; 0 makes the input exact (no
    /// generalisation across its values), which suits categorical inputs.
    uint8_t tile_shift[FW_CFG_MAX_COMPONENTS];
    uint8_t circular_mask;   ///< bit k set: input k wraps around (a heading)
    uint8_t n_actions;       ///< 1..FW_CFG_MAX_ACTIONS; the action is an exact input
    uint8_t n_tilings;       ///< power of two, 1..FW_CFG_MAX_TILINGS (c in the paper's Fig. 7)
    uint8_t n_outputs;       ///< 1..CMAC_MAX_OUTPUTS
    float learning_rate;     ///< the paper's gamma in Fig. 7, in (0, 1]
} cmac_config_t;

/// Counters; they only grow, until cmac_clear().
typedef struct cmac_stats {
    uint32_t cells_used;  ///< cells holding a tile
    uint32_t dropped;     ///< tiles that found no cell within the probe limit (table full)
    uint32_t evicted;     ///< cells reused for a new tile: the least-trained one in its window
    uint32_t saturated;   ///< weight updates clipped to the int16 range
    uint32_t trained;     ///< calls to cmac_train()
    uint32_t contradicted;  ///< observations that cmac_contradict() counted against a kept outcome
} cmac_stats_t;

/// The tile keys of one input (state components and action), computed once and reused for
/// prediction and training. Only the first `n_patterns` entries are used (see cmac_t).
typedef struct cmac_tiles {
    uint32_t key[FW_CFG_MAX_TILINGS];
    uint32_t action_bits;  // the action's field in every key
} cmac_tiles_t;

/// A CMAC in caller-owned storage.
///
/// Collision policy: the table stores each tile's full key beside its weights (the keys in an
/// open-addressing index, oa_table.h, with bounded windows; cell i belongs to the key in slot i),
/// so two tiles never share a cell: the approximation is exact until the table is full. A tile that finds
/// no free cell within FW_CFG_MAX_PROBE slots takes the least-trained cell of that window
/// (`evicted`), whose old tile then reads as untrained; only when every cell of the window is
/// held by the same training is the tile not stored (`dropped`).
///
/// Duplicate tilings are merged. The inputs are integers, so an input whose tiles are w values
/// wide can only be split w ways, and of the T tilings at most the product of the widths are
/// distinct: the rest repeat one of them exactly. Each distinct tiling (a "pattern") is stored
/// once and carries the weight of all its copies, and learns as much as they would together,
/// so predictions and training are exactly those of the T-tiling CMAC with less memory and
/// work. With every input exact (width 1) the CMAC is a table: one pattern.
typedef struct cmac {
    cmac_config_t cfg;
    uint8_t *counts;    // capacity: training hits per cell, saturating at 255 (the confidence)
    int16_t *weights;   // capacity * n_outputs
    uint32_t capacity;
    uint8_t n_patterns;  // distinct tilings, <= n_tilings
    uint8_t key_shift[FW_CFG_MAX_COMPONENTS];  // where input k's tile index sits in a key
    uint8_t action_shift;
    uint8_t n_tiled;  // inputs with tiles wider than one value (the others are not displaced)
    uint8_t tiled[FW_CFG_MAX_COMPONENTS];  // their numbers
    uint32_t action_field;  // the action's bits in a key
    // cmac_tiles_of()'s fast path (see there): carry_bits != 0 when it applies.
    uint32_t carry_bits;
    uint32_t pattern_offsets[FW_CFG_MAX_TILINGS];
    uint8_t low_shift[FW_CFG_MAX_COMPONENTS];  // key_shift - tile_shift: input k's tile index
                                               // lands on its field, its value within the tile
    uint32_t low_field[FW_CFG_MAX_COMPONENTS];  // below it, in these bits
    uint32_t tile_mask[FW_CFG_MAX_COMPONENTS];  // all ones, or the wrap of a circular input
    uint8_t offset[FW_CFG_MAX_COMPONENTS][FW_CFG_MAX_TILINGS];  // per pattern displacement
    uint8_t copies[FW_CFG_MAX_TILINGS];  // tilings each pattern stands for
    int32_t rate_q;  // learning_rate in 1/256
    cmac_stats_t stats;
    oa_table_t index;   // capacity slots: the cells' tile keys
} cmac_t;

/// Prepares an empty CMAC. `capacity` (cells) must be a power of two; `keys` and `counts` hold
/// `capacity` entries and `weights` holds `capacity * cfg->n_outputs`. The packed tile key (all
/// inputs' tile indices, the action and the tiling number) must fit in 31 bits.
/// Returns FW_OK or FW_ERR_INVAL.
int cmac_init(cmac_t *cmac, const cmac_config_t *cfg, uint32_t *keys, uint8_t *counts,
              int16_t *weights, uint32_t capacity);

/// Forgets everything learned and zeroes the counters.
void cmac_clear(cmac_t *cmac);

/// Computes the tile keys of `inputs` (n_inputs values, each within its bit range) for
/// `action`.
void cmac_tiles_of(const cmac_t *cmac, const uint32_t *inputs, uint32_t action, cmac_tiles_t *tiles);

/// cmac_tiles_of() for inputs also given packed, input 0 in the lowest bits and each in its
/// input_bits (as space_pack() packs a state). When every input is exact (tiles one value wide,
/// the shipped configurations) the one tile's key is the packed inputs shifted into place: no
/// input is looked at one by one.
static inline void cmac_tiles_of_packed(const cmac_t *cmac, uint32_t packed, const uint32_t *inputs,
                                        uint32_t action, cmac_tiles_t *tiles)
{
    if (cmac->n_tiled == 0u) {  // then one pattern, the inputs' fields in order from key_shift[0]
        tiles->action_bits = action << cmac->action_shift;
        tiles->key[0] = (packed << cmac->key_shift[0]) | tiles->action_bits;
        return;
    }
    cmac_tiles_of(cmac, inputs, action, tiles);
}

/// Re-targets tiles computed by cmac_tiles_of() to another action, without recomputing them.
static inline void cmac_tiles_set_action(const cmac_t *cmac, cmac_tiles_t *tiles, uint32_t action)
{
    const uint32_t change = tiles->action_bits ^ (action << cmac->action_shift);
    for (uint32_t p = 0; p < cmac->n_patterns; p++) {
        tiles->key[p] ^= change;
    }
    tiles->action_bits ^= change;
}

/// Predicts: out[j] = sum over the T tiles of weight j (fixed point, CMAC_ONE = 1.0). Each sum
/// must stay within +-128 * n_patterns for its cells not to saturate.
/// Returns the confidence: the smallest training count among the cells, 0 if any tile has
/// never been trained. Missing tiles contribute nothing.
uint32_t cmac_predict(const cmac_t *cmac, const cmac_tiles_t *tiles, int32_t *out);

/// Like cmac_predict() for `tiles` re-targeted to `action` (as cmac_tiles_set_action() would,
/// without changing them), but gives up at the first cell trained fewer than `min_count` times
/// (min_count >= 1): the planner's fast path, which asks about one state for several actions.
/// Returns true, with out[] filled, when every cell qualifies; false leaves out[] undefined.
bool cmac_predict_trusted(const cmac_t *cmac, const cmac_tiles_t *tiles, uint32_t action,
                          uint32_t min_count, int32_t *out);

/// The paper's learning rule (Fig. 7, step d): each of the T cells moves by
/// learning_rate / T * (desired - actual). Cells are created on first training.
/// `desired` holds n_outputs fixed-point values.
/// Returns true when every tile has its cell; false when a tile found no cell it could take
/// within the probe limit (counted in `dropped`): predictions over these tiles stay untrusted
/// until a later training stores them.
bool cmac_train(cmac_t *cmac, const cmac_tiles_t *tiles, const int32_t *desired);

/// One observation contradicted what the cells of `tiles` hold, which keeps it: each cell's
/// count drops by one, so that a count is how many more observations agreed than disagreed
/// (`contradicted` counts these). Refuses, changing nothing, when a cell is missing or has a count
/// of 1: the outcome has lost its majority, and the caller trains on the new one instead.
/// Returns whether the cells kept their outcome.
bool cmac_contradict(cmac_t *cmac, const cmac_tiles_t *tiles);

/// The regions cmac_regions() lists.
#define CMAC_REGIONS 3u

/// Lists the memory that holds what the CMAC learned, in a fixed order: keys, counts, weights.
/// Returns CMAC_REGIONS.
uint32_t cmac_regions(const cmac_t *cmac, agent_region_t *out);

/// Checks restored contents before they are copied into `cmac` (which gives the shape): image[i]
/// holds the bytes of region i as cmac_regions() lists them (keys and counts: capacity entries;
/// weights: capacity * n_outputs). Every cell must be empty with a zero count and zero weights (a
/// new tile takes an empty cell as it is), or hold a key of at most 31 bits that a search from its
/// home cell finds within FW_CFG_MAX_PROBE cells (no empty cell and no copy of it before it),
/// trained at least once (the planner trusts every stored cell: see cmac_predict_trusted). Reads
/// only. Returns FW_OK or FW_ERR_CORRUPT.
int cmac_check(const cmac_t *cmac, const void *const *image);

/// After contents that passed cmac_check() were copied into the regions: recounts the cells in
/// use (`stats.cells_used`, which only the CMAC computes). The other counters are left as they
/// are: statistics are not saved.
void cmac_restored(cmac_t *cmac);

#ifdef __cplusplus
}
#endif

#endif // AGENT_CMAC_H
