// SPDX-License-Identifier: MIT
// dynaqpc: the static storage of the "paper-sim-large" agent profile and its agent: this object's
// size is the agent's RAM. Two parts (agent_profiles.h): on the MCU the second, 64 KiB of 16-bit
// Q keys and Dyna-QPC's percept map, goes to the section .ccm, which the STM32F427's large image
// places in CCM (hal/ports/stm32f4/boards/robot-f42x/stm32f427-large.ld). The reset handler
// does not clear it (only .bss): its owners do, the Q store (qstore_clear) and the model
// (model_init, its reset) every time the agent starts, before either is read.
#include "robot/agent_profiles.h"

#if defined(__arm__) && !defined(__linux__)
#define IN_CCM_ __attribute__((section(".ccm")))
#else
#define IN_CCM_
#endif

static agent_memory_paper_sim_large_t memory_;
static agent_memory_paper_sim_large_apart_t apart_ IN_CCM_;

// Each algorithm's part, as AGENT_STORAGE_OF's; Dyna-QPC's percept map is the one apart.
#define LARGE_STORAGE_q_learning(mem) AGENT_STORAGE_q_learning((mem).alg.q_learning)
#define LARGE_STORAGE_dyna_q(mem) AGENT_STORAGE_dyna_q((mem).alg.dyna_q)
#define LARGE_STORAGE_dyna_q_majority(mem) AGENT_STORAGE_dyna_q_majority((mem).alg.dyna_q_majority)
#define LARGE_STORAGE_dyna_qpc(mem)                                                            \
    AGENT_STORAGE_dyna_qpc_PERCEPTS((mem).alg.dyna_qpc, apart_.percepts, AGENT_COUNT_OF(apart_.percepts))
#define LARGE_PART_(kind, number, name, label, id, mem) .id = LARGE_STORAGE_##id(mem),

const agent_storage_t agent_storage_paper_sim_large = {
    .q = memory_.q,
    .q_value_bytes = (uint8_t)sizeof(memory_.q[0]),
    .q_keys16 = apart_.q_keys16,
    .q_states = AGENT_COUNT_OF(apart_.q_keys16),
    .tried_keys = memory_.tried_keys,
    .tried_at = memory_.tried_at,
    .tried_pairs = AGENT_COUNT_OF(memory_.tried_keys),
    AGENT_ALGORITHMS_WITH(LARGE_PART_, memory_)
};

agent_t agent_paper_sim_large;
