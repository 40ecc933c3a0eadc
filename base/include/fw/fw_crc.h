// SPDX-License-Identifier: MIT
// dynaqpc base layer: the CRCs, chainable: crc = f(crc, data, len), starting from 0.
#ifndef FW_CRC_H
#define FW_CRC_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/// CRC-32 (IEEE 802.3, reflected, as zlib's crc32()): fw_crc32(0, "123456789", 9) is 0xCBF43926.
/// Four bytes a step (slicing by 4): tables of 4 KB of flash, about four times nibble-wise.
uint32_t fw_crc32(uint32_t crc, const void *data, uint32_t len);

/// CRC-8/SAE-J1850 (polynomial 0x1D, init 0xFF, final xor 0xFF, not reflected): fw_crc8(0,
/// "123456789", 9) is 0x4B. A byte a step (a 256-byte table in flash).
uint8_t fw_crc8(uint8_t crc, const void *data, uint32_t len);

#ifdef __cplusplus
}
#endif

#endif // FW_CRC_H
