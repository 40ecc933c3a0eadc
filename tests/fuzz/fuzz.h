// SPDX-License-Identifier: MIT
// dynaqpc fuzz targets: the libFuzzer entry point every target defines, and a byte reader.
//
// Each target is built twice: with clang's libFuzzer (the `fuzz` preset: campaigns and the
// bounded `ctest -L fuzz` runs) and, in every ordinary host build, with replay.c's main, which
// runs the committed corpus (tests/fuzz/corpus/<target>/, crash inputs included) through the
// same function under ctest (label fuzz-replay), so each input ever found stays a regression
// test under gcc, ASan and UBSan too.
#ifndef DYNAQPC_FUZZ_H
#define DYNAQPC_FUZZ_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/// Reads the fuzz input front to back; past its end every read gives 0.
typedef struct fuzz_in {
    const uint8_t *p;
    size_t left;
} fuzz_in_t;

static inline uint8_t fuzz_u8(fuzz_in_t *in)
{
    if (in->left == 0u) {
        return 0;
    }
    in->left--;
    return *in->p++;
}

static inline uint32_t fuzz_u16(fuzz_in_t *in)
{
    const uint32_t lo = fuzz_u8(in);
    return lo | ((uint32_t)fuzz_u8(in) << 8);
}

static inline uint32_t fuzz_u32(fuzz_in_t *in)
{
    const uint32_t lo = fuzz_u16(in);
    return lo | (fuzz_u16(in) << 16);
}

/// Up to `n` bytes in place; returns how many there were.
static inline size_t fuzz_take(fuzz_in_t *in, size_t n, const uint8_t **out)
{
    if (n > in->left) {
        n = in->left;
    }
    *out = in->p;
    in->p += n;
    in->left -= n;
    return n;
}

#ifdef __cplusplus
}
#endif

#endif // DYNAQPC_FUZZ_H
