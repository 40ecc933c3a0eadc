// SPDX-License-Identifier: MIT
// dynaqpc world: the bare world driven as lock-step drives it, without the firmware: the yardstick
// of `dynaqpc-sim speed` and of the world benchmark (tests/bench/world_bench.cpp).
#ifndef WORLD_BARE_RUN_H
#define WORLD_BARE_RUN_H

#include <cstdint>

#include "world/scenario.h"

namespace world {

/// What the periods of run_bare_world() saw, summed over calls: episodes that reached the goal,
/// bumps, Cricket lines heard, and a checksum of the readings (so that none is optimised away).
struct BareRunTotals {
    long goals = 0, bumps = 0, cricket_lines = 0;
    double checksum = 0.0;
};

/// `periods` control periods of the world alone, each as a lock-step period drives it: the wheel
/// targets of a random action, the physics substeps, every ray, the gyro, the GPS or the Cricket
/// listener, bump and goal checks; an episode ends at the goal or at the scenario's step cap.
/// Adds what it saw to `*totals`; returns the wall seconds of the periods (not of the setup).
double run_bare_world(const Scenario &s, long periods, std::uint32_t seed, BareRunTotals *totals);

}  // namespace world

#endif  // WORLD_BARE_RUN_H
