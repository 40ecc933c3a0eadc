// SPDX-License-Identifier: MIT
// dynaqpc base layer: the one place a build's own configuration file comes in.
//
// Build with -DFW_CONFIG_FILE="my_config.h" to override any FW_CFG_*, HAL_*_CFG_* or port
// STM32F4_CFG_* default: every *_config.h of every layer includes this header before its
// defaults, so one file configures them all and no layer needs another layer's config header.
#ifndef FW_USER_CONFIG_H
#define FW_USER_CONFIG_H

#ifdef FW_CONFIG_FILE
#include FW_CONFIG_FILE
#endif

#endif // FW_USER_CONFIG_H
