// SPDX-License-Identifier: MIT
// dynaqpc: CMAC tile coding over an exact, bounded open-addressing table.
#include "agent/cmac.h"

#include <stddef.h>

#include "fw/fw_base.h"

static uint32_t log2_(uint32_t x)
{
    uint32_t n = 0;
    while ((1u << n) < x) {
        n++;
    }
    return n;
}

int cmac_init(cmac_t *cmac, const cmac_config_t *cfg, uint32_t *keys, uint8_t *counts,
              int16_t *weights, uint32_t capacity)
{
    if (cmac == NULL || cfg == NULL || keys == NULL || counts == NULL || weights == NULL) {
        return FW_ERR_INVAL;
    }
    if (cfg->n_inputs < 1u || cfg->n_inputs > FW_CFG_MAX_COMPONENTS ||  //
        cfg->n_actions < 1u || cfg->n_actions > FW_CFG_MAX_ACTIONS ||     //
        !FW_IS_POW2(cfg->n_tilings) || cfg->n_tilings > FW_CFG_MAX_TILINGS ||
        cfg->n_outputs < 1u || cfg->n_outputs > CMAC_MAX_OUTPUTS ||  //
        !(cfg->learning_rate > 0.0f && cfg->learning_rate <= 1.0f) ||    //
        !FW_IS_POW2(capacity) || capacity < 16u || (cfg->circular_mask >> cfg->n_inputs)) {
        return FW_ERR_INVAL;
    }
    cmac->cfg = *cfg;
    cmac->keys = keys;
    cmac->counts = counts;
    cmac->weights = weights;
    cmac->capacity = capacity;
    cmac->capacity_shift = (uint8_t)log2_(capacity);
    cmac->tiling_shift = (uint8_t)log2_(cfg->n_tilings);

    // Key layout, low bits first: tiling number, action, then each input's tile index. A
    // circular input of b bits and tile width 2^w has 2^(b-w) tiles; an ordinal one has one more,
    // because the tiling offsets push the last values into an extra tile.
    uint32_t shift = cmac->tiling_shift;
    cmac->action_shift = (uint8_t)shift;
    shift += log2_(cfg->n_actions);
    for (uint32_t k = 0; k < cfg->n_inputs; k++) {
        if (cfg->input_bits[k] < 1u || cfg->input_bits[k] > 16u ||
            cfg->tile_shift[k] > cfg->input_bits[k]) {
            return FW_ERR_INVAL;
        }
        cmac->key_shift[k] = (uint8_t)shift;
        const uint32_t tile_bits = (uint32_t)(cfg->input_bits[k] - cfg->tile_shift[k]);
        const uint32_t circular = (cfg->circular_mask >> k) & 1u;
        shift += (cfg->tile_shift[k] == 0u || circular) ? tile_bits : tile_bits + 1u;
    }
    if (shift > 31u) {
        return FW_ERR_INVAL;
    }

    // Tiling t is displaced along input k by ((t * (2k + 1)) mod T) / T of a tile: the odd
    // factors (Miller and Glanz's asymmetric displacement) keep the tilings from sliding along
    // the diagonal together.
    for (uint32_t t = 0; t < cfg->n_tilings; t++) {
        for (uint32_t k = 0; k < cfg->n_inputs; k++) {
            const uint32_t step = (t * (2u * k + 1u)) & (cfg->n_tilings - 1u);
            cmac->offset[t][k] = (uint8_t)((step << cfg->tile_shift[k]) >> cmac->tiling_shift);
        }
    }
    cmac->rate_q = (int32_t)(cfg->learning_rate * (float)CMAC_ONE + 0.5f);
    cmac_clear(cmac);
    return FW_OK;
}

void cmac_clear(cmac_t *cmac)
{
    for (uint32_t i = 0; i < cmac->capacity; i++) {
        cmac->keys[i] = CMAC_EMPTY;
        cmac->counts[i] = 0;
    }
    const uint32_t n = cmac->capacity * cmac->cfg.n_outputs;
    for (uint32_t i = 0; i < n; i++) {
        cmac->weights[i] = 0;
    }
    cmac->stats = (cmac_stats_t){0};
}

void cmac_tiles(const cmac_t *cmac, const uint32_t *inputs, uint32_t action, cmac_tiles_t *tiles)
{
    const cmac_config_t *cfg = &cmac->cfg;
    for (uint32_t t = 0; t < cfg->n_tilings; t++) {
        uint32_t key = t | (action << cmac->action_shift);
        for (uint32_t k = 0; k < cfg->n_inputs; k++) {
            uint32_t tile = (inputs[k] + cmac->offset[t][k]) >> cfg->tile_shift[k];
            if ((cfg->circular_mask >> k) & 1u) {
                tile &= (1u << (cfg->input_bits[k] - cfg->tile_shift[k])) - 1u;
            }
            key |= tile << cmac->key_shift[k];
        }
        tiles->key[t] = key;
    }
}

