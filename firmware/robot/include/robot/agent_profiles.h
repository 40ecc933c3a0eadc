// SPDX-License-Identifier: MIT
// dynaqpc robot application: static storage for the agent profiles, with their RAM budgets
// checked at compile time. The application picks the profile; the agent only takes storage.
#ifndef AGENT_PROFILES_H
#define AGENT_PROFILES_H

#include "agent/agent.h"
#include "fw/fw_base.h"
#include "fw_config.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The storage of one agent: the Q store, and an overlay of Dyna-QPC's models and queue with
/// Dyna-Q's table and Dyna-Q-majority's (an agent runs one algorithm, so all get the same
/// memory: fw_config.h sizes the tables to fill the same bytes). Within Dyna-QPC's part, the
/// paper's two CMACs (`model paper`) overlay our model and the planner's carry, and share the
/// queue. Q_TYPE is float or value16_t (qstore.h).
#define AGENT_MEMORY_STRUCT(Q_TYPE, Q_STATES, CELLS, PQ_CAP, TABLE_STATES, MAJORITY_STATES, PLACES, \
                            CLASSES, POSITIONS, PAPER_FWD, PAPER_INV)                          \
    struct {                                                                                   \
        Q_TYPE q[(Q_STATES)*FW_CFG_MAX_ACTIONS];                                               \
        uint32_t q_keys[Q_STATES];                                                             \
        union {                                                                                \
            struct {                                                                           \
                union {                                                                        \
                    struct {                                                                   \
                        uint32_t fwd_keys[CELLS];                                              \
                        int16_t fwd_weights[(CELLS) * (FW_CFG_MAX_COMPONENTS + 2)];            \
                        uint8_t fwd_counts[CELLS];                                             \
                        model_class_t classes[CLASSES];                                        \
                        uint16_t percepts[PLACES];                                             \
                        int16_t arrivals[POSITIONS];                                           \
                        agent_plan_carry_t carry;                                              \
                    } ours;                                                                    \
                    struct {                                                                   \
                        uint32_t fwd_keys[PAPER_FWD];                                          \
                        int16_t fwd_weights[(PAPER_FWD) * (FW_CFG_MAX_COMPONENTS + 2)];        \
                        uint8_t fwd_counts[PAPER_FWD];                                         \
                        uint32_t inv_keys[PAPER_INV];                                          \
                        int16_t inv_weights[(PAPER_INV) * (FW_CFG_MAX_COMPONENTS + 1)];        \
                        uint8_t inv_counts[PAPER_INV];                                         \
                    } paper;                                                                   \
                } m;                                                                           \
                pq_item_t pq_heap[PQ_CAP];                                                     \
                uint32_t pq_index_keys[PQ_INDEX_SLOTS(PQ_CAP)];                                \
                uint32_t pq_index_pos[PQ_INDEX_SLOTS(PQ_CAP)];                                 \
            } qpc;                                                                             \
            struct {                                                                           \
                dynaq_record_t records[TABLE_STATES];                                          \
                uint32_t index_keys[DYNAQ_INDEX_SLOTS(TABLE_STATES)];                          \
                uint32_t index_rec[DYNAQ_INDEX_SLOTS(TABLE_STATES)];                           \
            } dynaq;                                                                           \
            struct {                                                                           \
                dynaq_record_t records[MAJORITY_STATES];                                       \
                uint32_t index_keys[DYNAQ_INDEX_SLOTS(MAJORITY_STATES)];                       \
                uint32_t index_rec[DYNAQ_INDEX_SLOTS(MAJORITY_STATES)];                        \
                uint8_t counts[(MAJORITY_STATES)*FW_CFG_MAX_ACTIONS];                          \
            } majority;                                                                        \
        } model;                                                                               \
    }

#define AGENT_COUNT_OF(a) ((uint32_t)(sizeof(a) / sizeof((a)[0])))

