// SPDX-License-Identifier: MIT
// dynaqpc-sim / dynaqpc-fw: which agent profile (agent_profiles.h) the firmware uses for a
// configuration, and the boot options the two share.
#ifndef DYNAQPC_SIM_AGENT_PICK_H
#define DYNAQPC_SIM_AGENT_PICK_H

#include <cstdint>
#include <string>

#include "robot/agent_profiles.h"
#include "robot/robot_app.h"
#include "robot/robot_config.h"

namespace dynaqpc {

/// The smallest profile whose tables suit cfg's state space: paper-lab's up to 13 state bits,
/// paper-sim's (192 KiB, the default robot's) up to 18, paper-sim-large's (16,384 Q rows: the
/// 16 x 16 m floor, 64 x 64 cells) beyond. A floor of up to 13 bits whose model paper-lab's
/// tables cannot hold takes paper-sim's. A configuration whose model the profile's tables
/// cannot hold (percept map, per-position table, situations) is refused: std::runtime_error
/// naming the profile, its bytes and the bytes it would need (profile_need()).
void pick_agent_profile(const robot_config_t &cfg, agent_t **agent, const agent_storage_t **storage);

/// robot_app_init()'s options as every host boot of the firmware starts them (lock-step and
/// dynaqpc-fw): `cfg` (which must outlive the firmware), its agent profile, the seed, and what was
/// learned kept in flash; the rest zero, for the caller to set.
robot_app_options_t host_app_options(const robot_config_t &cfg, std::uint32_t seed);

/// What a profile holds and what cfg needs of it (bytes on the MCU: the agent's storage and
/// agent_t; the tables the model sizes by the floor: places, positions and situations).
struct ProfileNeed {
    const char *profile;       ///< "paper-lab", "paper-sim" or "paper-sim-large"
    std::uint32_t bytes;       ///< what the profile takes
    std::uint32_t need_bytes;  ///< what it would take with tables that hold cfg's floor
    std::string short_of;      ///< the tables that are short, e.g. "places 65536 > 16384"; empty: fits
};
ProfileNeed profile_need(const robot_config_t &cfg);

}  // namespace dynaqpc

#endif  // DYNAQPC_SIM_AGENT_PICK_H
