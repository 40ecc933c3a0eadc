// SPDX-License-Identifier: MIT
// dynaqpc: Dyna-QPC (the paper's Figs. 3, 7, 10): its state and storage.
#ifndef AGENT_DYNA_QPC_H
#define AGENT_DYNA_QPC_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/model.h"
#include "agent/model_state.h"
#include "agent/paper_model.h"
#include "agent/pqueue.h"

#ifdef __cplusplus
extern "C" {
#endif

/// What planning updates pass on to the next ones in the same agent_plan() call (dyna_qpc.c
/// says why it pays): the last state whose predecessors were found, those predecessors, and
/// the model queries of all of them. About 1.8 KB; it lives in the agent's storage, where the
/// size report counts it and the MCU's planning stack stays small.
typedef struct agent_plan_carry {
    bool valid;           ///< `here` and the predecessors belong together
    /// the predecessors came from the host's cache (dyna_qpc.c) without their queries
    bool queries_missing;
    /// `here` names its state, but its query was not made: its prediction came from the host's
    /// cache (dyna_qpc.c)
    bool here_missing;
    model_query_t *here;  ///< the last state whose predecessors were found
    uint32_t n;
    model_pred_t pred[MODEL_MAX_PREDECESSORS];
    model_query_t *query[MODEL_MAX_PREDECESSORS];  ///< pred[i]'s
    model_counts_t counted;  ///< what finding them added to the model's counters
    model_query_t store[MODEL_MAX_PREDECESSORS + 1];  ///< where `here` and `query` point
} agent_plan_carry_t;

/// Dyna-QPC's state: the world model, the priority queue, and where its planner's carry is; or,
/// with the paper's model (agent_params_t.model, dyna_qpc_paper.c), the paper's CMACs and the
/// queue.
typedef struct agent_dyna_qpc {
    world_model_t model;
    pqueue_t pq;
    agent_plan_carry_t *carry;
    paper_model_t paper;
} agent_dyna_qpc_t;

/// Dyna-QPC's part of agent_storage_t.
typedef struct agent_dyna_qpc_storage {
    model_cmac_storage_t forward;  ///< weights: cells * (FW_CFG_MAX_COMPONENTS + 2)
    model_reloc_storage_t reloc;   ///< the relocatable model and the percept map
    pq_item_t *pq_heap;            ///< pq_capacity
    uint32_t *pq_index_keys;       ///< PQ_INDEX_SLOTS(pq_capacity)
    uint32_t *pq_index_pos;        ///< PQ_INDEX_SLOTS(pq_capacity)
    uint32_t pq_capacity;
    agent_plan_carry_t *carry;
    /// The paper's CMACs (AGENT_MODEL_PAPER), which may overlay `forward`, `reloc` and `carry`:
    /// an agent runs one model.
    paper_model_storage_t paper;
} agent_dyna_qpc_storage_t;

/// Its memory in a profile P (agent_profiles.h: P(KNOB) is the profile's setting KNOB): the
/// relocatable model (CMAC_CELLS, CLASSES, PLACES, POSITIONS) and the planner's carry, overlaid
/// by the paper's CMACs (PAPER_FWD_CELLS, PAPER_INV_CELLS: an agent runs one model), then the
/// queue (PQ_CAPACITY).
#define AGENT_MEMORY_dyna_qpc(P)                                                               \
    struct {                                                                                   \
        union {                                                                                \
            struct {                                                                           \
                uint32_t fwd_keys[P(CMAC_CELLS)];                                              \
                int16_t fwd_weights[(P(CMAC_CELLS)) * (FW_CFG_MAX_COMPONENTS + 2)];            \
                uint8_t fwd_counts[P(CMAC_CELLS)];                                             \
                model_class_t classes[P(CLASSES)];                                             \
                uint16_t percepts[P(PLACES)];                                                  \
                int16_t arrivals[P(POSITIONS)];                                                \
                agent_plan_carry_t carry;                                                      \
            } ours;                                                                            \
            struct {                                                                           \
                uint32_t fwd_keys[P(PAPER_FWD_CELLS)];                                         \
                int16_t fwd_weights[(P(PAPER_FWD_CELLS)) * (FW_CFG_MAX_COMPONENTS + 2)];       \
                uint8_t fwd_counts[P(PAPER_FWD_CELLS)];                                        \
                uint32_t inv_keys[P(PAPER_INV_CELLS)];                                         \
                int16_t inv_weights[(P(PAPER_INV_CELLS)) * (FW_CFG_MAX_COMPONENTS + 1)];       \
                uint8_t inv_counts[P(PAPER_INV_CELLS)];                                        \
            } paper;                                                                           \
        } m;                                                                                   \
        pq_item_t pq_heap[P(PQ_CAPACITY)];                                                     \
        uint32_t pq_index_keys[PQ_INDEX_SLOTS(P(PQ_CAPACITY))];                                \
        uint32_t pq_index_pos[PQ_INDEX_SLOTS(P(PQ_CAPACITY))];                                 \
    }
/// Its part of agent_storage_t, in memory `m` of that type.
#define AGENT_STORAGE_dyna_qpc(mem)                                                              \
    AGENT_STORAGE_dyna_qpc_PERCEPTS(mem, (mem).m.ours.percepts, AGENT_COUNT_OF((mem).m.ours.percepts))
/// The same with the percept map in an array of its own (`places` entries), not in `mem`: a
/// profile that places it apart (paper-sim-large, agent_profiles.h).
#define AGENT_STORAGE_dyna_qpc_PERCEPTS(mem, percepts_, places_)                                 \
    {{(mem).m.ours.fwd_keys, (mem).m.ours.fwd_counts, (mem).m.ours.fwd_weights,                      \
      AGENT_COUNT_OF((mem).m.ours.fwd_keys)},                                                    \
     {(percepts_), (places_), (mem).m.ours.classes,                                              \
      AGENT_COUNT_OF((mem).m.ours.classes), (mem).m.ours.arrivals, AGENT_COUNT_OF((mem).m.ours.arrivals)}, \
     (mem).pq_heap,                                                                              \
     (mem).pq_index_keys,                                                                        \
     (mem).pq_index_pos,                                                                         \
     AGENT_COUNT_OF((mem).pq_heap),                                                              \
     &(mem).m.ours.carry,                                                                        \
     {{(mem).m.paper.fwd_keys, (mem).m.paper.fwd_counts, (mem).m.paper.fwd_weights,                  \
       AGENT_COUNT_OF((mem).m.paper.fwd_keys)},                                                  \
      {(mem).m.paper.inv_keys, (mem).m.paper.inv_counts, (mem).m.paper.inv_weights,                  \
       AGENT_COUNT_OF((mem).m.paper.inv_keys)}}}

#ifdef __cplusplus
}
#endif

#endif // AGENT_DYNA_QPC_H
