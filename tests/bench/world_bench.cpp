// SPDX-License-Identifier: MIT
// dynaqpc-world-bench: speed of the simulated world, in control periods per second.
//
// One control period = what the lock-step runner does per period: wheel targets for a random
// action, timing.substeps physics steps, one range reading of every ray, gyro, GPS (paper-sim) or
// the Cricket listener (paper-lab), bump and goal checks; a new random start on reaching the goal
// or after the scenario's step cap. Prints, per scenario, the median of 5 runs:
//   scenario=<name> control_periods_per_s=<n> physics_steps_per_s=<n> rays_per_period=<n>
// Usage: dynaqpc-world-bench [--periods N] [--seed S] [scenario...]   (default: paper-sim paper-lab)
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "world/bare_run.h"
#include "world/scenario.h"

namespace {

// Control periods per wall second of one run (world::run_bare_world, as `dynaqpc-sim speed`).
double run_once(const world::Scenario &s, long periods, std::uint32_t seed, world::BareRunTotals *t)
{
    return static_cast<double>(periods) / world::run_bare_world(s, periods, seed, t);
}

}  // namespace

int main(int argc, char **argv)
{
    long periods = 100000;
    std::uint32_t seed = 1;
    std::vector<std::string> names;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--periods") == 0 && i + 1 < argc) {
            periods = std::strtol(argv[++i], nullptr, 10);
        } else if (std::strcmp(argv[i], "--seed") == 0 && i + 1 < argc) {
            seed = static_cast<std::uint32_t>(std::strtoul(argv[++i], nullptr, 10));
        } else if (argv[i][0] == '-') {
            std::fprintf(stderr, "usage: %s [--periods N] [--seed S] [scenario...]\n", argv[0]);
            return 2;
        } else {
            names.emplace_back(argv[i]);
        }
    }
    if (periods < 1) periods = 1;
    if (names.empty()) names = {"paper-sim", "paper-lab"};
    for (const std::string &name : names) {
        world::Scenario s;
        std::string err;
        if (!world::load_scenario(name, &s, &err)) {
            std::fprintf(stderr, "%s\n", err.c_str());
            return 1;
        }
        std::vector<double> rates;
        world::BareRunTotals t;
        for (int r = 0; r < 5; ++r) rates.push_back(run_once(s, periods, seed, &t));
        std::sort(rates.begin(), rates.end());
        const double median = rates[2];
        std::printf("scenario=%s control_periods_per_s=%.0f physics_steps_per_s=%.0f "
                    "rays_per_period=%zu periods_per_run=%ld goals=%ld bumps=%ld "
                    "cricket_lines=%ld checksum=%.6g\n",
                    s.name.c_str(), median, median * s.timing.substeps, s.ranger.rays.size(),
                    periods, t.goals / 5, t.bumps / 5, t.cricket_lines / 5, t.checksum / 5);
    }
    return 0;
}
