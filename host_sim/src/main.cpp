// SPDX-License-Identifier: MIT
// dynaqpc-sim: the desktop simulator's command line. One subcommand per cmd_<name>.cpp.
#include <cstring>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "commands.h"
#include "options.h"

namespace {

// Add a subcommand here and in commands.h.
const dynaqpc::Command kCommands[] = {
    {"train", "the firmware learns on the simulated robot: sets of episodes, a CSV row each", dynaqpc::cmd_train},
    {"run", "replay a learned policy greedily from random starts, with a trajectory log", dynaqpc::cmd_run},
    {"learned", "what a flash image holds (Q, greedy actions, visited and modelled states, fill) as JSON", dynaqpc::cmd_learned},
    {"devices", "the simulated robot's devices in real time on the virtual CAN bus, for dynaqpc-fw", dynaqpc::cmd_devices},
    {"maze", "gridworld experiments: Q-learning, Dyna-Q and Dyna-QPC on a map", dynaqpc::cmd_maze},
    {"rooms", "seeded random rooms for paper-lab or paper-sim, one scenario file each", dynaqpc::cmd_rooms},
    {"speed", "lock-step's speed (firmware + devices + world) against the bare world's, in the same run", dynaqpc::cmd_speed},
    {"agents", "the learning algorithms the firmware registers: names, labels, models, counters", dynaqpc::cmd_agents},
    {"firmware-config", "the MCU images' built-in scenarios as C, from the scenario files", dynaqpc::cmd_firmware_config},
};

void print_usage(std::ostream &out, const std::string &program)
{
    out << "Usage: " << program << " <command> [options]\n"
        << "       " << program << " <command> --help\n\n"
        << "The dynaqpc desktop simulator.\n\nCommands:\n";
    for (const dynaqpc::Command &c : kCommands) {
        out << "  " << c.name << std::string(10 - std::min<std::size_t>(9, std::strlen(c.name)), ' ')
            << c.summary << '\n';
    }
    out << "\nExit status: 0 success, 1 a failure while running, 2 bad usage or bad input.\n";
}

}  // namespace

int main(int argc, char **argv)
{
    const std::string program = "dynaqpc-sim";
    std::vector<std::string> args(argv + (argc > 0 ? 1 : 0), argv + argc);

    if (args.empty()) {
        std::cerr << program << ": missing command (try '" << program << " --help')\n";
        return dynaqpc::kExitUsage;
    }
    if (args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
        print_usage(std::cout, program);
        return dynaqpc::kExitOk;
    }
    for (const dynaqpc::Command &c : kCommands) {
        if (args[0] == c.name) {
            try {
                return c.run(program, std::vector<std::string>(args.begin() + 1, args.end()));
            } catch (const dynaqpc::UsageError &e) {
                std::cerr << program << ' ' << c.name << ": " << e.what() << '\n';
                return dynaqpc::kExitUsage;
            } catch (const std::exception &e) {
                std::cerr << program << ' ' << c.name << ": " << e.what() << '\n';
                return dynaqpc::kExitFailure;
            }
        }
    }
    std::cerr << program << ": unknown command '" << args[0] << "' (try '" << program
              << " --help')\n";
    return dynaqpc::kExitUsage;
}
