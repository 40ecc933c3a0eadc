// SPDX-License-Identifier: MIT
// dynaqpc: the paper's world model for Dyna-QPC (§3.1, §3.2): CMAC-Model forward, CMAC-R backward.
#ifndef AGENT_PAPER_MODEL_H
#define AGENT_PAPER_MODEL_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/cmac.h"
#include "agent/model.h"
#include "agent/region.h"
#include "agent/space.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The paper's two CMACs (`--model paper`; docs/agent.md, "The paper's model"), each over the
/// state's components and the action, with tiles wider than a state cell on the components the
/// caller tiles, 16 tilings, in a static hashed table (cmac.h):
///
/// - **CMAC-Model** (Fig. 7): (s, a) -> (s', r, terminal). Per component it predicts the change
///   s' - s (a circular one wrapped), or, for the space's absolute components (a sensor
///   reading), the value; then the reward and a terminal flag. Trained by the paper's rule
///   (each cell moves by rate / c of the error), so a pair keeps its last outcome, and a pair
///   never tried is predicted from the cells its tiles share with tried neighbours.
/// - **CMAC-R** (§3.2, Fig. 9): the input is the pair (s_t, a_t) a trajectory went on with from
///   s_t, the output the pair (s_{t-1}, a_{t-1}) that led into s_t: per component the change
///   s_{t-1} - s_t (or the absolute value), and the action a_{t-1}. With the action in the input
///   the backward trace of a cyclic path (turn right, turn left) names s_{t-1}, not the state the
///   cycle came back from (the paper's Fig. 8). The predecessors of s are what CMAC-R names for
///   (s, a) over every action a.
///
/// The trust gate: a prediction is used only when every cell it reads was trained at least
/// `min_count` times (an untrained CMAC says "no change, reward 0", which would teach that every
/// unexplored move is a free stay) and every predicted component lies in range; a predecessor
/// named by CMAC-R is used only when CMAC-Model, asked about it, leads back to s, not terminal
/// (counted in `rejected` otherwise); the predecessor's reward is CMAC-Model's.

/// Widest tiles a component may have: 2^PAPER_MAX_TILE_SHIFT values (16 tilings displace by
/// sixteenths of a tile, so wider tiles would only repeat displacements).
#define PAPER_MAX_TILE_SHIFT 4u
/// The component tiled wider than one value by default (agent_default_params()): the robot's
/// range code (component 3), 2 values wide; the others exact. Chosen on tuning seeds among the
/// tilings wider than a cell: wide x or y tiles blend a wall's bumps into the free cells beside it
/// and learned slowest (docs/agent.md, "The paper's model").
#define PAPER_DEFAULT_TILED_COMPONENT 3u
/// The most predecessors paper_model_predecessors() names: one per action.
#define PAPER_MAX_PREDECESSORS FW_CFG_MAX_ACTIONS
/// The regions paper_model_regions() lists: CMAC-Model's, then CMAC-R's.
#define PAPER_MODEL_REGIONS (2u * CMAC_REGIONS)

typedef struct paper_model {
    const agent_space_t *space;
    cmac_t forward;  ///< CMAC-Model: n_components changes or values, reward, terminal
    cmac_t inverse;  ///< CMAC-R: n_components changes or values, the action
    uint8_t min_count;
    // The trajectory's last real step, which CMAC-R's next training names as the predecessor.
    uint8_t last_valid;  ///< a step was observed and did not end its episode
    uint8_t last_action;
    agent_state_t last_state, last_next;
    uint32_t untrusted;  ///< predictions refused by the trust gate
    uint32_t rejected;   ///< CMAC-R's predecessors that CMAC-Model did not confirm
} paper_model_t;

/// Caller-owned storage of the two CMACs: CMAC-Model's cells hold FW_CFG_MAX_COMPONENTS + 2
/// weights, CMAC-R's FW_CFG_MAX_COMPONENTS + 1.
typedef struct paper_model_storage {
    model_cmac_storage_t forward;
    model_cmac_storage_t inverse;
} paper_model_storage_t;

/// Prepares an empty model over `space`, its components tiled 2^tile_shift[k] values wide, with
/// `tilings` tilings and the CMACs' learning rate `rate` (Fig. 7's gamma). Returns FW_OK, or
/// FW_ERR_INVAL for missing storage, a tile wider than its component or than
/// 2^PAPER_MAX_TILE_SHIFT, or tile keys that do not fit (cmac_init()).
int paper_model_init(paper_model_t *m, const agent_space_t *space, const uint8_t *tile_shift,
                     uint8_t tilings, float rate, uint8_t min_count, const paper_model_storage_t *st);

/// Forgets everything (and the trajectory).
void paper_model_clear(paper_model_t *m);

/// One real step: CMAC-Model learns (s, a) -> (s', r, terminal); CMAC-R learns (s, a) -> the
/// previous step's pair, if that step led into s and did not end its episode. Returns false when
/// a tile of CMAC-Model's for (s, a) found no cell (the table full: cmac_train()).
bool paper_model_learn(paper_model_t *m, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                       bool terminal);

/// CMAC-Model's prediction for (s, a), tried or not. Returns false (filling nothing) when the
/// trust gate refuses it. `out->others` is always 0 (one outcome).
bool paper_model_predict(paper_model_t *m, agent_state_t s, uint8_t a, model_step_t *out);

/// The predecessors of s: for each action a, the pair CMAC-R names for (s, a), if trusted and
/// confirmed, each pair once. Returns how many were written to out[] (room for
/// PAPER_MAX_PREDECESSORS).
uint32_t paper_model_predecessors(paper_model_t *m, agent_state_t s, model_pred_t *out);

/// Lists CMAC-Model's and CMAC-R's regions (cmac_regions()). Returns PAPER_MODEL_REGIONS.
uint32_t paper_model_regions(const paper_model_t *m, agent_region_t *out);

/// Checks a saved image of those regions (cmac_check() of each). Returns FW_OK or
/// FW_ERR_CORRUPT.
int paper_model_check(const paper_model_t *m, const void *const *image);

/// After a restore: the CMACs recount their cells; the trajectory is forgotten.
void paper_model_restored(paper_model_t *m);

#ifdef __cplusplus
}
#endif

#endif // AGENT_PAPER_MODEL_H
