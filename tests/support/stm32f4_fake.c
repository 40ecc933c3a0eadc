// SPDX-License-Identifier: MIT
// dynaqpc tests: the STM32F4 fake peripherals (stm32f4_fake.h).
#include "stm32f4_fake.h"

#include <stddef.h>
#include <string.h>

static stm32f4_fake_flash_t *flash_;
static stm32f4_can_t *can_;

static void flash_hw_(void)
{
    stm32f4_fake_flash_t *f = flash_;
    stm32f4_flash_if_t *r = &f->regs;
    if ((r->CR & FLASH_CR_LOCK) && r->KEYR == FLASH_KEY2 && !f->never_unlock) {
        r->CR &= ~FLASH_CR_LOCK;
    }
    if (r->CR & FLASH_CR_STRT) {
        r->CR &= ~FLASH_CR_STRT;
        f->last_snb = (r->CR & FLASH_CR_SNB_MASK) >> FLASH_CR_SNB_SHIFT;
        f->last_psize = r->CR & FLASH_CR_PSIZE_MASK;
        f->erased_snbs |= 1u << f->last_snb;
        // RM0090: SNB 0-11 are sectors 0-11, 16-27 are bank 2's sectors 12-23 (12-15 invalid).
        const uint32_t sector = f->last_snb >= 16u ? f->last_snb - 4u : f->last_snb;
        const uint32_t s = sector - f->first_sector;
        if (f->last_snb >= 12u && f->last_snb < 16u) {
            r->SR |= FLASH_SR_PGSERR;  // not a sector: the hardware refuses
        } else if (s < f->mem_sectors && !f->error_on_start) {
            memset(&f->mem[s * f->sector_size], 0xFF, f->sector_size);
        }
        r->SR |= FLASH_SR_BSY | f->error_on_start;
        return;
    }
    if (r->SR & FLASH_SR_BSY) {
        if (f->busy_polls > 0u) {
            f->busy_polls--;
        } else {
            r->SR &= ~FLASH_SR_BSY;
        }
    }
}

void stm32f4_fake_flash_reset(stm32f4_fake_flash_t *f, uint8_t *mem, uint32_t mem_sectors,
                              uint32_t sector_size, uint32_t first_sector)
{
    memset(f, 0, sizeof *f);
    f->regs.CR = FLASH_CR_LOCK;  // reset value
    f->regs.ACR = FLASH_ACR_DCEN | FLASH_ACR_ICEN | 5u;
    f->mem = mem;
    f->mem_sectors = mem_sectors;
    f->sector_size = sector_size;
    f->first_sector = first_sector;
    flash_ = f;
    stm32f4_poll_hook = flash_hw_;
}

void stm32f4_fake_can_reset(stm32f4_can_t *can)
{
    memset(can, 0, sizeof *can);
    can->MCR = CAN_MCR_SLEEP;  // reset values (RM0090 32.9.2)
    can->MSR = CAN_MSR_SLAK;
    can->TSR = CAN_TSR_TME0 | CAN_TSR_TME0 << 1 | CAN_TSR_TME0 << 2;
}

void stm32f4_fake_can_ack(stm32f4_can_t *can)
{
    if (can->MCR & CAN_MCR_INRQ) {
        can->MSR |= CAN_MSR_INAK;
    } else {
        can->MSR &= ~CAN_MSR_INAK;
    }
    if (!(can->MCR & CAN_MCR_SLEEP)) {
        can->MSR &= ~CAN_MSR_SLAK;
    }
}

static void can_hw_(void)
{
    stm32f4_fake_can_ack(can_);
}

void stm32f4_fake_can_install(stm32f4_can_t *can)
{
    stm32f4_fake_can_reset(can);
    can_ = can;
    stm32f4_poll_hook = can_hw_;
}

int stm32f4_fake_teardown(void **state)
{
    (void)state;
    stm32f4_poll_hook = NULL;
    return 0;
}
