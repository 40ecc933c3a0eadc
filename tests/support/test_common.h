// SPDX-License-Identifier: MIT
// dynaqpc tests: the includes every cmocka test needs, in the order cmocka needs them.
#ifndef TEST_COMMON_H
#define TEST_COMMON_H

// clang-format off
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
// clang-format on

#endif // TEST_COMMON_H
