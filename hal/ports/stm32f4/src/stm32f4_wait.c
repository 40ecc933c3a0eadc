// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 port: bounded polling of a hardware flag.
//
// A peripheral that never raises its flag (a missing crystal, a CAN transceiver without power,
// a locked flash) must not hang the robot: every wait has a poll limit and its caller reports
// FW_ERR_TIMEOUT or FW_ERR_IO instead.
#include "stm32f4/stm32f4_drivers.h"

void (*stm32f4_poll_hook)(void) = NULL;

int stm32f4_wait_bits(const volatile uint32_t *reg, uint32_t mask, uint32_t want,
                      uint32_t max_polls)
{
    for (uint32_t i = 0; i < max_polls; i++) {
        if (stm32f4_poll_hook != NULL) {
            stm32f4_poll_hook();
        }
        if ((*reg & mask) == want) {
            return FW_OK;
        }
    }
    return FW_ERR_TIMEOUT;
}
