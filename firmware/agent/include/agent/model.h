// SPDX-License-Identifier: MIT
// dynaqpc: the learned world model of Dyna-QPC: CMAC-Model, the relocatable action model, predecessors.
#ifndef AGENT_MODEL_H
#define AGENT_MODEL_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/cmac.h"
#include "agent/space.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The world model of Dyna-QPC, in three parts (docs/agent.md, "The model"):
///
/// - **CMAC-Model** (forward, exact tiles in the shipped configurations): (s, a) -> (s', r,
///   terminal) for the pairs the robot has tried. It predicts a change of state per component
///   (s' - s), except the components in the space's absolute_mask, whose value it predicts.
/// - **The relocatable action model** (generalisation, for spaces with a context_mask): the
///   outcome of an action in a *situation* (the context components: heading and range code),
///   wherever the robot is, with counts of agreeing and disagreeing observations; a map of what
///   the robot perceived at each place (the absolute components seen at each value of the
///   others); and where arriving ended an episode. A situation not yet seen often enough falls
///   back on the action's usual outcome at the same percept in any heading (what generalises
///   across headings: a bump, a turn, a step too short to leave the cell). Together they
///   predict pairs never tried:
///   the situation's usual change applied to s, the percept the map has for the place it leads
///   to, the goal's reward if arriving there ended an episode before.
/// - **The predecessors** (what the paper's CMAC-R is for): every change an action has produced
///   is kept per action; the predecessors of s by a are s minus each such change, with each
///   percept seen at that place, confirmed by the forward prediction. So every observed
///   predecessor is found (CMAC-R named one per (s', a), the last seen), and so are untried
///   pairs the generalisation predicts to lead to s.
///
/// Outcomes are stochastic (a wheel slips, a reading is noisy): both models keep the outcome
/// most observations agreed on, replaced only once as many disagreed (CMAC-Model through
/// cmac_contradict(); a situation through its counts of agreeing and disagreeing observations).
///
/// An action that changes nothing and earns what its usual outcome earns did not go far enough
/// (a fixed step that ended in the cell it began in): such an observation is a *stay*, counted
/// beside the outcome instead of against it (model_class_t.stay), and a prediction carries the
/// share of stays (model_step_t.stay) for the planner's expected backup over "moved" and
/// "stayed" (docs/agent.md, "Steps that stay in their cell").
///
/// A prediction is trusted only when its CMAC cells were each trained at least `min_count`
/// times, or, for an untried pair, when its situation's outcome was seen at least
/// MODEL_CLASS_MIN_COUNT times (else its percept's at least MODEL_PERCEPT_MIN_COUNT times) and
/// the place it leads to shows one percept only; and each predicted component lies in range.

/// Most predecessors model_query_predecessors() returns for one state.
#define MODEL_MAX_PREDECESSORS 16u
/// The changes each action made are kept per arrival heading (the context components that are
/// not absolute, folded into this many buckets), so the predecessor search of a state tries only
/// the changes that arrived in its heading: about a quarter of the candidates.
#define MODEL_DELTA_BUCKETS 16u
/// Most distinct changes kept per action and bucket (the least seen is replaced when full).
#define MODEL_MAX_DELTAS 4u
/// Most values the absolute components (the percept) take together: a place's percepts are a
/// 16-bit mask (space.h: SPACE_MAX_ABSOLUTE_BITS).
#define MODEL_MAX_PERCEPTS 16u
/// A situation's outcome generalises once it was seen this often.
#ifndef MODEL_CLASS_MIN_COUNT
#define MODEL_CLASS_MIN_COUNT 3u
#endif
/// A percept's outcome stands in for a situation not yet trusted once it was seen this often
/// (docs/agent.md: 1 learned fastest on the tuning rooms; the next real step corrects it).
#ifndef MODEL_PERCEPT_MIN_COUNT
#define MODEL_PERCEPT_MIN_COUNT 1u
#endif

/// world_model_t.ablate: no predictions for untried pairs (agent.h: AGENT_ABLATE_GENERALISE).
#define MODEL_ABLATE_GENERALISE 0x01u
/// world_model_t.ablate: tried pairs keep their last outcome (agent.h: AGENT_ABLATE_MAJORITY).
#define MODEL_ABLATE_MAJORITY 0x02u
/// world_model_t.ablate: a stay is an outcome like any other (agent.h: AGENT_ABLATE_STAY).
#define MODEL_ABLATE_STAY 0x10u

/// How a predicted change applies to one component (see decode_() in model.c).
typedef struct model_field {
    uint32_t keep_from;  // all ones: the models predict the change (else the value itself)
    uint32_t wrap;       // 2^bits - 1 for the change of a circular component, else all ones
    uint32_t shift;      // where the component sits in a packed state
    uint32_t bits;       // its width
} model_field_t;

