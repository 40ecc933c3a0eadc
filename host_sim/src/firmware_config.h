// SPDX-License-Identifier: MIT
// dynaqpc-sim: a robot_config_t as C source, every field by name. One emitter serves both
// `dynaqpc-sim firmware-config` (which writes firmware/robot/src/robot_scenarios.c from the
// scenario files) and the tests that compare configurations as whole structures.
#ifndef DYNAQPC_SIM_FIRMWARE_CONFIG_H
#define DYNAQPC_SIM_FIRMWARE_CONFIG_H

#include <string>
#include <vector>

#include "robot/robot_config.h"

namespace dynaqpc {

/// `const robot_config_t <var> = { .field = value, ... };` with every field of robot_config_t
/// (and of agent_params_t), floats in the shortest text that reads back to the same float.
/// Two configurations are equal, field for field and bit for bit, exactly when these are.
std::string robot_config_c(const robot_config_t &cfg, const std::string &var);

/// The whole robot_scenarios.c for the named shipped scenarios (host_sim/scenarios/<name>.scn),
/// each as robot_config_<name with '-' as '_'>.
std::string robot_scenarios_c(const std::vector<std::string> &names);

}  // namespace dynaqpc

#endif  // DYNAQPC_SIM_FIRMWARE_CONFIG_H
