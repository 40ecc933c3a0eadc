// SPDX-License-Identifier: MIT
// dynaqpc base layer: the one handler every FW_ASSERT goes to (see fw_assert.h).
#include "fw/fw_assert.h"

#include <stddef.h>

#if defined(FW_ASSERT_HOSTED)
#include <stdio.h>
#include <stdlib.h>
#endif

static fw_assert_handler_t handler_;

fw_assert_handler_t fw_assert_set_handler(fw_assert_handler_t handler)
{
    const fw_assert_handler_t old = handler_;
    handler_ = handler;
    return old;
}

void fw_assert_failed(const char *file, int line)
{
    if (handler_ != NULL) {
        handler_(file, line);
    }
#if defined(FW_ASSERT_HOSTED)
    // Hosted builds (set by base/CMakeLists.txt when not cross-compiling): say where, and stop
    // the way a test runner and a debugger both notice.
    (void)fprintf(stderr, "%s:%d: assertion failed\n", file, line);
    abort();
#else
    // On the MCU there is nowhere to print: stop here, and let the watchdog reset the board.
    for (;;) {
    }
#endif
}
