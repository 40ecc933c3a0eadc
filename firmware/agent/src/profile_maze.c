// SPDX-License-Identifier: MIT
// dynaqpc: the static storage of the "maze" agent profile (its size is the agent's RAM).
#include "agent/agent_profiles.h"

static agent_memory_maze_t memory_;

const agent_storage_t agent_storage_maze = AGENT_STORAGE_OF(memory_);
