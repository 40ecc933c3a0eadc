// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 firmware images: the entry point after the reset handler.
//
// Brings the board up (clocks, pins, reset cause) and hands over to the robot application,
// which initialises the HAL, the drivers and the agent and then runs its scheduler for ever.
// The application provides robot/robot_main.h with
//     void robot_main(const void *scenario_config);
// (NULL: the scenario built into the image, chosen by the profile's FW_CFG knobs).
#include "robot/robot_main.h"
#include "stm32f4/stm32f4_board.h"

int main(void)
{
    if (stm32f4_board_init() != 0) {
        // No crystal or no PLL lock: CAN and UART timing would be wrong. Stop here; the watchdog
        // is not running yet, so the board stays visibly dead rather than half-working.
        for (;;) {
            __asm__ volatile("wfi");
        }
    }
    robot_main((const void *)0);
    for (;;) {  // robot_main() does not return
        __asm__ volatile("wfi");
    }
}
