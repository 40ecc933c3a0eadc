// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 port: erase and program the internal flash (RM0090 3.5 and 3.6).
//
// Sequence of each operation: wait until not busy, clear stale error flags, unlock (KEY1 then
// KEY2 into KEYR), set the parallelism (x32: a 2.7-3.6 V supply) and the operation bits, start
// it, wait until not busy, check the error flags, clear the operation bits, lock again. The
// region is read back afterwards: a write into bytes that were not erased fails its verify with
// FW_ERR_IO. The data cache is reset after a change, or it could keep serving the old bytes.
//
// Sector numbers are RM0090's (tables 5 and 6); the region a port uses is checked against that
// map and the part's flash size, so an image built for a larger part reports "no region"
// instead of faulting on memory that is not there.
#include <string.h>

#include "stm32f4/stm32f4_drivers.h"

#define KB 1024u
#define BANK_BYTES (1024u * KB)
#define BANK_SECTORS 12u

int stm32f4_flash_sector(uint32_t sector, uint32_t *addr, uint32_t *size)
{
    if (sector >= STM32F4_FLASH_SECTORS_MAX) {
        return FW_ERR_INVAL;
    }
    // Within a bank: sectors 0-3 of 16 KB, 4 of 64 KB (at 64 KB), 5-11 of 128 KB (from 128 KB).
    const uint32_t bank = sector / BANK_SECTORS;
    const uint32_t s = sector % BANK_SECTORS;
    uint32_t offset;
    if (s < 4u) {
        *size = 16u * KB;
        offset = s * 16u * KB;
    } else if (s == 4u) {
        *size = 64u * KB;
        offset = 64u * KB;
    } else {
        *size = 128u * KB;
        offset = (s - 4u) * 128u * KB;
    }
    *addr = STM32F4_FLASH_MEM_BASE + bank * BANK_BYTES + offset;
    return FW_OK;
}

uint32_t stm32f4_flash_snb(uint32_t sector)
{
    return sector < BANK_SECTORS ? sector : sector + 4u;
}

int stm32f4_flash_region_check(uint32_t addr, uint32_t first_sector, uint32_t count,
                               uint32_t sector_size, uint32_t flash_kb)
{
    if (count < 2u || first_sector >= STM32F4_FLASH_SECTORS_MAX ||
        count > STM32F4_FLASH_SECTORS_MAX - first_sector) {
        return FW_ERR_NOSYS;
    }
    const uint64_t part_end = (uint64_t)STM32F4_FLASH_MEM_BASE + (uint64_t)flash_kb * KB;
    uint32_t expect = addr;
    for (uint32_t i = 0; i < count; i++) {
        uint32_t a = 0, size = 0;
        if (stm32f4_flash_sector(first_sector + i, &a, &size) != FW_OK || a != expect || size != sector_size || (uint64_t)a + size > part_end) {
            return FW_ERR_NOSYS;
        }
        expect = a + size;
    }
    return FW_OK;
}

int stm32f4_flash_geometry(const stm32f4_flash_dev_t *d, hal_flash_geometry_t *out)
{
    if (d->sector_count == 0u) {
        return FW_ERR_NOSYS;
    }
    out->sector_size = d->sector_size;
    out->sector_count = d->sector_count;
    out->write_align = 4u;
    return FW_OK;
}

int stm32f4_flash_read(const stm32f4_flash_dev_t *d, uint32_t offset, void *buf, size_t len)
{
    const uint32_t region = d->sector_count * d->sector_size;
    if (offset > region || len > region - offset || (len > 0u && buf == NULL)) {
        return FW_ERR_INVAL;
    }
    // The flash is memory-mapped; the data cache was reset after every change (end_()).
    memcpy(buf, (const void *)(uintptr_t)(d->mem + offset), len);
    return FW_OK;
}

const void *stm32f4_flash_map(const stm32f4_flash_dev_t *d, uint32_t offset, size_t len)
{
    const uint32_t region = d->sector_count * d->sector_size;
    if (d->sector_count == 0u || offset > region || len > region - offset) {
        return NULL;
    }
    return (const void *)(uintptr_t)(d->mem + offset);
}

static int wait_idle_(const stm32f4_flash_dev_t *d, uint32_t max_polls)
{
    uint32_t polls = 0;
    while (polls < max_polls) {
        const uint32_t slice =
            max_polls - polls < STM32F4_FLASH_WAIT_SLICE ? max_polls - polls : STM32F4_FLASH_WAIT_SLICE;
        if (stm32f4_wait_bits(&d->regs->SR, FLASH_SR_BSY, 0u, slice) == FW_OK) {
            return FW_OK;
        }
        polls += slice;
        if (d->on_wait != NULL) {
            d->on_wait();  // a 128 KB erase outlasts a short watchdog timeout
        }
    }
    return FW_ERR_TIMEOUT;
}

