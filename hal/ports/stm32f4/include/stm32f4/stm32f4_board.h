// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 port: board bring-up and the pins the port uses (MCU build only).
//
// Pins (RM0090 / datasheet alternate-function table):
//   CAN1  RX PB8, TX PB9 (AF9)  -> the CAN transceiver's RXD / TXD
//   USART2 TX PA2, RX PA3 (AF7) -> the Cricket listener's RX / TX (115200 8N1)
// The internal flash region of hal_flash is the image's linker script's (_dynaqpc_store_*):
//   STM32F405/407 (boards/robot, paper-lab):  sectors 10-11, 0x080C0000, 2 x 128 KB
//   STM32F427/429 2 MB (boards/robot-f42x, paper-sim): bank-2 sectors 20-23, 0x08180000, 4 x 128 KB
#ifndef STM32F4_BOARD_H
#define STM32F4_BOARD_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/// Clocks (168 MHz from the 8 MHz crystal), the GPIO alternate functions of CAN1 and USART2, and
/// the reset cause latched (RCC_CSR flags read and cleared). Call first in main(), before any
/// hal_* function. Returns FW_OK or FW_ERR_TIMEOUT (crystal or PLL failed: the CPU runs on the
/// 16 MHz HSI and CAN and UART timing would be wrong, so the caller should stop).
int stm32f4_board_init(void);

#ifdef __cplusplus
}
#endif

#endif // STM32F4_BOARD_H
