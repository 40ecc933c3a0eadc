// SPDX-License-Identifier: MIT
// dynaqpc: Q-learning (the paper's Fig. 1): the shared Q step and nothing else.
#ifndef AGENT_Q_LEARNING_H
#define AGENT_Q_LEARNING_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/// Q-learning keeps nothing beside the Q store every agent has (C99 has no empty structs).
typedef struct agent_q_learning {
    uint8_t none;
} agent_q_learning_t;

/// ... and needs no storage beside it.
typedef struct agent_q_learning_storage {
    uint8_t none;
} agent_q_learning_storage_t;

/// Its memory in a profile P (agent_profiles.h): none.
#define AGENT_MEMORY_q_learning(P) \
    struct {                       \
        uint8_t none;              \
    }
/// Its part of agent_storage_t, in memory `m` of that type.
#define AGENT_STORAGE_q_learning(m) {0}

#ifdef __cplusplus
}
#endif

#endif // AGENT_Q_LEARNING_H
