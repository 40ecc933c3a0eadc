// SPDX-License-Identifier: MIT
// dynaqpc robot application: static storage for the agent profiles, with their RAM budgets
// checked at compile time. The application picks the profile; the agent only takes storage.
#ifndef AGENT_PROFILES_H
#define AGENT_PROFILES_H

#include "agent/agent.h"
#include "fw/fw_base.h"
#include "fw_config.h"
#include "robot/agent_profile_config.h"

#ifdef __cplusplus
extern "C" {
#endif

/// A profile as the algorithms' memories read it: P(KNOB) is its setting FW_CFG_<profile>_KNOB
/// (robot/agent_profile_config.h). Each algorithm's header says which settings its memory reads
/// (AGENT_MEMORY_<id>); the Dyna-Q tables size themselves from ALGORITHM_BYTES.
#define AGENT_PROFILE_MAZE(knob) FW_CFG_MAZE_##knob
#define AGENT_PROFILE_PAPER_LAB(knob) FW_CFG_LAB_##knob
#define AGENT_PROFILE_PAPER_SIM(knob) FW_CFG_SIM_##knob
#define AGENT_PROFILE_PAPER_SIM_LARGE(knob) FW_CFG_SIM_LARGE_##knob

#define AGENT_MEMORY_MEMBER_(kind, number, name, label, id, P) AGENT_MEMORY_##id(P) id;
/// The storage of one agent in profile P: the Q store (Q_TYPE is float or value16_t, qstore.h),
/// the tried-pairs table of the exploration bonus (explore.h, shared by the algorithms), and an
/// overlay of every registered algorithm's memory (an agent runs one algorithm, so all get the
/// same bytes).
#define AGENT_MEMORY_STRUCT(P)                                                                 \
    struct {                                                                                   \
        P(Q_TYPE) q[(P(Q_STATES)) * FW_CFG_MAX_ACTIONS];                                       \
        uint32_t q_keys[P(Q_STATES)];                                                          \
        uint32_t tried_keys[P(TRIED_PAIRS)];                                                   \
        uint32_t tried_at[P(TRIED_PAIRS)];                                                     \
        union {                                                                                \
            AGENT_ALGORITHMS_WITH(AGENT_MEMORY_MEMBER_, P)                                     \
        } alg;                                                                                 \
    }

#define AGENT_STORAGE_PART_(kind, number, name, label, id, mem) .id = AGENT_STORAGE_##id((mem).alg.id),
/// An agent_storage_t initializer pointing into a variable of an AGENT_MEMORY_STRUCT type.
#define AGENT_STORAGE_OF(mem)                                                                  \
    {                                                                                          \
        .q = (mem).q, .q_value_bytes = (uint8_t)sizeof((mem).q[0]), .q_keys = (mem).q_keys,    \
        .q_states = AGENT_COUNT_OF((mem).q_keys), .tried_keys = (mem).tried_keys,              \
        .tried_at = (mem).tried_at, .tried_pairs = AGENT_COUNT_OF((mem).tried_keys),           \
        AGENT_ALGORITHMS_WITH(AGENT_STORAGE_PART_, mem)                                        \
    }

typedef AGENT_MEMORY_STRUCT(AGENT_PROFILE_MAZE) agent_memory_maze_t;
typedef AGENT_MEMORY_STRUCT(AGENT_PROFILE_PAPER_LAB) agent_memory_paper_lab_t;
typedef AGENT_MEMORY_STRUCT(AGENT_PROFILE_PAPER_SIM) agent_memory_paper_sim_t;

/// paper-sim-large (agent_profile_config.h) in two parts, so that the STM32F427 image can place
/// them in its two RAMs (docs/porting.md, "robot-f42x"): the Q values, the tried pairs and the
/// algorithms' overlay (the SRAM's), and its Q keys, 16-bit (qstore_init16), with Dyna-QPC's
/// percept map (CCM's: 64 KiB). The overlay is sized as the profile's but for that map
/// (AGENT_PROFILE_PAPER_SIM_LARGE_OVERLAY: 1 place in it, unused).
#define AGENT_PROFILE_PAPER_SIM_LARGE_OVERLAY(knob) AGENT_SIM_LARGE_OVERLAY_##knob
#define AGENT_SIM_LARGE_OVERLAY_ALGORITHM_BYTES FW_CFG_SIM_LARGE_ALGORITHM_BYTES
#define AGENT_SIM_LARGE_OVERLAY_CMAC_CELLS FW_CFG_SIM_LARGE_CMAC_CELLS
#define AGENT_SIM_LARGE_OVERLAY_CLASSES FW_CFG_SIM_LARGE_CLASSES
#define AGENT_SIM_LARGE_OVERLAY_PLACES 1
#define AGENT_SIM_LARGE_OVERLAY_POSITIONS FW_CFG_SIM_LARGE_POSITIONS
#define AGENT_SIM_LARGE_OVERLAY_PQ_CAPACITY FW_CFG_SIM_LARGE_PQ_CAPACITY
#define AGENT_SIM_LARGE_OVERLAY_PAPER_FWD_CELLS FW_CFG_SIM_LARGE_PAPER_FWD_CELLS
#define AGENT_SIM_LARGE_OVERLAY_PAPER_INV_CELLS FW_CFG_SIM_LARGE_PAPER_INV_CELLS
typedef struct {
    FW_CFG_SIM_LARGE_Q_TYPE q[FW_CFG_SIM_LARGE_Q_STATES * FW_CFG_MAX_ACTIONS];
    uint32_t tried_keys[FW_CFG_SIM_LARGE_TRIED_PAIRS];
    uint32_t tried_at[FW_CFG_SIM_LARGE_TRIED_PAIRS];
    union {
        AGENT_ALGORITHMS_WITH(AGENT_MEMORY_MEMBER_, AGENT_PROFILE_PAPER_SIM_LARGE_OVERLAY)
    } alg;
} agent_memory_paper_sim_large_t;
typedef struct {
    uint16_t q_keys16[FW_CFG_SIM_LARGE_Q_STATES];
    uint16_t percepts[FW_CFG_SIM_LARGE_PLACES];
} agent_memory_paper_sim_large_apart_t;
/// Its whole storage (both parts).
#define AGENT_PAPER_SIM_LARGE_BYTES \
    (sizeof(agent_memory_paper_sim_large_t) + sizeof(agent_memory_paper_sim_large_apart_t))

// Each profile's agent (its storage plus the agent_t that manages it) must fit its budget.
FW_STATIC_ASSERT(sizeof(agent_memory_maze_t) + sizeof(agent_t) <= FW_CFG_MAZE_BUDGET_BYTES,
                 maze_agent_fits_budget);
FW_STATIC_ASSERT(sizeof(agent_memory_paper_lab_t) + sizeof(agent_t) <= FW_CFG_LAB_BUDGET_BYTES,
                 paper_lab_agent_fits_budget);
FW_STATIC_ASSERT(sizeof(agent_memory_paper_sim_t) + sizeof(agent_t) <= FW_CFG_SIM_BUDGET_BYTES,
                 paper_sim_agent_fits_budget);
FW_STATIC_ASSERT(AGENT_PAPER_SIM_LARGE_BYTES + sizeof(agent_t) <= FW_CFG_SIM_LARGE_BUDGET_BYTES,
                 paper_sim_large_agent_fits_budget);

// ALGORITHM_BYTES is what the overlay of the algorithms' memories takes on the MCU (32-bit
// pointers): Dyna-QPC's model and queue, the largest, whose settings must change with it
// (agent_profile_config.h). The Dyna-Q tables fill as much of it as they can (DYNAQ_RECORDS_IN). The host's
// overlay is 80 bytes larger (the planner's carry holds pointers), so the simulator runs the
// MCU's tables.
#define AGENT_OVERLAY_IS_(T, bytes) (sizeof(void *) != 4u || sizeof(((T *)0)->alg) == (bytes))
FW_STATIC_ASSERT(AGENT_OVERLAY_IS_(agent_memory_maze_t, FW_CFG_MAZE_ALGORITHM_BYTES) &&
                     AGENT_OVERLAY_IS_(agent_memory_paper_lab_t, FW_CFG_LAB_ALGORITHM_BYTES) &&
                     AGENT_OVERLAY_IS_(agent_memory_paper_sim_t, FW_CFG_SIM_ALGORITHM_BYTES) &&
                     AGENT_OVERLAY_IS_(agent_memory_paper_sim_large_t, FW_CFG_SIM_LARGE_ALGORITHM_BYTES),
                 the_algorithms_overlay_takes_ALGORITHM_BYTES_on_the_MCU);

// The paper's CMACs (model paper) overlay our model and the planner's carry: they must not make
// Dyna-QPC's memory larger, or ALGORITHM_BYTES would no longer be our model's.
#define AGENT_PAPER_FITS_(T)                                                                   \
    (sizeof(((T *)0)->alg.dyna_qpc.m.paper) <= sizeof(((T *)0)->alg.dyna_qpc.m.ours))
FW_STATIC_ASSERT(AGENT_PAPER_FITS_(agent_memory_maze_t) && AGENT_PAPER_FITS_(agent_memory_paper_lab_t) &&
                     AGENT_PAPER_FITS_(agent_memory_paper_sim_t) &&
                     AGENT_PAPER_FITS_(agent_memory_paper_sim_large_t),
                 paper_models_fit_in_our_model_s_bytes);
// Every hashed table is a power of two (hashing masks the index); the Dyna-Q tables' records
// need not be (their index is: DYNAQ_INDEX_SLOTS). Of the profile whose limits are FW_CFG_<P>_*:
// the Q store, CMAC-Model, the queue and the tried pairs; the paper model's CMACs.
#define AGENT_TABLES_POW2_(P)                                                    \
    (FW_IS_POW2(FW_CFG_##P##_Q_STATES) && FW_IS_POW2(FW_CFG_##P##_CMAC_CELLS) &&  \
     FW_IS_POW2(FW_CFG_##P##_PQ_CAPACITY) && FW_IS_POW2(FW_CFG_##P##_TRIED_PAIRS))
#define AGENT_PAPER_TABLES_POW2_(P)                                               \
    (FW_IS_POW2(FW_CFG_##P##_PAPER_FWD_CELLS) && FW_IS_POW2(FW_CFG_##P##_PAPER_INV_CELLS))
FW_STATIC_ASSERT(AGENT_TABLES_POW2_(LAB) && AGENT_PAPER_TABLES_POW2_(LAB), paper_lab_tables_pow2);
FW_STATIC_ASSERT(AGENT_TABLES_POW2_(SIM) && AGENT_PAPER_TABLES_POW2_(SIM), paper_sim_tables_pow2);
FW_STATIC_ASSERT(AGENT_TABLES_POW2_(SIM_LARGE) && AGENT_PAPER_TABLES_POW2_(SIM_LARGE),
                 paper_sim_large_tables_pow2);
FW_STATIC_ASSERT(AGENT_TABLES_POW2_(MAZE) && AGENT_PAPER_TABLES_POW2_(MAZE), maze_tables_pow2);

/// The storage of each profile and an agent to run on it, one static instance each, defined in
/// its own object file so that an image links only the profile it uses and the size report of
/// that object is the whole agent's RAM.
extern const agent_storage_t agent_storage_maze;
extern const agent_storage_t agent_storage_paper_lab;
extern const agent_storage_t agent_storage_paper_sim;
extern const agent_storage_t agent_storage_paper_sim_large;
extern agent_t agent_maze;
extern agent_t agent_paper_lab;
extern agent_t agent_paper_sim;
extern agent_t agent_paper_sim_large;

#ifdef __cplusplus
}
#endif

#endif // AGENT_PROFILES_H
