// SPDX-License-Identifier: MIT
// dynaqpc-sim: a scenario file, as the world sees it and as the firmware sees it.
#ifndef DYNAQPC_SIM_SCENARIO_BRIDGE_H
#define DYNAQPC_SIM_SCENARIO_BRIDGE_H

#include <cstdint>
#include <memory>
#include <string>

#include "robot/robot_config.h"

namespace world {
struct Scenario;
}

namespace dynaqpc {

class Options;

/// A loaded scenario: the world's description and the firmware configuration built from it.
struct ScenarioBundle {
    std::shared_ptr<const world::Scenario> world;
    robot_config_t robot{};
    std::string name;  ///< kept alive for robot.name
    std::string path;
    std::uint32_t sets = 1;       ///< the scenario's protocol
    std::uint32_t episodes = 1;
};

/// Loads `--scenario NAME|FILE`. A bad file throws UsageError "FILE:LINE: problem".
ScenarioBundle load_scenario(const std::string &arg);

/// The agent an `--agent` option names: q, dyna-q or dyna-qpc (anything else: dyna-qpc).
agent_kind_t agent_kind_of(const std::string &name);

/// What a command line may change in a scenario's configuration: the variables a command's
/// Options fill in, null where the command has no such option. The agent always applies (the
/// option's default is dyna-qpc); the rest only when their option was given.
struct ConfigOverrides {
    const std::string *agent = nullptr;        ///< --agent
    const std::uint32_t *planning = nullptr;   ///< --planning
    const std::uint32_t *step_cap = nullptr;   ///< --step-cap
    const double *epsilon = nullptr;           ///< --epsilon
    const double *alpha = nullptr;             ///< --alpha: the Q learning rate, real and planning
    const double *gamma = nullptr;             ///< --gamma
};

/// Applies `v` to `cfg` as the options `o` were given (one place for train, run and dynaqpc-fw).
void apply_overrides(const Options &o, const ConfigOverrides &v, robot_config_t *cfg);

/// The arena as JSON (docs/tools.md): width, height, obstacles, goal, beacons.
std::string arena_json(const world::Scenario &sc);

}  // namespace dynaqpc

#endif  // DYNAQPC_SIM_SCENARIO_BRIDGE_H
