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

/// The arena as JSON (docs/tools.md): width, height, obstacles, goal, beacons.
std::string arena_json(const world::Scenario &sc);

}  // namespace dynaqpc

#endif  // DYNAQPC_SIM_SCENARIO_BRIDGE_H
