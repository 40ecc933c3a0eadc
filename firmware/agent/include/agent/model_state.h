// SPDX-License-Identifier: MIT
// dynaqpc: the world model's state as a whole: its save regions, the check of a saved image, its
// restore step, and its counters as one value.
#ifndef AGENT_MODEL_STATE_H
#define AGENT_MODEL_STATE_H

#include <stdint.h>

#include "agent/cmac.h"
#include "agent/model.h"
#include "agent/region.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Part of the model's module (model.h): what the agent needs to save, restore and account for
/// the model without knowing its tables. Kept in a file of its own (model_state.c) beside
/// model.c; it lists exactly the tables model.h declares.

/// The most regions model_regions() lists: CMAC-Model's, the percept map, the situations, the
/// arrivals, the changes per action and the percepts' outcomes.
#define MODEL_MAX_REGIONS (CMAC_REGIONS + 5u)

/// Lists the memory that holds what the model learned, in a fixed order: CMAC-Model (its own
/// regions, cmac_regions()), then the percept map, the situations and the arrivals (each only if
/// the space has it), then the changes per action, then the percepts' outcomes (if the space has
/// them). Returns how many regions it wrote to `out`.
uint32_t model_regions(const world_model_t *m, agent_region_t *out);

/// Checks restored contents before they are copied into `m` (which gives the shape): image[i]
/// holds the bytes of region i as model_regions() lists them. CMAC-Model checks its own cells
/// (cmac_check); a percept mask must not name a value the absolute components cannot take
/// (model_percepts_check). The situations, arrivals, changes and percepts' outcomes hold any
/// values safely: every
/// use range-checks what it computes from them. Reads only. Returns FW_OK or FW_ERR_CORRUPT.
int model_check(const world_model_t *m, const void *const *image);

/// After contents that passed model_check() were copied into the regions: each part recounts
/// what it keeps count of (CMAC-Model its cells in use). The model's counters are left as they
/// are: statistics are not saved.
void model_restored(world_model_t *m);

/// The model's counters (model.h: untrusted, rejected, generalised) as one value, so that what a
/// piece of work added is the difference of two, and a caller that keeps an answer instead of
/// asking again (the planner's carry, agent.c) can have the model count it as if asked.
typedef struct {
    uint32_t untrusted;
    uint32_t rejected;
    uint32_t generalised;
} model_counts_t;

/// The counters now.
static inline model_counts_t model_counts(const world_model_t *m)
{
    const model_counts_t c = {m->untrusted, m->rejected, m->generalised};
    return c;
}

/// What the counters gained since `before` (an earlier model_counts()).
static inline model_counts_t model_counts_since(const world_model_t *m, model_counts_t before)
{
    const model_counts_t c = {m->untrusted - before.untrusted, m->rejected - before.rejected,
                              m->generalised - before.generalised};
    return c;
}

/// Counts `added` again: work whose answer the caller kept, done once more in effect.
static inline void model_count_again(world_model_t *m, model_counts_t added)
{
    m->untrusted += added.untrusted;
    m->rejected += added.rejected;
    m->generalised += added.generalised;
}

/// Counts one prediction refused without asking: a pair the caller knows the model cannot
/// predict (its CMAC-Model tiles found no room, model_learn() returned false), as
/// model_predict() would have counted it.
static inline void model_count_untrusted(world_model_t *m)
{
    m->untrusted++;
}

#ifdef __cplusplus
}
#endif

#endif // AGENT_MODEL_STATE_H