/// Some components (a mask over them) packed into one index, in order (see select_() in
/// model.c): one shift and one mask of the packed state when they lie next to each other.
typedef struct model_select {
    uint32_t components;  // the mask
    uint32_t mask;        // of the index: 2^(their bits) - 1
    uint8_t shift;        // of the lowest one in a packed state
    uint8_t adjacent;     // they lie next to each other (else packed one by one)
    uint8_t first, last;  // adjacent: the lowest and the highest of them
} model_select_t;

/// The usual outcome of one action in one situation.
typedef struct model_class {
    int8_t delta[FW_CFG_MAX_COMPONENTS];  ///< change of each component (absolute ones: 0)
    int16_t reward;                       ///< fixed point, 8 fractional bits
    uint8_t count;                        ///< observations that agreed (saturates by halving)
    uint8_t miss;                         ///< observations that did not
    /// observations that changed nothing and earned `reward` while the outcome moves: the action
    /// did not go far enough (halved with count and miss)
    uint8_t stay;
} model_class_t;

/// One change an action has produced, and how often.
typedef struct model_delta {
    int8_t delta[FW_CFG_MAX_COMPONENTS];
    uint16_t count;
} model_delta_t;

/// A terminal arrival's reward at a position (fixed point, 8 fractional bits), or none.
#define MODEL_NO_ARRIVAL INT16_MIN
/// world_model_t.stay_reward when no reward marks a stay.
#define MODEL_NO_STAY INT16_MIN

typedef struct world_model {
    const agent_space_t *space;
    model_field_t field[FW_CFG_MAX_COMPONENTS];
    // The parts of a state the tables below are indexed by.
    model_select_t place_of;     // the components outside absolute_mask
    model_select_t position_of;  // outside absolute_mask and context_mask
    model_select_t situation_of; // context_mask
    model_select_t heading_of;   // context_mask outside absolute_mask (the delta buckets)
    model_select_t percept_of;   // absolute_mask
    cmac_t forward;   // outputs: n_components changes, reward, terminal
    uint8_t min_count;
    // Places (the components outside absolute_mask), situations (context_mask) and positions
    // (outside both), packed as indices into the tables below.
    uint16_t *percepts;   ///< per place: bit v set when the absolute components read v there
    uint32_t places;
    uint32_t place_gap;   ///< the low bits of the heading in a place index (space->turn_step_bits)
    uint32_t place_low;   ///< the place index's bits below the heading
    uint8_t place_gap_bits;
    model_class_t *classes;  ///< per situation and action
    uint32_t n_classes;
    int16_t *arrivals;    ///< per position: reward of an arrival that ended an episode
    uint32_t positions;
    model_delta_t deltas[FW_CFG_MAX_ACTIONS][MODEL_DELTA_BUCKETS][MODEL_MAX_DELTAS];
    /// per percept and action (a space with both a context_mask and absolute components): the
    /// usual outcome of the action at that percept in any heading, for situations not yet
    /// trusted
    model_class_t percept_classes[MODEL_MAX_PERCEPTS * FW_CFG_MAX_ACTIONS];
    uint32_t n_percept_classes;  ///< in use: 2^(absolute bits) * n_actions, or 0
    uint32_t untrusted;    ///< predictions refused for low confidence or an out-of-range result
    uint32_t rejected;     ///< predecessor candidates the forward prediction did not confirm
    uint32_t generalised;  ///< predictions made for untried pairs by the relocatable model
    /// The reward of an ordinary step (fixed point, 8 fractional bits): a change of nothing that
    /// earns it is a stay; MODEL_NO_STAY (after model_init()): no observation is
    int16_t stay_reward;
    /// AGENT_ABLATE_GENERALISE, AGENT_ABLATE_MAJORITY and AGENT_ABLATE_STAY (agent.h), for the
    /// ablation; 0 after
    /// model_init()
    uint8_t ablate;
} world_model_t;

/// One predicted transition. A move into a place the map has seen with several percepts has as
/// many outcomes, equally likely: `next`, and `next` with each percept (absolute components'
/// value) in `others` instead of its own (model_step_outcomes()). A step that moves may also
/// leave the state as it was, with the same reward: `stay` of 255 times.
typedef struct model_step {
    agent_state_t next;
    float reward;
    uint8_t terminal;
    uint16_t others;  ///< a bit per other percept value; 0: `next` is the one outcome
    uint8_t stay;     ///< of 255: the chance the state stays as it was (0: it moves to `next`)
} model_step_t;

/// A predecessor of a state: taking `action` in `state` is predicted to lead there with
/// `reward` (or, with `others`, there or to the same place with another of those percepts; with
/// `stay`, of 255 times it stays in `state`).
typedef struct model_pred {
    agent_state_t state;
    uint8_t action;
    uint8_t stay;
    uint16_t others;
    float reward;
} model_pred_t;

