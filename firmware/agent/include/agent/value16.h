// SPDX-License-Identifier: MIT
// dynaqpc: 16-bit floating-point values for tables that hold many: converted in C99, rounded to
// nearest even.
#ifndef AGENT_VALUE16_H
#define AGENT_VALUE16_H

#include <stdint.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

/// A value16's bits: 1 sign, 6 exponent (bias 31), 9 fraction bits — the layout of IBM's
/// DLFloat16, not IEEE's binary16. 10 significant bits (a relative step of 2^-10, 0.1 %) over
/// normal values from 2^-30 (9.3e-10) to 4.3e9, subnormal down to 2^-39. IEEE half's 5-bit
/// exponent (normal from 6.1e-5) loses a gridworld's values: 0.95^240 = 4.5e-6 at the far end of
/// the 240-step corridor (tests/integration/maze_learning) keeps 7 bits there and the sweep
/// stops finding the path; one bit of precision buys the whole range a float's values take here.
/// Exponent 63 is not a value (as IEEE's infinities and NaNs): a restored table holding it is
/// corrupt.
typedef uint16_t value16_t;

/// The largest value16: 2^31 * (2 - 2^-9).
#define VALUE16_MAX 4290772992.0f

/// Whether bits v are a value (exponent below 63).
static inline int value16_ok(value16_t v)
{
    return (v & 0x7e00u) != 0x7e00u;
}

/// The value16 nearest to f (ties to even); beyond +-VALUE16_MAX it saturates there. f must
/// not be NaN.
///
/// Integer arithmetic for normal results and one float addition for subnormal ones, both exact
/// in IEEE single precision: the same bits on the host and on the Cortex-M4 (no FMA involved).
static inline value16_t value16_from_float(float f)
{
    if (f > VALUE16_MAX) {
        f = VALUE16_MAX;
    } else if (f < -VALUE16_MAX) {
        f = -VALUE16_MAX;
    }
    uint32_t x;
    memcpy(&x, &f, sizeof x);
    const uint32_t sign = x & 0x80000000u;
    x ^= sign;
    uint32_t v;
    if (x < 0x30800000u) {  // |f| < 2^-30: a subnormal value16 (or zero)
        // Adding 2^-16, whose float step is 2^-39 (the value16 subnormal step), rounds |f| to a
        // multiple of that step (to nearest even, by the FPU) in the float's low bits.
        float t;
        memcpy(&t, &x, sizeof t);
        t += 0x1p-16f;
        memcpy(&v, &t, sizeof v);
        v -= 0x37800000u;
    } else {
        const uint32_t odd = (x >> 14) & 1u;  // ties go to the even neighbour
        x += 0xd0001fffu + odd;               // rebias the exponent (-96 << 23), round half up
        v = x >> 14;
    }
    return (value16_t)(v | (sign >> 16));
}

/// The float a value16 stands for (exactly: every value16 is a float). Not for exponent 63.
static inline float value16_to_float(value16_t v)
{
    const uint32_t exponent = (v >> 9) & 0x3fu;
    const uint32_t fraction = v & 0x1ffu;
    float f;
    if (exponent == 0u) {
        // Subnormal (or zero): fraction * 2^-39, exact, and a normal float (never a subnormal
        // one, which an FPU flushing to zero would read as 0).
        f = (float)fraction * 0x1p-39f;
    } else {
        const uint32_t x = ((exponent + 96u) << 23) | (fraction << 14);  // rebias 31 -> 127
        memcpy(&f, &x, sizeof f);
    }
    return (v & 0x8000u) != 0u ? -f : f;
}

#ifdef __cplusplus
}
#endif

#endif // AGENT_VALUE16_H
