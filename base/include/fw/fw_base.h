// SPDX-License-Identifier: MIT
// dynaqpc base layer: error codes and compile-time checks shared by every layer (runtime
// assertions: fw/fw_assert.h, included here).
#ifndef FW_BASE_H
#define FW_BASE_H

#include "fw/fw_assert.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Error codes. 0 is success; failures are negative so that functions returning counts can
/// return a count or an error in one signed value.
typedef enum fw_err {
    FW_OK = 0,
    FW_ERR_INVAL = -1,   ///< a parameter or configuration is out of its documented range
    FW_ERR_NOMEM = -2,   ///< a fixed-capacity table cannot take another entry
    FW_ERR_FULL = -3,    ///< a queue is full
    FW_ERR_NOENT = -4,   ///< the thing asked for does not exist (yet)
    FW_ERR_TIMEOUT = -5, ///< a deadline passed
    FW_ERR_IO = -6,      ///< a peripheral or medium failed
    FW_ERR_NOSYS = -7,   ///< the port does not implement this
    FW_ERR_CORRUPT = -8, ///< stored data failed its check
} fw_err_t;

/// Compile-time assertion that works under `-std=c99 -pedantic` on every compiler we use
/// (`_Static_assert` is C11 and arm-none-eabi-gcc rejects it under -pedantic -std=c99).
/// A false condition declares an array of negative size, which is a hard error.
#define FW_STATIC_ASSERT(cond, msg) typedef char fw_static_assert_##msg[(cond) ? 1 : -1]

/// True when x is a power of two (and non-zero).
#define FW_IS_POW2(x) ((x) != 0u && (((x) & ((x)-1u)) == 0u))

/// FW_CHECK_RETURN on a declaration: ignoring the result is a compile error (-Werror), even cast
/// to (void); on the boot calls whose failure must be handled (hal_*_init, sched_init,
/// sched_add_task). FW_UNUSED on a variable only an FW_ASSERT reads (compiled out with it).
#if defined(__GNUC__)
#define FW_CHECK_RETURN __attribute__((warn_unused_result))
#define FW_UNUSED __attribute__((unused))
#else
#define FW_CHECK_RETURN
#define FW_UNUSED
#endif

#ifdef __cplusplus
}
#endif

#endif // FW_BASE_H
