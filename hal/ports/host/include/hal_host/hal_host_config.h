// SPDX-License-Identifier: MIT
// dynaqpc host port: capacities and defaults. Override any of them in your FW_CONFIG_FILE.
#ifndef HAL_HOST_CONFIG_H
#define HAL_HOST_CONFIG_H

#include "fw/fw_base.h"
#include "fw/fw_user_config.h"

/// Frames the firmware can send before the simulator drains them (hal_host_can_take_tx());
/// beyond it hal_can_send() returns FW_ERR_FULL. bxCAN has 3 mailboxes; the simulator drains
/// after every scheduler pass, so this only has to hold one pass's output.
#ifndef FW_CFG_HOST_CAN_TX_CAPACITY
#define FW_CFG_HOST_CAN_TX_CAPACITY 64
#endif

/// Standard ids the accept filter can list (bxCAN: 14 banks x 4 ids in 16-bit list mode = 56).
#ifndef FW_CFG_HOST_CAN_MAX_FILTER_IDS
#define FW_CFG_HOST_CAN_MAX_FILTER_IDS 56
#endif

/// UART receive ring (bytes). 256 holds two full Cricket lines (~110 bytes each).
#ifndef FW_CFG_HOST_UART_RX_CAPACITY
#define FW_CFG_HOST_UART_RX_CAPACITY 256
#endif

/// UART transmit buffer (bytes) the simulator drains with hal_host_uart_take_tx().
#ifndef FW_CFG_HOST_UART_TX_CAPACITY
#define FW_CFG_HOST_UART_TX_CAPACITY 256
#endif

/// Flash image capacity (bytes): the most a geometry may cover. Default: four 128 KB sectors,
/// two slots of two, because paper-sim's learned record (140 KB) is larger than one sector.
#ifndef FW_CFG_HOST_FLASH_CAPACITY
#define FW_CFG_HOST_FLASH_CAPACITY (4u * 128u * 1024u)
#endif

/// Default flash geometry (until hal_host_flash_configure()); the simulator and the firmware's
/// host build configure exactly this.
#ifndef FW_CFG_HOST_FLASH_SECTOR_SIZE
#define FW_CFG_HOST_FLASH_SECTOR_SIZE (128u * 1024u)
#endif
#ifndef FW_CFG_HOST_FLASH_SECTOR_COUNT
#define FW_CFG_HOST_FLASH_SECTOR_COUNT 4u
#endif
#ifndef FW_CFG_HOST_FLASH_WRITE_ALIGN
#define FW_CFG_HOST_FLASH_WRITE_ALIGN 4u
#endif

/// The modelled CPU clock for hal_cpu_account() in lock-step (Hz): the STM32F4's 168 MHz.
#ifndef FW_CFG_HOST_CPU_HZ
#define FW_CFG_HOST_CPU_HZ 168000000u
#endif

FW_STATIC_ASSERT(FW_CFG_HOST_CAN_TX_CAPACITY >= 1, host_can_tx_capacity);
FW_STATIC_ASSERT(FW_IS_POW2(FW_CFG_HOST_UART_RX_CAPACITY), host_uart_rx_capacity_pow2);
FW_STATIC_ASSERT(FW_CFG_HOST_UART_TX_CAPACITY >= 1, host_uart_tx_capacity);
FW_STATIC_ASSERT(FW_CFG_HOST_FLASH_SECTOR_SIZE * FW_CFG_HOST_FLASH_SECTOR_COUNT <=
                     FW_CFG_HOST_FLASH_CAPACITY,
                 host_flash_default_fits);
FW_STATIC_ASSERT(FW_CFG_HOST_FLASH_SECTOR_COUNT >= 2u, host_flash_two_sectors);
FW_STATIC_ASSERT(FW_IS_POW2(FW_CFG_HOST_FLASH_WRITE_ALIGN), host_flash_align_pow2);

#endif // HAL_HOST_CONFIG_H
