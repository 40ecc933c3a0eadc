// SPDX-License-Identifier: MIT
// Fuzz target: a scenario file (dynaqpc-sim --scenario), parsed; an accepted one must build a
// world and place the robot at a start.
#include <string>
#include <string_view>

#include "fuzz.h"
#include "world/scenario.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    world::Scenario sc;
    std::string error;
    const std::string_view text(reinterpret_cast<const char *>(data), size);
    if (!world::parse_scenario(text, "fuzz.scn", &sc, &error)) {
        if (error.empty() || error.find('\n') != std::string::npos) {
            __builtin_trap();  // a refusal is one line that says why
        }
        return 0;
    }
    return 0;
}