/// Caller-owned storage of one CMAC: cells of keys, counts, and weights.
typedef struct model_cmac_storage {
    uint32_t *keys;
    uint8_t *counts;
    int16_t *weights;  // cells * outputs
    uint32_t cells;
} model_cmac_storage_t;

/// Caller-owned storage of the relocatable model and the percept map. A space with an
/// absolute component needs `percepts` for 2^(bits outside absolute_mask) places, or, with
/// fewer, 2^(those bits - turn_step_bits) (the headings between aligned turns left out:
/// agent_space_t); one with a
/// context_mask needs `classes` for 2^(context bits) * n_actions situations and `arrivals` for
/// 2^(bits outside context and absolute masks) positions. Unneeded parts may be NULL.
typedef struct model_reloc_storage {
    uint16_t *percepts;
    uint32_t places;
    model_class_t *classes;
    uint32_t n_classes;
    int16_t *arrivals;
    uint32_t positions;
} model_reloc_storage_t;

/// Prepares an empty model. `fwd` needs weights for n_components + 2 outputs per cell.
/// `tilings` and `learning_rate` configure the CMAC.
/// Returns FW_OK or FW_ERR_INVAL (also when `reloc` is too small for the space).
int model_init(world_model_t *m, const agent_space_t *space, uint8_t tilings,
               float learning_rate, uint8_t min_count, const model_cmac_storage_t *fwd,
               const model_reloc_storage_t *reloc);

/// Forgets everything.
void model_clear(world_model_t *m);

/// Recognises stays (model.h): a change of nothing that earns `step_reward` (the reward of an
/// ordinary step, within +-127) is counted beside the move it did not finish. Until called (and
/// in a space without a context_mask, whose model keeps no situations) every outcome is one.
void model_set_stay_reward(world_model_t *m, float step_reward);

/// Learns one real transition: CMAC-Model on (s, a) -> (s', r, terminal); the change a made; what
/// was perceived at both places; the situation's outcome, or, for a terminal step, the arrival.
/// Returns false when one of CMAC-Model's tiles for (s, a) found no room in its table: then
/// model_predict() refuses (s, a) until a later training stores that tile.
bool model_learn(world_model_t *m, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                 bool terminal);

/// Checks a percept map about to be restored (m->places entries): every mask names only values
/// the absolute components can take. Returns FW_OK or FW_ERR_CORRUPT.
int model_percepts_check(const world_model_t *m, const uint16_t *percepts);

/// Whether the map has seen state s (its percept at its place). False for a space without
/// absolute components, which has no map.
bool model_has_seen(const world_model_t *m, agent_state_t s);

/// Predicts the outcome of a in s: CMAC-Model's when (s, a) was tried, else the relocatable
/// model's. Returns false (and fills nothing) if no prediction is trusted.
bool model_predict(world_model_t *m, agent_state_t s, uint8_t a, model_step_t *out);

/// The outcomes of `step` into out[] (room for MODEL_MAX_PERCEPTS): step->next first, then
/// step->next with each percept of step->others. Returns how many (1 + the bits of others).
uint32_t model_step_outcomes(const world_model_t *m, const model_step_t *step, agent_state_t *out);

/// Predicts the trusted predecessors of s into out[] (room for MODEL_MAX_PREDECESSORS): every
/// (state, action) predicted to lead to s, not terminal. Returns how many.
uint32_t model_predecessors(world_model_t *m, agent_state_t s, model_pred_t *out);

/// A state made ready for several queries: its components and its tile keys, computed once
/// (each query names its action, so the keys' own action field does not matter).
typedef struct model_query {
    agent_state_t state;
    uint32_t comp[FW_CFG_MAX_COMPONENTS];
    cmac_tiles_t tiles;
} model_query_t;

/// Prepares the queries about s.
void model_query_init(const world_model_t *m, agent_state_t s, model_query_t *q);

/// CMAC-Model's outcome for (s, a) when the pair was tried (its cells trained at least
/// min_count times): the outcome its learning kept (the majority rule of model_learn()), no
/// relocatable guess and no stay share. Counts nothing. False when the pair was not tried.
bool model_tried_outcome(const world_model_t *m, agent_state_t s, uint8_t a, model_step_t *out);

/// model_predict() for the query's state.
bool model_query_predict(world_model_t *m, const model_query_t *q, uint8_t a, model_step_t *out);

/// model_predecessors() for the query's state. With `queries` (MODEL_MAX_PREDECESSORS places
/// apart from q, or NULL), *queries[i] also receives the query of out[i].state, ready for
/// further questions, and model_query_predict() for out[i] is known to give: q's state (with
/// out[i].others as the other outcomes and out[i].stay as its stay share), reward
/// out[i].reward, not terminal (that is how a predecessor is confirmed).
uint32_t model_query_predecessors(world_model_t *m, const model_query_t *q, model_pred_t *out,
                                  model_query_t *const *queries);

#ifdef __cplusplus
}
#endif

#endif // AGENT_MODEL_H
