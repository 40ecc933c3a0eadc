// SPDX-License-Identifier: MIT
// dynaqpc: the static storage of the "maze" agent profile and its agent: this object's size is the agent's RAM.
#include "robot/agent_profiles.h"

static agent_memory_maze_t memory_;

const agent_storage_t agent_storage_maze = AGENT_STORAGE_OF(memory_);

agent_t agent_maze;
