// SPDX-License-Identifier: MIT
// dynaqpc base layer: the seeded pseudo-random number generator every random choice goes through.
#ifndef FW_PRNG_H
#define FW_PRNG_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/// xoshiro128** (Blackman & Vigna): 32-bit operations only, 128 bits of state, period 2^128 - 1.
/// Bit-identical on the host and on a Cortex-M4: no floating point in the generator itself.
typedef struct prng {
    uint32_t s[4];
} prng_t;

/// Seeds the generator. Every seed, 0 included, gives a valid, distinct stream.
void prng_seed(prng_t *rng, uint32_t seed);

/// The next 32 uniformly distributed bits.
uint32_t prng_next(prng_t *rng);

/// A uniform integer in [0, n). n must be > 0. Unbiased (Lemire's multiply-and-reject).
uint32_t prng_below(prng_t *rng, uint32_t n);

/// A uniform float in [0, 1) with 24 bits of resolution.
float prng_unit(prng_t *rng);

#ifdef __cplusplus
}
#endif

#endif // FW_PRNG_H
