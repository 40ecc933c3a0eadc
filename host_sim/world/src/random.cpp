// SPDX-License-Identifier: MIT
// dynaqpc world: seeded random streams.
#include <cmath>

#include "world/random.h"
#include "fw/fw_util.h"

namespace world {

RandomStream::RandomStream(std::uint32_t seed, std::uint32_t stream)
{
    // Streams of one seed must not overlap: mix the stream number into the seed with an odd
    // multiplier (a bijection on 32 bits for a fixed stream), then let prng_seed spread it.
    prng_seed(&rng_, seed ^ (stream * 0x9E3779B9u));
}

double RandomStream::uniform()
{
    // 53 bits: two draws, so uniform() never returns 1.0 and has no visible grid.
    std::uint64_t hi = prng_next(&rng_) >> 5;  // 27 bits
    std::uint64_t lo = prng_next(&rng_) >> 6;  // 26 bits
    return static_cast<double>((hi << 26) | lo) * (1.0 / 9007199254740992.0);
}

double RandomStream::normal()
{
    if (has_spare_) {
        has_spare_ = false;
        return spare_;
    }
    // Box-Muller: u1 in (0, 1] so log(u1) is finite.
    double u1 = 1.0 - uniform();
    double u2 = uniform();
    double r = std::sqrt(-2.0 * std::log(u1));
    double t = 2.0 * FW_PI * u2;
    spare_ = r * std::sin(t);
    has_spare_ = true;
    return r * std::cos(t);
}

}  // namespace world
