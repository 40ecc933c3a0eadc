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

#ifdef __cplusplus
}
#endif

#endif // AGENT_Q_LEARNING_H
