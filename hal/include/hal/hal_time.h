// SPDX-License-Identifier: MIT
// dynaqpc HAL: time. Implemented by each port (hal/ports/<port>/).
//
// One clock for the whole firmware: microseconds since boot, 64 bits so that it never wraps in
// the robot's lifetime. On the MCU it is SysTick plus a sub-tick counter; on the host it is the
// simulator's virtual time in lock-step, or the monotonic clock (optionally sped up) otherwise.
#ifndef HAL_TIME_H
#define HAL_TIME_H

#include <stdint.h>

#include "fw/fw_base.h"  // FW_OK and the FW_ERR_* codes the functions return

#ifdef __cplusplus
extern "C" {
#endif

/// Microseconds since hal_time_init(). Never goes backwards.
/// Context: any, including interrupt handlers. Never blocks.
uint64_t hal_time_us(void);

/// Starts the clock at 0. Called once at boot, before interrupts are enabled.
/// Returns FW_OK, or FW_ERR_IO if the timer cannot be started.
FW_CHECK_RETURN int hal_time_init(void);

#ifdef __cplusplus
}
#endif

#endif // HAL_TIME_H
