// SPDX-License-Identifier: MIT
// dynaqpc-sim / dynaqpc-fw: which agent profile (agent_profiles.h) the firmware uses for a
// configuration, and the boot options the two share.
#ifndef DYNAQPC_SIM_AGENT_PICK_H
#define DYNAQPC_SIM_AGENT_PICK_H

#include <cstdint>

#include "robot/agent_profiles.h"
#include "robot/robot_app.h"
#include "robot/robot_config.h"

namespace dynaqpc {

/// The smallest profile whose tables suit cfg's state space: paper-lab's up to 13 state bits,
/// paper-sim's beyond (the same rule as the lock-step runner).
void pick_agent_profile(const robot_config_t &cfg, agent_t **agent, const agent_storage_t **storage);

/// robot_app_init()'s options as every host boot of the firmware starts them (lock-step and
/// dynaqpc-fw): `cfg` (which must outlive the firmware), its agent profile, the seed, and what was
/// learned kept in flash; the rest zero, for the caller to set.
robot_app_options_t host_app_options(const robot_config_t &cfg, std::uint32_t seed);

}  // namespace dynaqpc

#endif  // DYNAQPC_SIM_AGENT_PICK_H
