// SPDX-License-Identifier: MIT
// dynaqpc-sim firmware-config: the MCU images' built-in scenarios, written from the scenario
// files (firmware_config.h).
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "commands.h"
#include "firmware_config.h"
#include "options.h"

namespace dynaqpc {

int cmd_firmware_config(const std::string &program, const std::vector<std::string> &args)
{
    std::string out;
    Options o("firmware-config",
              "the MCU images' built-in scenarios (paper-sim, paper-lab) as C, from their scenario files");
    o.add_string("--out", "FILE", "write FILE (firmware/robot/src/robot_scenarios.c) instead of stdout", &out);
    if (o.parse_or_usage(args, program)) {
        return kExitOk;
    }
    const std::string text = robot_scenarios_c({"paper-sim", "paper-lab"});
    if (!o.seen("--out")) {
        std::cout << text;
        return kExitOk;
    }
    std::FILE *f = std::fopen(out.c_str(), "wb");
    if (f == nullptr) throw UsageError("--out: cannot write '" + out + "': " + std::strerror(errno));
    const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    if (std::fclose(f) != 0 || !ok) throw UsageError("--out: cannot write '" + out + "'");
    return kExitOk;
}

}  // namespace dynaqpc
