// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 port: capacities and board choices, each overridable from FW_CONFIG_FILE.
#ifndef STM32F4_CONFIG_H
#define STM32F4_CONFIG_H

#include "fw/fw_base.h"
#include "fw/fw_user_config.h"

/// HSE crystal frequency; the clock tree (stm32f4_clock_init) assumes 8 MHz.
#ifndef STM32F4_CFG_HSE_HZ
#define STM32F4_CFG_HSE_HZ 8000000u
#endif
#define STM32F4_SYSCLK_HZ 168000000u
#define STM32F4_APB1_HZ 42000000u
#define STM32F4_APB2_HZ 84000000u

/// CAN1's share of the filter banks (CAN2 starts at bank 14 after reset).
#ifndef STM32F4_CFG_CAN1_FILTER_BANKS
#define STM32F4_CFG_CAN1_FILTER_BANKS 14u
#endif
/// Cricket listener UART receive and transmit rings (bytes, powers of two). At 115200 baud a
/// byte arrives every 87 µs: 512 bytes cover 44 ms of the scheduler not draining.
#ifndef STM32F4_CFG_UART_RX_BYTES
#define STM32F4_CFG_UART_RX_BYTES 512u
#endif
#ifndef STM32F4_CFG_UART_TX_BYTES
#define STM32F4_CFG_UART_TX_BYTES 128u
#endif
/// 1: hal_uart_write() writes DR directly, each byte after at most STM32F4_CFG_UART_TX_POLLS
/// reads of TXE, with no transmit ring (a USART whose TXE never interrupts: QEMU's); 0: a ring
/// fed by the TXE interrupt.
#ifndef STM32F4_CFG_UART_TX_POLLED
#define STM32F4_CFG_UART_TX_POLLED 0
#endif
/// Polls of TXE before a polled byte is given up (QEMU sets it at once; a real USART at 115200
/// baud would need ~87 us a byte).
#ifndef STM32F4_CFG_UART_TX_POLLS
#define STM32F4_CFG_UART_TX_POLLS 1000u
#endif
/// Polls of a flag before a short wait (peripheral mode changes, clock ready) gives up.
#ifndef STM32F4_CFG_SHORT_WAIT_POLLS
#define STM32F4_CFG_SHORT_WAIT_POLLS 1000000u
#endif
/// Polls before a flash sector erase gives up (a 128 KB erase takes up to 4 s; a poll is at least
/// a few core cycles at 168 MHz, so this allows well over 4 s).
#ifndef STM32F4_CFG_ERASE_WAIT_POLLS
#define STM32F4_CFG_ERASE_WAIT_POLLS 400000000u
#endif
/// Polls of RF0R.RFOM0 after releasing a CAN receive FIFO slot before the interrupt handler
/// stops draining (the release takes a few peripheral clocks; until it is done FMP0 and the
/// output mailbox still show the frame just read). The interrupt stays pending while frames wait,
/// so stopping early loses nothing.
#ifndef STM32F4_CFG_CAN_RELEASE_POLLS
#define STM32F4_CFG_CAN_RELEASE_POLLS 64u
#endif
/// Interrupt priorities (0 highest, 15 lowest; 4 bits on the STM32F4).
#ifndef STM32F4_CFG_IRQ_PRIO_CAN
#define STM32F4_CFG_IRQ_PRIO_CAN 5u
#endif
#ifndef STM32F4_CFG_IRQ_PRIO_UART
#define STM32F4_CFG_IRQ_PRIO_UART 6u
#endif
#ifndef STM32F4_CFG_IRQ_PRIO_SYSTICK
#define STM32F4_CFG_IRQ_PRIO_SYSTICK 4u
#endif

FW_STATIC_ASSERT(FW_IS_POW2(STM32F4_CFG_UART_RX_BYTES) && FW_IS_POW2(STM32F4_CFG_UART_TX_BYTES),
                 stm32f4_uart_rings_pow2);
FW_STATIC_ASSERT(STM32F4_CFG_CAN1_FILTER_BANKS >= 1u && STM32F4_CFG_CAN1_FILTER_BANKS <= 27u,
                 stm32f4_can1_filter_banks);
FW_STATIC_ASSERT(STM32F4_CFG_CAN_RELEASE_POLLS >= 1u, stm32f4_can_release_polls);
FW_STATIC_ASSERT(STM32F4_CFG_HSE_HZ == 8000000u, stm32f4_clock_tree_assumes_8mhz_hse);

#endif // STM32F4_CONFIG_H
