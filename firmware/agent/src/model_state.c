// SPDX-License-Identifier: MIT
// dynaqpc: the world model's state as a whole: its save regions, the check of a saved image, its
// restore step.
#include "agent/model_state.h"

#include <stddef.h>

#include "fw/fw_base.h"

// Why a file of its own: the agent used to list the model's tables, index the saved image by
// them and recount CMAC-Model's fill itself, so every change to what the model keeps meant an
// edit to agent.c that nothing checked. Here the model's module says it once; agent.c strings the
// modules' regions together without knowing any table. (It sits beside model.c rather than in it
// while model.c is being rewritten; either file may hold it.)

uint32_t model_regions(const world_model_t *m, agent_region_t *out)
{
    uint32_t n = cmac_regions(&m->forward, out);
    n = agent_region_add(out, n, m->percepts, m->places * (uint32_t)sizeof(uint16_t));
    n = agent_region_add(out, n, m->classes, m->n_classes * (uint32_t)sizeof(model_class_t));
    n = agent_region_add(out, n, m->arrivals, m->positions * (uint32_t)sizeof(int16_t));
    n = agent_region_add(out, n, m->deltas, (uint32_t)sizeof m->deltas);
    return agent_region_add(out, n, m->percept_classes,
                            m->n_percept_classes * (uint32_t)sizeof(model_class_t));
}

int model_check(const world_model_t *m, const void *const *image)
{
    if (cmac_check(&m->forward, image) != FW_OK) {
        return FW_ERR_CORRUPT;
    }
    // The percept map, when the space has one, comes right after CMAC-Model's regions.
    if (m->places != 0u && model_percepts_check(m, image[CMAC_REGIONS]) != FW_OK) {
        return FW_ERR_CORRUPT;
    }
    return FW_OK;
}

void model_restored(world_model_t *m)
{
    cmac_restored(&m->forward);
}
