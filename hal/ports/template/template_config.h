// SPDX-License-Identifier: MIT
// dynaqpc HAL port template: the port's capacities and board choices. Each is a default a
// build's FW_CONFIG_FILE may override (fw/fw_user_config.h brings it in first).
#ifndef TEMPLATE_CONFIG_H
#define TEMPLATE_CONFIG_H

#include "fw/fw_base.h"
#include "fw/fw_user_config.h"

/// Example: the UART receive ring in bytes (a power of two, checked below).
#ifndef TEMPLATE_CFG_UART_RX_BYTES
#define TEMPLATE_CFG_UART_RX_BYTES 256u
#endif

FW_STATIC_ASSERT(FW_IS_POW2(TEMPLATE_CFG_UART_RX_BYTES), template_uart_rx_pow2);

#endif // TEMPLATE_CONFIG_H
