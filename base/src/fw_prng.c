// SPDX-License-Identifier: MIT
// dynaqpc base layer: xoshiro128** seeded through splitmix32.
#include "fw/fw_prng.h"

#include "fw/fw_assert.h"

static uint32_t rotl_(uint32_t x, unsigned k)
{
    return (x << k) | (x >> (32u - k));
}

// splitmix32 spreads one 32-bit seed over the 128-bit state, so neighbouring seeds give
// unrelated streams and no seed yields the all-zero state xoshiro cannot leave.
static uint32_t splitmix32_(uint32_t *x)
{
    uint32_t z = (*x += 0x9E3779B9u);
    z = (z ^ (z >> 16)) * 0x85EBCA6Bu;
    z = (z ^ (z >> 13)) * 0xC2B2AE35u;
    return z ^ (z >> 16);
}

void prng_seed(prng_t *rng, uint32_t seed)
{
    uint32_t x = seed;
    for (unsigned i = 0; i < 4; i++) {
        rng->s[i] = splitmix32_(&x);
    }
    if ((rng->s[0] | rng->s[1] | rng->s[2] | rng->s[3]) == 0u) {
        rng->s[0] = 1u;
    }
}

uint32_t prng_next(prng_t *rng)
{
    uint32_t *s = rng->s;
    const uint32_t result = rotl_(s[1] * 5u, 7) * 9u;
    const uint32_t t = s[1] << 9;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl_(s[3], 11);
    return result;
}

uint32_t prng_below(prng_t *rng, uint32_t n)
{
    FW_ASSERT(n > 0u);
    // Lemire: the high word of x * n is uniform in [0, n) once the few low products that would
    // over-represent some values are rejected.
    uint64_t m = (uint64_t)prng_next(rng) * n;
    uint32_t low = (uint32_t)m;
    if (low < n) {
        const uint32_t threshold = (0u - n) % n;
        while (low < threshold) {
            m = (uint64_t)prng_next(rng) * n;
            low = (uint32_t)m;
        }
    }
    return (uint32_t)(m >> 32);
}

float prng_unit(prng_t *rng)
{
    return (float)(prng_next(rng) >> 8) * (1.0f / 16777216.0f);
}