/// An agent_storage_t initializer pointing into a variable of an AGENT_MEMORY_STRUCT type.
#define AGENT_STORAGE_OF(mem)                                                                  \
    {                                                                                          \
        .q = (mem).q, .q_value_bytes = (uint8_t)sizeof((mem).q[0]), .q_keys = (mem).q_keys,    \
        .q_states = AGENT_COUNT_OF((mem).q_keys),                                              \
        .dyna_q = {(mem).model.dynaq.records, (mem).model.dynaq.index_keys,                    \
                   (mem).model.dynaq.index_rec, AGENT_COUNT_OF((mem).model.dynaq.records)},    \
        .dyna_qpc = {{(mem).model.qpc.m.ours.fwd_keys, (mem).model.qpc.m.ours.fwd_counts,        \
                      (mem).model.qpc.m.ours.fwd_weights,                                      \
                      AGENT_COUNT_OF((mem).model.qpc.m.ours.fwd_keys)},                        \
                     {(mem).model.qpc.m.ours.percepts, AGENT_COUNT_OF((mem).model.qpc.m.ours.percepts), \
                      (mem).model.qpc.m.ours.classes, AGENT_COUNT_OF((mem).model.qpc.m.ours.classes), \
                      (mem).model.qpc.m.ours.arrivals,                                         \
                      AGENT_COUNT_OF((mem).model.qpc.m.ours.arrivals)},                        \
                     (mem).model.qpc.pq_heap, (mem).model.qpc.pq_index_keys,                   \
                     (mem).model.qpc.pq_index_pos, AGENT_COUNT_OF((mem).model.qpc.pq_heap),    \
                     &(mem).model.qpc.m.ours.carry,                                            \
                     {{(mem).model.qpc.m.paper.fwd_keys, (mem).model.qpc.m.paper.fwd_counts,   \
                       (mem).model.qpc.m.paper.fwd_weights,                                    \
                       AGENT_COUNT_OF((mem).model.qpc.m.paper.fwd_keys)},                      \
                      {(mem).model.qpc.m.paper.inv_keys, (mem).model.qpc.m.paper.inv_counts,   \
                       (mem).model.qpc.m.paper.inv_weights,                                    \
                       AGENT_COUNT_OF((mem).model.qpc.m.paper.inv_keys)}}},                    \
        .dyna_q_majority = {(mem).model.majority.records, (mem).model.majority.index_keys,     \
                            (mem).model.majority.index_rec, (mem).model.majority.counts,       \
                            AGENT_COUNT_OF((mem).model.majority.records)},                     \
    }

typedef AGENT_MEMORY_STRUCT(FW_CFG_MAZE_Q_TYPE, FW_CFG_MAZE_Q_STATES, FW_CFG_MAZE_CMAC_CELLS, FW_CFG_MAZE_PQ_CAPACITY,
                            FW_CFG_MAZE_TABLE_STATES, FW_CFG_MAZE_MAJORITY_STATES, FW_CFG_MAZE_PLACES,
                            FW_CFG_MAZE_CLASSES, FW_CFG_MAZE_POSITIONS,
                            FW_CFG_MAZE_PAPER_FWD_CELLS, FW_CFG_MAZE_PAPER_INV_CELLS) agent_memory_maze_t;
typedef AGENT_MEMORY_STRUCT(FW_CFG_LAB_Q_TYPE, FW_CFG_LAB_Q_STATES, FW_CFG_LAB_CMAC_CELLS, FW_CFG_LAB_PQ_CAPACITY,
                            FW_CFG_LAB_TABLE_STATES, FW_CFG_LAB_MAJORITY_STATES, FW_CFG_LAB_PLACES,
                            FW_CFG_LAB_CLASSES, FW_CFG_LAB_POSITIONS,
                            FW_CFG_LAB_PAPER_FWD_CELLS, FW_CFG_LAB_PAPER_INV_CELLS) agent_memory_paper_lab_t;
typedef AGENT_MEMORY_STRUCT(FW_CFG_SIM_Q_TYPE, FW_CFG_SIM_Q_STATES, FW_CFG_SIM_CMAC_CELLS, FW_CFG_SIM_PQ_CAPACITY,
                            FW_CFG_SIM_TABLE_STATES, FW_CFG_SIM_MAJORITY_STATES, FW_CFG_SIM_PLACES,
                            FW_CFG_SIM_CLASSES, FW_CFG_SIM_POSITIONS,
                            FW_CFG_SIM_PAPER_FWD_CELLS, FW_CFG_SIM_PAPER_INV_CELLS) agent_memory_paper_sim_t;

// Each profile's agent (its storage plus the agent_t that manages it) must fit its budget.
FW_STATIC_ASSERT(sizeof(agent_memory_maze_t) + sizeof(agent_t) <= FW_CFG_MAZE_BUDGET_BYTES,
                 maze_agent_fits_budget);
FW_STATIC_ASSERT(sizeof(agent_memory_paper_lab_t) + sizeof(agent_t) <= FW_CFG_LAB_BUDGET_BYTES,
                 paper_lab_agent_fits_budget);
FW_STATIC_ASSERT(sizeof(agent_memory_paper_sim_t) + sizeof(agent_t) <= FW_CFG_SIM_BUDGET_BYTES,
                 paper_sim_agent_fits_budget);

// The paper's CMACs (model paper) overlay our model and the planner's carry: they must not make
// Dyna-QPC's area larger, or the Dyna-Q tables below would no longer get exactly its bytes.
#define AGENT_PAPER_FITS_(T)                                                                   \
    (sizeof(((T *)0)->model.qpc.m.paper) <= sizeof(((T *)0)->model.qpc.m.ours))
FW_STATIC_ASSERT(AGENT_PAPER_FITS_(agent_memory_maze_t) && AGENT_PAPER_FITS_(agent_memory_paper_lab_t) &&
                     AGENT_PAPER_FITS_(agent_memory_paper_sim_t),
                 paper_models_fit_in_our_model_s_bytes);
