// SPDX-License-Identifier: MIT
// dynaqpc: the static storage of the "paper-lab" agent profile and its agent: this object's size is the agent's RAM.
#include "robot/agent_profiles.h"

static agent_memory_paper_lab_t memory_;

const agent_storage_t agent_storage_paper_lab = AGENT_STORAGE_OF(memory_);

agent_t agent_paper_lab;
