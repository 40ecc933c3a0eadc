// SPDX-License-Identifier: MIT
// Compiled with FW_CFG_ASSERT=0 (tests/unit/base/CMakeLists.txt): FW_ASSERT is compiled out.
#include "fw/fw_assert.h"

#if FW_CFG_ASSERT
#error "this file must be compiled with FW_CFG_ASSERT=0"
#endif

void assert_off_check(int *counter);

void assert_off_check(int *counter)
{
    FW_ASSERT(++*counter == 0);
    (void)counter;
}
