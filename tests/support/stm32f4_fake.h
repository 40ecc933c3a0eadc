// SPDX-License-Identifier: MIT
// dynaqpc tests: the STM32F4 port's peripherals as RAM register blocks that answer like the
// hardware, one definition for every test that compiles the port's drivers for the host.
//
// The drivers poll flags through stm32f4_wait_bits(), which calls stm32f4_poll_hook on every
// poll; a fake installs its hook there and plays the hardware (RM0090 section numbers beside
// each rule). stm32f4_fake_teardown() is the cmocka teardown that removes it.
#ifndef STM32F4_FAKE_H
#define STM32F4_FAKE_H

#include <stdbool.h>
#include <stdint.h>

#include "stm32f4/stm32f4_drivers.h"

// ---- Flash interface (RM0090 3.9): key-sequence unlock, sector erase, BSY, error flags --------

typedef struct stm32f4_fake_flash {
    stm32f4_flash_if_t regs;
    uint8_t *mem;            ///< the region's bytes: mem_sectors sectors of sector_size
    uint32_t mem_sectors;
    uint32_t sector_size;
    uint32_t first_sector;   ///< the RM0090 sector number of mem[0]
    // What the fake saw.
    uint32_t last_snb;       ///< SNB of the last erase started (RM0090's code: bank 2 from 16)
    uint32_t last_psize;     ///< the PSIZE bits of that erase
    uint32_t erased_snbs;    ///< bit n: an erase of SNB n was started
    // How it misbehaves, set by a test.
    uint32_t busy_polls;     ///< polls BSY stays set after a start (0: clears on the next poll)
    uint32_t error_on_start; ///< SR error bits an operation raises (the erase then does nothing)
    bool never_unlock;       ///< a wrong key sequence locked the interface until reset
} stm32f4_fake_flash_t;

/// Registers at their reset values (CR.LOCK; ACR with the caches on and 5 wait states), the
/// counters and misbehaviours cleared, `mem` left as it is; installs the flash's poll hook.
void stm32f4_fake_flash_reset(stm32f4_fake_flash_t *f, uint8_t *mem, uint32_t mem_sectors,
                              uint32_t sector_size, uint32_t first_sector);

// ---- bxCAN (RM0090 32.9): reset values, INAK following INRQ ----------------------------------

/// Registers at their reset values: sleep mode (MCR.SLEEP, MSR.SLAK), three empty TX mailboxes.
void stm32f4_fake_can_reset(stm32f4_can_t *can);

/// One poll of the controller's mode handshake: MSR.INAK follows MCR.INRQ, SLAK clears when
/// SLEEP is cleared. Tests whose own hook models more (a receive FIFO) call it from there.
void stm32f4_fake_can_ack(stm32f4_can_t *can);

/// stm32f4_fake_can_reset() and a poll hook running stm32f4_fake_can_ack() on `can`.
void stm32f4_fake_can_install(stm32f4_can_t *can);

/// cmocka teardown: removes whichever fake's poll hook is installed.
int stm32f4_fake_teardown(void **state);

#endif // STM32F4_FAKE_H
