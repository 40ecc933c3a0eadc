// SPDX-License-Identifier: MIT
// dynaqpc: packing and unpacking state components.
#include "agent/space.h"

#include <stddef.h>

#include "fw/fw_base.h"

uint32_t space_state_bits(const agent_space_t *sp)
{
    uint32_t total = 0;
    for (uint32_t k = 0; k < sp->n_components; k++) {
        total += sp->bits[k];
    }
    return total;
}

int space_validate(const agent_space_t *sp)
{
    if (sp == NULL || sp->n_components < 1u || sp->n_components > FW_CFG_MAX_COMPONENTS) {
        return FW_ERR_INVAL;
    }
    if (sp->n_actions < 1u || sp->n_actions > FW_CFG_MAX_ACTIONS) {
        return FW_ERR_INVAL;
    }
    for (uint32_t k = 0; k < sp->n_components; k++) {
        if (sp->bits[k] < 1u || sp->bits[k] > 16u || sp->tile_shift[k] > sp->bits[k]) {
            return FW_ERR_INVAL;
        }
    }
    if ((sp->circular_mask | sp->absolute_mask | sp->context_mask) >> sp->n_components) {
        return FW_ERR_INVAL;
    }
    uint32_t absolute_bits = 0;
    for (uint32_t k = 0; k < sp->n_components; k++) {
        absolute_bits += (sp->absolute_mask >> k) & 1u ? sp->bits[k] : 0u;
    }
    if (absolute_bits > SPACE_MAX_ABSOLUTE_BITS) {
        return FW_ERR_INVAL;
    }
    if (space_state_bits(sp) > SPACE_MAX_STATE_BITS) {
        return FW_ERR_INVAL;
    }
    if (sp->turn_step_bits != 0u) {  // one circular component, not absolute, wider than a step
        const uint32_t c = sp->circular_mask;
        if (c == 0u || (c & (c - 1u)) != 0u || (c & sp->absolute_mask) != 0u) {
            return FW_ERR_INVAL;
        }
        for (uint32_t k = 0; k < sp->n_components; k++) {
            if (((c >> k) & 1u) && sp->turn_step_bits >= sp->bits[k]) {
                return FW_ERR_INVAL;
            }
        }
    }
    return FW_OK;
}

void space_unpack(const agent_space_t *sp, agent_state_t s, uint32_t *comp)
{
    for (uint32_t k = 0; k < sp->n_components; k++) {
        comp[k] = s & ((1u << sp->bits[k]) - 1u);
        s >>= sp->bits[k];
    }
}

agent_state_t space_pack(const agent_space_t *sp, const uint32_t *comp)
{
    agent_state_t s = 0;
    uint32_t shift = 0;
    for (uint32_t k = 0; k < sp->n_components; k++) {
        s |= comp[k] << shift;
        shift += sp->bits[k];
    }
    return s;
}

int32_t space_change(const agent_space_t *sp, uint32_t k, uint32_t from, uint32_t to)
{
    if ((sp->absolute_mask >> k) & 1u) {
        return (int32_t)to;
    }
    int32_t d = (int32_t)to - (int32_t)from;
    if ((sp->circular_mask >> k) & 1u) {
        const int32_t n = (int32_t)1 << sp->bits[k];
        if (d >= n / 2) {
            d -= n;
        } else if (d < -n / 2) {
            d += n;
        }
    }
    return d;
}

uint32_t space_position_mask(const agent_space_t *sp)
{
    const uint32_t outside_position = (uint32_t)sp->context_mask | sp->absolute_mask;
    uint32_t mask = 0;
    uint32_t shift = 0;
    for (uint32_t k = 0; k < sp->n_components; k++) {
        if (((outside_position >> k) & 1u) == 0u) {
            mask |= ((1u << sp->bits[k]) - 1u) << shift;
        }
        shift += sp->bits[k];
    }
    return mask;
}
