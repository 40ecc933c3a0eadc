// SPDX-License-Identifier: MIT
// dynaqpc base layer: the small numeric helpers every layer shares (one definition each).
#ifndef FW_UTIL_H
#define FW_UTIL_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/// π as a double constant expression; FW_PI_F is the float nearest to it.
#define FW_PI 3.14159265358979323846
#define FW_PI_F 3.14159265358979323846f

/// Fibonacci hashing's multiplier: the prime nearest 2^32 / φ. The product's top bits depend on
/// every bit of the key, so packed keys (state * actions + action, fields in high bits) spread.
#define FW_FIB_HASH_MUL 0x9E3779B1u

/// key * FW_FIB_HASH_MUL mod 2^32: take the top bits (>> (32 - bits), or a 32x32->64 multiply by
/// the slot count) for a table index; the low bits depend only on the key's low bits.
static inline uint32_t fw_fib_mix(uint32_t key)
{
    return key * FW_FIB_HASH_MUL;
}

/// The index of a table of 2^bits slots (1 <= bits <= 31) that `key` hashes to.
static inline uint32_t fw_fib_hash(uint32_t key, unsigned bits)
{
    return fw_fib_mix(key) >> (32u - bits);
}

/// The smallest n with 2^n >= x (0 for x <= 1): log2(x) exactly when x is a power of two.
static inline uint32_t fw_log2_ceil(uint32_t x)
{
    uint32_t n = 0;
    while (n < 32u && (1ull << n) < x) {
        n++;
    }
    return n;
}

/// v limited to [lo, hi] (lo <= hi).
static inline int32_t fw_clamp_i32(int32_t v, int32_t lo, int32_t hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}

/// v limited to [lo, hi] (lo <= hi); a NaN stays NaN.
static inline float fw_clamp_f(float v, float lo, float hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}

/// v limited to UINT32_MAX.
static inline uint32_t fw_sat_u32(uint64_t v)
{
    return v > UINT32_MAX ? UINT32_MAX : (uint32_t)v;
}

/// The value of the hex digit c ('0'-'9', 'a'-'f', 'A'-'F'), or -1 for any other character.
static inline int fw_hex_digit(int c)
{
    if (c >= '0' && c <= '9') {
        return c - '0';
    }
    if (c >= 'a' && c <= 'f') {
        return c - 'a' + 10;
    }
    if (c >= 'A' && c <= 'F') {
        return c - 'A' + 10;
    }
    return -1;
}

#ifdef __cplusplus
}
#endif

#endif // FW_UTIL_H
