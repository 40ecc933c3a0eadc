// SPDX-License-Identifier: MIT
// dynaqpc-sim: the subcommands main() dispatches to, one file each (cmd_<name>.cpp).
#ifndef DYNAQPC_SIM_COMMANDS_H
#define DYNAQPC_SIM_COMMANDS_H

#include <string>
#include <vector>

namespace dynaqpc {

/// A subcommand: `program` is argv[0]'s name for messages, `args` what follows the subcommand's
/// name. Returns the process exit status (options.h's ExitStatus). Usage problems print one line
/// on stderr and return kExitUsage; `--help` prints usage on stdout and returns kExitOk.
using CommandFn = int (*)(const std::string &program, const std::vector<std::string> &args);

struct Command {
    const char *name;
    const char *summary;
    CommandFn run;
};

/// `maze`: gridworld experiments (cmd_maze.cpp).
int cmd_maze(const std::string &program, const std::vector<std::string> &args);

/// `train`: the firmware learns on the simulated robot (cmd_train.cpp).
int cmd_train(const std::string &program, const std::vector<std::string> &args);

/// `run`: replays a learned policy from random starts (cmd_run.cpp).
int cmd_run(const std::string &program, const std::vector<std::string> &args);

/// `learned`: what a flash image holds, decoded by the firmware, as JSON (cmd_learned.cpp).
int cmd_learned(const std::string &program, const std::vector<std::string> &args);

/// `devices`: the simulated robot's devices in real time on the virtual CAN bus (cmd_devices.cpp).
int cmd_devices(const std::string &program, const std::vector<std::string> &args);

/// `rooms`: seeded random rooms for a robot, one scenario file each (cmd_rooms.cpp).
int cmd_rooms(const std::string &program, const std::vector<std::string> &args);

/// `speed`: lock-step's speed against the bare world's, in the same run (cmd_speed.cpp).
int cmd_speed(const std::string &program, const std::vector<std::string> &args);

/// `agents`: the learning algorithms the firmware registers (cmd_agents.cpp).
int cmd_agents(const std::string &program, const std::vector<std::string> &args);

/// `firmware-config`: the MCU images' built-in scenarios as C (cmd_firmware_config.cpp).
int cmd_firmware_config(const std::string &program, const std::vector<std::string> &args);

}  // namespace dynaqpc

#endif  // DYNAQPC_SIM_COMMANDS_H
