// SPDX-License-Identifier: MIT
// dynaqpc-sim / dynaqpc-fw: which agent profile (agent_profiles.h) the firmware uses for a
// configuration.
#ifndef DYNAQPC_SIM_AGENT_PICK_H
#define DYNAQPC_SIM_AGENT_PICK_H

#include "robot/agent_profiles.h"
#include "robot/robot_config.h"

namespace dynaqpc {

/// The smallest profile whose tables suit cfg's state space: paper-lab's up to 13 state bits,
/// paper-sim's beyond (the same rule as the lock-step runner).
void pick_agent_profile(const robot_config_t &cfg, agent_t **agent, const agent_storage_t **storage);

}  // namespace dynaqpc

#endif  // DYNAQPC_SIM_AGENT_PICK_H