void cmac_tiles_set_action(const cmac_t *cmac, cmac_tiles_t *tiles, uint32_t action)
{
    const uint32_t field = ((1u << (cmac->key_shift[0] - cmac->action_shift)) - 1u)
                           << cmac->action_shift;
    for (uint32_t t = 0; t < cmac->cfg.n_tilings; t++) {
        tiles->key[t] = (tiles->key[t] & ~field) | (action << cmac->action_shift);
    }
}

// The cell holding key, or the first empty cell on its probe path, or capacity when the probe
// limit is reached first. The table is never deleted from, so an empty cell ends every search.
static uint32_t find_(const cmac_t *cmac, uint32_t key)
{
    const uint32_t mask = cmac->capacity - 1u;
    uint32_t slot = (key * 0x9E3779B1u) >> (32u - cmac->capacity_shift);
    for (uint32_t probe = 0; probe < FW_CFG_MAX_PROBE; probe++) {
        const uint32_t k = cmac->keys[slot];
        if (k == key || k == CMAC_EMPTY) {
            return slot;
        }
        slot = (slot + 1u) & mask;
    }
    return cmac->capacity;
}

uint32_t cmac_predict(const cmac_t *cmac, const cmac_tiles_t *tiles, int32_t *out)
{
    const uint32_t n_out = cmac->cfg.n_outputs;
    uint32_t confidence = UINT32_MAX;
    for (uint32_t j = 0; j < n_out; j++) {
        out[j] = 0;
    }
    for (uint32_t t = 0; t < cmac->cfg.n_tilings; t++) {
        const uint32_t slot = find_(cmac, tiles->key[t]);
        if (slot == cmac->capacity || cmac->keys[slot] == CMAC_EMPTY) {
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

bool cmac_predict_trusted(const cmac_t *cmac, const cmac_tiles_t *tiles, uint32_t min_count,
                          int32_t *out)
{
    const uint32_t n_out = cmac->cfg.n_outputs;
    for (uint32_t j = 0; j < n_out; j++) {
        out[j] = 0;
    }
    for (uint32_t t = 0; t < cmac->cfg.n_tilings; t++) {
        const uint32_t slot = find_(cmac, tiles->key[t]);
        if (slot == cmac->capacity || cmac->keys[slot] == CMAC_EMPTY ||
            cmac->counts[slot] < min_count) {
            return false;
        }
        const int16_t *w = &cmac->weights[slot * n_out];
        for (uint32_t j = 0; j < n_out; j++) {
            out[j] += w[j];
        }
    }
    return true;
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

void cmac_train(cmac_t *cmac, const cmac_tiles_t *tiles, const int32_t *desired)
{
    const uint32_t n_out = cmac->cfg.n_outputs;
    const uint32_t n_tiles = cmac->cfg.n_tilings;
    uint32_t slots[FW_CFG_MAX_TILINGS];
    int32_t actual[CMAC_MAX_OUTPUTS] = {0};

    cmac->stats.trained++;
    for (uint32_t t = 0; t < n_tiles; t++) {
        uint32_t slot = find_(cmac, tiles->key[t]);
        if (slot == cmac->capacity) {
            cmac->stats.dropped++;
        } else if (cmac->keys[slot] == CMAC_EMPTY) {
            cmac->keys[slot] = tiles->key[t];  // weights and count of an empty cell are zero
            cmac->stats.cells_used++;
        } else {
            const int16_t *w = &cmac->weights[slot * n_out];
            for (uint32_t j = 0; j < n_out; j++) {
                actual[j] += w[j];
            }
        }
        slots[t] = slot;
    }

    // Fig. 7 (d): every hit cell moves by rate / T of the output error, rounded to nearest so
    // small errors are not lost to truncation.
    const int32_t den = (int32_t)n_tiles << CMAC_FRAC_BITS;
    int32_t delta[CMAC_MAX_OUTPUTS];
    for (uint32_t j = 0; j < n_out; j++) {
        const int32_t num = (desired[j] - actual[j]) * cmac->rate_q;
        delta[j] = (num >= 0 ? num + den / 2 : num - den / 2) / den;
    }
    for (uint32_t t = 0; t < n_tiles; t++) {
        const uint32_t slot = slots[t];
        if (slot == cmac->capacity) {
            continue;
        }
        int16_t *w = &cmac->weights[slot * n_out];
        for (uint32_t j = 0; j < n_out; j++) {
            w[j] = saturate_(cmac, (int32_t)w[j] + delta[j]);
        }
        if (cmac->counts[slot] < UINT8_MAX) {
            cmac->counts[slot]++;
        }
    }
}