FW_STATIC_ASSERT(FW_IS_POW2(FW_CFG_MAZE_PAPER_FWD_CELLS) && FW_IS_POW2(FW_CFG_MAZE_PAPER_INV_CELLS) &&
                     FW_IS_POW2(FW_CFG_LAB_PAPER_FWD_CELLS) && FW_IS_POW2(FW_CFG_LAB_PAPER_INV_CELLS) &&
                     FW_IS_POW2(FW_CFG_SIM_PAPER_FWD_CELLS) && FW_IS_POW2(FW_CFG_SIM_PAPER_INV_CELLS),
                 paper_model_tables_pow2);

// The Dyna-Q tables get the bytes of Dyna-QPC's model and queue, which they overlay, on every
// profile: they fit, and on the MCU (32-bit pointers) one more record would not (fw_config.h:
// what to set when the model's tables change size). The host's model area is 80 bytes larger
// (the planner's carry holds pointers), so the simulator runs the MCU's tables.
#define AGENT_DYNAQ_BYTES_(n)                                                                  \
    ((uint32_t)(n) * (uint32_t)sizeof(dynaq_record_t) +                                        \
     2u * DYNAQ_INDEX_SLOTS(n) * (uint32_t)sizeof(uint32_t))
#define AGENT_MAJORITY_BYTES_(n) (AGENT_DYNAQ_BYTES_(n) + (uint32_t)(n) * FW_CFG_MAX_ACTIONS)
#define AGENT_QPC_BYTES_(T) ((uint32_t)sizeof(((T *)0)->model.qpc))
#define AGENT_FILLS_(bytes_of, n, T)                                                           \
    (bytes_of(n) <= AGENT_QPC_BYTES_(T) &&                                                     \
     (sizeof(void *) != 4u || bytes_of((n) + 1u) > AGENT_QPC_BYTES_(T)))
FW_STATIC_ASSERT(AGENT_FILLS_(AGENT_DYNAQ_BYTES_, FW_CFG_MAZE_TABLE_STATES, agent_memory_maze_t) &&
                     AGENT_FILLS_(AGENT_MAJORITY_BYTES_, FW_CFG_MAZE_MAJORITY_STATES,
                                  agent_memory_maze_t),
                 maze_dyna_q_tables_get_the_model_s_bytes);
FW_STATIC_ASSERT(AGENT_FILLS_(AGENT_DYNAQ_BYTES_, FW_CFG_LAB_TABLE_STATES,
                              agent_memory_paper_lab_t) &&
                     AGENT_FILLS_(AGENT_MAJORITY_BYTES_, FW_CFG_LAB_MAJORITY_STATES,
                                  agent_memory_paper_lab_t),
                 paper_lab_dyna_q_tables_get_the_model_s_bytes);
FW_STATIC_ASSERT(AGENT_FILLS_(AGENT_DYNAQ_BYTES_, FW_CFG_SIM_TABLE_STATES,
                              agent_memory_paper_sim_t) &&
                     AGENT_FILLS_(AGENT_MAJORITY_BYTES_, FW_CFG_SIM_MAJORITY_STATES,
                                  agent_memory_paper_sim_t),
                 paper_sim_dyna_q_tables_get_the_model_s_bytes);

// Every hashed table is a power of two (hashing masks the index); the Dyna-Q tables' records
// need not be (their index is: DYNAQ_INDEX_SLOTS).
FW_STATIC_ASSERT(FW_IS_POW2(FW_CFG_LAB_Q_STATES) && FW_IS_POW2(FW_CFG_LAB_CMAC_CELLS) &&
                     FW_IS_POW2(FW_CFG_LAB_PQ_CAPACITY),
                 paper_lab_tables_pow2);
FW_STATIC_ASSERT(FW_IS_POW2(FW_CFG_SIM_Q_STATES) && FW_IS_POW2(FW_CFG_SIM_CMAC_CELLS) &&
                     FW_IS_POW2(FW_CFG_SIM_PQ_CAPACITY),
                 paper_sim_tables_pow2);
FW_STATIC_ASSERT(FW_IS_POW2(FW_CFG_MAZE_Q_STATES) && FW_IS_POW2(FW_CFG_MAZE_CMAC_CELLS) &&
                     FW_IS_POW2(FW_CFG_MAZE_PQ_CAPACITY),
                 maze_tables_pow2);

/// The storage of each profile and an agent to run on it, one static instance each, defined in
/// its own object file so that an image links only the profile it uses and the size report of
/// that object is the whole agent's RAM.
extern const agent_storage_t agent_storage_maze;
extern const agent_storage_t agent_storage_paper_lab;
extern const agent_storage_t agent_storage_paper_sim;
extern agent_t agent_maze;
extern agent_t agent_paper_lab;
extern agent_t agent_paper_sim;

#ifdef __cplusplus
}
#endif

#endif // AGENT_PROFILES_H
