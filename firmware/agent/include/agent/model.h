// SPDX-License-Identifier: MIT
// dynaqpc: the learned world model of Dyna-QPC: CMAC-Model (forward) and CMAC-R (inverse).
#ifndef AGENT_MODEL_H
#define AGENT_MODEL_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/cmac.h"
#include "agent/space.h"

#ifdef __cplusplus
extern "C" {
#endif

/// CMAC-Model maps (s, a) to (s', r, terminal); CMAC-R maps (s', a), "arrived in s' by taking
/// a", to the state s it came from (design.md decision 3: having a in the input breaks the
/// cyclic-path ambiguity of the paper's section 3.2).
///
/// Both predict a change of state per component (s' - s, or s - s' for CMAC-R), except the
/// components in the space's absolute_mask, whose value they predict. A change generalises: the
/// same action moves the robot the same way in neighbouring states.
///
/// A prediction is trusted only when every one of its T cells has been trained at least
/// `min_count` times and each predicted component lies in range. A predecessor from CMAC-R is
/// trusted only if CMAC-Model, asked about it, leads back to the state it came from.
/// How a predicted change applies to one component (see decode_() in model.c).
typedef struct model_field {
    uint32_t keep_from;  // all ones: the models predict the change (else the value itself)
    uint32_t wrap;       // 2^bits - 1 for the change of a circular component, else all ones
} model_field_t;

typedef struct world_model {
    const agent_space_t *space;
    model_field_t field[FW_CFG_MAX_COMPONENTS];
    cmac_t forward;   // outputs: n_components changes, reward, terminal
    cmac_t inverse;   // outputs: n_components changes
    uint8_t min_count;
    uint32_t untrusted;  ///< predictions refused for low confidence or an out-of-range result
    uint32_t rejected;   ///< CMAC-R predecessors that CMAC-Model did not confirm
} world_model_t;

/// One predicted transition.
typedef struct model_step {
    agent_state_t next;
    float reward;
    uint8_t terminal;
} model_step_t;

/// A predecessor of a state: taking `action` in `state` is predicted to lead there with
/// `reward`.
typedef struct model_pred {
    agent_state_t state;
    uint8_t action;
    float reward;
} model_pred_t;

/// Caller-owned storage of one CMAC: cells of keys, counts, and weights.
typedef struct model_cmac_storage {
    uint32_t *keys;
    uint8_t *counts;
    int16_t *weights;  // cells * outputs
    uint32_t cells;
} model_cmac_storage_t;

/// Prepares an empty model. `fwd` needs weights for n_components + 2 outputs per cell, `inv` for
/// n_components. `tilings` and `learning_rate` configure both CMACs.
/// Returns FW_OK or FW_ERR_INVAL.
int model_init(world_model_t *m, const agent_space_t *space, uint8_t tilings,
               float learning_rate, uint8_t min_count, const model_cmac_storage_t *fwd,
               const model_cmac_storage_t *inv);

/// Forgets everything.
void model_clear(world_model_t *m);

/// Learns one real transition: CMAC-Model on (s, a) -> (s', r, terminal), CMAC-R on (s', a) -> s.
/// Returns false when one of CMAC-Model's tiles for (s, a) found no room in its table: then
/// model_predict() refuses (s, a) until a later training stores that tile.
bool model_learn(world_model_t *m, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                 bool terminal);

/// Predicts the outcome of a in s. Returns false (and fills nothing) if the prediction is not
/// trusted.
bool model_predict(world_model_t *m, agent_state_t s, uint8_t a, model_step_t *out);

/// Predicts the trusted predecessors of s, at most one per action, into out[] (room for
/// n_actions). Returns how many.
uint32_t model_predecessors(world_model_t *m, agent_state_t s, model_pred_t *out);

/// A state made ready for several queries: its components and its tile keys, computed once
/// (CMAC-Model and CMAC-R share one key layout, so the same keys serve both; each query names
/// its action, so the keys' own action field does not matter).
typedef struct model_query {
    agent_state_t state;
    uint32_t comp[FW_CFG_MAX_COMPONENTS];
    cmac_tiles_t tiles;
} model_query_t;

/// Prepares the queries about s.
void model_query_init(const world_model_t *m, agent_state_t s, model_query_t *q);

/// model_predict() for the query's state.
bool model_query_predict(world_model_t *m, const model_query_t *q, uint8_t a, model_step_t *out);

/// model_predecessors() for the query's state. With `queries` (n_actions places apart from q, or
/// NULL), *queries[i] also receives the query of out[i].state, ready for further questions, and
/// CMAC-Model's prediction for out[i] is known to be: q's state, reward out[i].reward, not
/// terminal (that is how a predecessor is confirmed).
uint32_t model_query_predecessors(world_model_t *m, const model_query_t *q, model_pred_t *out,
                                  model_query_t *const *queries);

#ifdef __cplusplus
}
#endif

#endif // AGENT_MODEL_H