static int unlock_(stm32f4_flash_if_t *f)
{
    if (f->CR & FLASH_CR_LOCK) {
        f->KEYR = FLASH_KEY1;
        f->KEYR = FLASH_KEY2;
    }
    // A wrong sequence locks the interface until reset (and raises a bus fault): check it took.
    return stm32f4_wait_bits(&f->CR, FLASH_CR_LOCK, 0u, 1u) == FW_OK ? FW_OK : FW_ERR_IO;
}

static void reset_data_cache_(stm32f4_flash_if_t *f)
{
    const uint32_t acr = f->ACR;
    if (acr & FLASH_ACR_DCEN) {
        f->ACR = acr & ~FLASH_ACR_DCEN;
        f->ACR = (acr & ~FLASH_ACR_DCEN) | FLASH_ACR_DCRST;
        f->ACR = acr & ~FLASH_ACR_DCRST;
    }
}

// Starts one operation: waits for the flash, clears what a previous one left, unlocks, and
// selects the operation in CR (`op`: PG, or SER with the sector's SNB) at 32-bit parallelism.
// end_() locks again.
static int begin_(const stm32f4_flash_dev_t *d, uint32_t op)
{
    stm32f4_flash_if_t *f = d->regs;
    if (wait_idle_(d, STM32F4_CFG_SHORT_WAIT_POLLS) != FW_OK) {
        return FW_ERR_TIMEOUT;
    }
    const uint32_t stale = f->SR & (FLASH_SR_ERRORS | FLASH_SR_EOP);
    if (stale != 0u) {
        f->SR = stale;  // write 1 to clear what a previous operation left
    }
    if (unlock_(f) != FW_OK) {
        return FW_ERR_IO;
    }
    f->CR = (f->CR & ~(FLASH_CR_PSIZE_MASK | FLASH_CR_SNB_MASK | FLASH_CR_SER | FLASH_CR_PG)) |
            FLASH_CR_PSIZE_X32 | op;
    return FW_OK;
}

static int end_(const stm32f4_flash_dev_t *d, uint32_t max_polls)
{
    stm32f4_flash_if_t *f = d->regs;
    const int rc = wait_idle_(d, max_polls);
    const uint32_t sr = f->SR;
    f->CR &= ~(FLASH_CR_PG | FLASH_CR_SER | FLASH_CR_SNB_MASK);
    f->CR |= FLASH_CR_LOCK;
    reset_data_cache_(f);
    if (rc != FW_OK) {
        return rc;
    }
    return (sr & FLASH_SR_ERRORS) ? FW_ERR_IO : FW_OK;
}

int stm32f4_flash_erase(const stm32f4_flash_dev_t *d, uint32_t sector)
{
    if (sector >= d->sector_count) {
        return FW_ERR_INVAL;
    }
    const uint32_t snb = stm32f4_flash_snb(d->first_sector + sector) << FLASH_CR_SNB_SHIFT;
    int rc = begin_(d, FLASH_CR_SER | snb);
    if (rc != FW_OK) {
        return rc;
    }
    d->regs->CR |= FLASH_CR_STRT;
    rc = end_(d, STM32F4_CFG_ERASE_WAIT_POLLS);
    if (rc != FW_OK) {
        return rc;
    }
    const volatile uint32_t *w = (const volatile uint32_t *)(d->mem + sector * d->sector_size);
    for (uint32_t i = 0; i < d->sector_size / 4u; i++) {
        if (w[i] != 0xFFFFFFFFu) {
            return FW_ERR_IO;
        }
    }
    return FW_OK;
}

int stm32f4_flash_program(const stm32f4_flash_dev_t *d, uint32_t offset, const void *data,
                          size_t len)
{
    const uint32_t region = d->sector_count * d->sector_size;
    if ((offset & 3u) != 0u || (len & 3u) != 0u || offset > region || len > region - offset ||
        (len > 0u && data == NULL)) {
        return FW_ERR_INVAL;
    }
    if (len == 0u) {
        return FW_OK;
    }
    int rc = begin_(d, FLASH_CR_PG);
    if (rc != FW_OK) {
        return rc;
    }
    const stm32f4_flash_if_t *f = d->regs;
    const uint8_t *src = (const uint8_t *)data;
    volatile uint32_t *dst = (volatile uint32_t *)(d->mem + offset);
    for (size_t i = 0; i < len / 4u; i++) {
        const uint32_t word = (uint32_t)src[4u * i] | (uint32_t)src[4u * i + 1u] << 8 |
                              (uint32_t)src[4u * i + 2u] << 16 | (uint32_t)src[4u * i + 3u] << 24;
        dst[i] = word;  // with PG set, a word store into the region programs it
        rc = wait_idle_(d, STM32F4_CFG_SHORT_WAIT_POLLS);
        if (rc != FW_OK || (f->SR & FLASH_SR_ERRORS) != 0u) {
            break;
        }
    }
    const int end_rc = end_(d, STM32F4_CFG_SHORT_WAIT_POLLS);
    if (rc != FW_OK) {
        return rc;
    }
    if (end_rc != FW_OK) {
        return end_rc;
    }
    for (size_t i = 0; i < len; i++) {
        if (d->mem[offset + i] != src[i]) {
            return FW_ERR_IO;
        }
    }
    return FW_OK;
}
