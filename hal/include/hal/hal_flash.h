// SPDX-License-Identifier: MIT
// dynaqpc HAL: the flash region that keeps what the robot learned across reboots.
//
// NOR semantics, as on the MCU: erasing a sector sets its bytes to 0xFF; programming can only
// clear bits (1 -> 0); a byte is programmed once between erases. The region is a few equal
// sectors the image's linker script reserves (STM32F405: sectors 10-11; F427/429 with 2 MB: bank-2
// sectors 20-23, docs/flashing.md); offsets are from
// the region's start. The firmware's persistence layer (firmware/robot) keeps two slots with a
// CRC and a sequence number, so a power cut during a save never loses the last good copy.
#ifndef HAL_FLASH_H
#define HAL_FLASH_H

#include <stddef.h>
#include <stdint.h>

#include "fw/fw_base.h"  // FW_OK and the FW_ERR_* codes the functions return

#ifdef __cplusplus
extern "C" {
#endif

typedef struct hal_flash_geometry {
    uint32_t sector_size;   ///< bytes per erasable sector
    uint32_t sector_count;  ///< sectors in the region (at least 2)
    uint32_t write_align;   ///< hal_flash_write offsets and lengths are multiples of this
} hal_flash_geometry_t;

/// The region's shape. Returns FW_OK, or FW_ERR_NOSYS if the port has no flash region.
/// Context: thread.
int hal_flash_get_geometry(hal_flash_geometry_t *out);

/// Reads `len` bytes at `offset`. Returns FW_OK or FW_ERR_INVAL (out of the region).
/// Context: thread. Never blocks.
int hal_flash_read(uint32_t offset, void *buf, size_t len);

/// The region's bytes in place: internal flash is memory-mapped (on the host, the port's image).
/// Returns a read-only pointer to `len` bytes at `offset`, or NULL (out of the region, or no
/// region). The pointer stays valid, and the bytes as they are, until the next erase or write.
/// The persistence layer checks a record where it lies, before it copies anything (a copy made
/// through a buffer could fail half way). Context: thread. Never blocks.
const void *hal_flash_map(uint32_t offset, size_t len);

/// Erases one sector (every byte becomes 0xFF). Blocks until done: on the STM32F4 a 128 KB
/// sector takes 1–2 s and, in the bank the code runs from (the F405's only bank), stalls
/// instruction fetch, so the firmware erases only when
/// the robot is stopped (at an episode's end). Returns FW_OK, FW_ERR_INVAL or FW_ERR_IO.
/// Context: thread.
int hal_flash_erase(uint32_t sector);

/// Programs `len` bytes at `offset` (both multiples of write_align) into erased flash.
/// Returns FW_OK, FW_ERR_INVAL (alignment, range), or FW_ERR_IO (verify failed, e.g. the bytes
/// were not erased). Context: thread. Blocks for the programming time (~16 µs per word on F4).
int hal_flash_write(uint32_t offset, const void *data, size_t len);

#ifdef __cplusplus
}
#endif

#endif // HAL_FLASH_H
