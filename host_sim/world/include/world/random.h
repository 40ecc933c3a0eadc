// SPDX-License-Identifier: MIT
// dynaqpc world: one seeded random stream (the firmware's PRNG) with Gaussian draws.
#ifndef WORLD_RANDOM_H
#define WORLD_RANDOM_H

#include <cstdint>

#include "fw/fw_prng.h"

namespace world {

/// A stream of uniform and normal draws from the firmware's xoshiro128** (fw/fw_prng.h).
/// Normal draws use Box-Muller (ours, not std::normal_distribution, whose algorithm differs
/// between standard libraries): deterministic for a seed on a given binary and libm.
class RandomStream {
public:
    /// `stream` separates independent streams of one seed (start poses, range noise, ...).
    explicit RandomStream(std::uint32_t seed = 0, std::uint32_t stream = 0);

    /// Uniform in [0, 1).
    double uniform();
    /// Uniform in [lo, hi).
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    /// Standard normal N(0, 1).
    double normal();

private:
    prng_t rng_;
    bool has_spare_ = false;
    double spare_ = 0.0;
};

}  // namespace world

#endif  // WORLD_RANDOM_H
