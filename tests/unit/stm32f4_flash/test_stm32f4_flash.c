// SPDX-License-Identifier: MIT
// Tests of the STM32F4 flash driver (hal/ports/stm32f4/src/stm32f4_flash.c) against a fake flash
// interface: a RAM register block plus a small "flash" array, with a poll hook that plays the
// hardware (unlock on the key sequence, NOR erase, busy and error flags driven by the test).
#include "test_common.h"

#include <string.h>

#include "fw/fw_base.h"
#include "stm32f4/stm32f4_drivers.h"
#include "stm32f4_fake.h"

#define SECTOR 256u

#define MEM_SECTORS 4u
static uint8_t mem_[MEM_SECTORS * SECTOR];
static stm32f4_fake_flash_t fake_;
static stm32f4_flash_dev_t dev_;
static uint32_t waits_;

static void on_wait_(void)
{
    waits_++;
}

static int setup_(void **state)
{
    (void)state;
    memset(mem_, 0x5A, sizeof mem_);
    stm32f4_fake_flash_reset(&fake_, mem_, MEM_SECTORS, SECTOR, 10);
    dev_.regs = &fake_.regs;
    dev_.mem = mem_;
    dev_.first_sector = 10;
    dev_.sector_count = 2;
    dev_.sector_size = SECTOR;
    dev_.on_wait = on_wait_;
    waits_ = 0;
    return 0;
}

static void register_layout_matches_manual(void **state)
{
    (void)state;
    assert_int_equal(offsetof(stm32f4_flash_if_t, KEYR), 0x04);
    assert_int_equal(offsetof(stm32f4_flash_if_t, SR), 0x0C);
    assert_int_equal(offsetof(stm32f4_flash_if_t, CR), 0x10);
}

static void erase_unlocks_erases_sector_and_locks(void **state)
{
    (void)state;
    assert_int_equal(stm32f4_flash_erase(&dev_, 1), FW_OK);
    assert_int_equal(fake_.regs.KEYR, FLASH_KEY2);  // the second key was the last written
    assert_int_equal(fake_.last_snb, 11);         // region sector 1 = RM0090 sector 11
    assert_int_equal(fake_.last_psize, FLASH_CR_PSIZE_X32);
    for (uint32_t i = 0; i < SECTOR; i++) {
        assert_int_equal(mem_[SECTOR + i], 0xFF);
        assert_int_equal(mem_[i], 0x5A);  // the other sector untouched
    }
    assert_true(fake_.regs.CR & FLASH_CR_LOCK);
    assert_int_equal(fake_.regs.CR & (FLASH_CR_SER | FLASH_CR_SNB_MASK), 0);
    assert_true(fake_.regs.ACR & FLASH_ACR_DCEN);  // data cache reset and back on
    assert_int_equal(fake_.regs.ACR & FLASH_ACR_DCRST, 0);
}

static void long_erase_calls_the_wait_hook(void **state)
{
    (void)state;
    fake_.busy_polls = 3u * STM32F4_FLASH_WAIT_SLICE;
    assert_int_equal(stm32f4_flash_erase(&dev_, 0), FW_OK);
    assert_true(waits_ >= 3u);  // the port kicks the watchdog there
}

static void erase_refuses_bad_sector(void **state)
{
    (void)state;
    assert_int_equal(stm32f4_flash_erase(&dev_, 2), FW_ERR_INVAL);
    assert_true(fake_.regs.CR & FLASH_CR_LOCK);
}

static void locked_interface_is_io_error(void **state)
{
    (void)state;
    fake_.never_unlock = true;  // a wrong key sequence locks until reset
    assert_int_equal(stm32f4_flash_erase(&dev_, 0), FW_ERR_IO);
    assert_int_equal(fake_.regs.CR & FLASH_CR_STRT, 0);
    assert_int_equal(mem_[0], 0x5A);
}

static void stuck_busy_times_out(void **state)
{
    (void)state;
    fake_.regs.SR = FLASH_SR_BSY;
    fake_.busy_polls = 0xFFFFFFFFu;
    assert_int_equal(stm32f4_flash_erase(&dev_, 0), FW_ERR_TIMEOUT);
}

static void error_flag_is_io_error(void **state)
{
    (void)state;
    fake_.error_on_start = FLASH_SR_WRPERR;  // write-protected sector
    assert_int_equal(stm32f4_flash_erase(&dev_, 0), FW_ERR_IO);
    assert_true(fake_.regs.CR & FLASH_CR_LOCK);
}

static void program_writes_words_and_verifies(void **state)
{
    (void)state;
    assert_int_equal(stm32f4_flash_erase(&dev_, 0), FW_OK);
    const uint8_t data[8] = {1, 2, 3, 4, 0xDE, 0xAD, 0xBE, 0xEF};
    assert_int_equal(stm32f4_flash_program(&dev_, 16, data, sizeof data), FW_OK);
    assert_memory_equal(&mem_[16], data, sizeof data);
    assert_int_equal(mem_[15], 0xFF);
    assert_int_equal(mem_[24], 0xFF);
    assert_true(fake_.regs.CR & FLASH_CR_LOCK);
    assert_int_equal(fake_.regs.CR & FLASH_CR_PG, 0);
}

static void program_refuses_misaligned_and_out_of_range(void **state)
{
    (void)state;
    const uint8_t data[8] = {0};
    assert_int_equal(stm32f4_flash_program(&dev_, 2, data, 4), FW_ERR_INVAL);
    assert_int_equal(stm32f4_flash_program(&dev_, 0, data, 6), FW_ERR_INVAL);
    assert_int_equal(stm32f4_flash_program(&dev_, 2 * SECTOR - 4, data, 8), FW_ERR_INVAL);
    assert_int_equal(stm32f4_flash_program(&dev_, 2 * SECTOR, data, 4), FW_ERR_INVAL);
    assert_int_equal(stm32f4_flash_program(&dev_, 2 * SECTOR - 4, data, 4), FW_OK);
}

// RM0090 tables 5 and 6: each bank is 4 x 16 KB, 64 KB, 7 x 128 KB; bank 2 follows bank 1.
static void sector_map_matches_manual(void **state)
{
    (void)state;
    static const struct {
        uint32_t sector, addr, size;
    } rows[] = {
        {0, 0x08000000u, 16384u},   {3, 0x0800C000u, 16384u},   {4, 0x08010000u, 65536u},
        {5, 0x08020000u, 131072u},  {10, 0x080C0000u, 131072u}, {11, 0x080E0000u, 131072u},
        {12, 0x08100000u, 16384u},  {16, 0x08110000u, 65536u},  {17, 0x08120000u, 131072u},
        {20, 0x08180000u, 131072u}, {23, 0x081E0000u, 131072u},
    };
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        uint32_t addr = 0, size = 0;
        assert_int_equal(stm32f4_flash_sector(rows[i].sector, &addr, &size), FW_OK);
        assert_int_equal(addr, rows[i].addr);
        assert_int_equal(size, rows[i].size);
    }
    // Back to back, 2 MB in all.
    uint32_t end = 0x08000000u;
    for (uint32_t sct = 0; sct < STM32F4_FLASH_SECTORS_MAX; sct++) {
        uint32_t addr = 0, size = 0;
        assert_int_equal(stm32f4_flash_sector(sct, &addr, &size), FW_OK);
        assert_int_equal(addr, end);
        end = addr + size;
    }
    assert_int_equal(end, 0x08200000u);
    uint32_t addr = 0, size = 0;
    assert_int_equal(stm32f4_flash_sector(24, &addr, &size), FW_ERR_INVAL);
}

static void bank2_sectors_are_coded_from_16(void **state)
{
    (void)state;
    assert_int_equal(stm32f4_flash_snb(0), 0);
    assert_int_equal(stm32f4_flash_snb(11), 11);
    assert_int_equal(stm32f4_flash_snb(12), 16);
    assert_int_equal(stm32f4_flash_snb(20), 24);
    assert_int_equal(stm32f4_flash_snb(23), 27);
    assert_int_equal(stm32f4_flash_snb(23) << FLASH_CR_SNB_SHIFT & ~FLASH_CR_SNB_MASK, 0);  // fits
}

// The two boards' regions (boards/robot, boards/robot-f42x) against parts of several sizes.
static void region_checked_against_map_and_part_size(void **state)
{
    (void)state;
    const uint32_t k128 = 128u * 1024u;
    assert_int_equal(stm32f4_flash_region_check(0x080C0000u, 10, 2, k128, 1024), FW_OK);
    assert_int_equal(stm32f4_flash_region_check(0x080C0000u, 10, 2, k128, 2048), FW_OK);
    assert_int_equal(stm32f4_flash_region_check(0x080C0000u, 10, 2, k128, 512), FW_ERR_NOSYS);
    assert_int_equal(stm32f4_flash_region_check(0x08180000u, 20, 4, k128, 2048), FW_OK);
    assert_int_equal(stm32f4_flash_region_check(0x08180000u, 20, 4, k128, 1024), FW_ERR_NOSYS);
    assert_int_equal(stm32f4_flash_region_check(0x08080000u, 8, 4, k128, 1024), FW_OK);
    // Wrong start, unequal sectors (64 KB sector 4 and 128 KB sector 5), too few, off the map.
    assert_int_equal(stm32f4_flash_region_check(0x080A0000u, 10, 2, k128, 1024), FW_ERR_NOSYS);
    assert_int_equal(stm32f4_flash_region_check(0x08010000u, 4, 2, 65536u, 1024), FW_ERR_NOSYS);
    assert_int_equal(stm32f4_flash_region_check(0x080E0000u, 11, 1, k128, 1024), FW_ERR_NOSYS);
    assert_int_equal(stm32f4_flash_region_check(0x081E0000u, 23, 2, k128, 4096), FW_ERR_NOSYS);
    // Across the bank boundary: sector 12 is 16 KB.
    assert_int_equal(stm32f4_flash_region_check(0x080E0000u, 11, 2, k128, 2048), FW_ERR_NOSYS);
}

static void geometry_and_read_of_the_region(void **state)
{
    (void)state;
    hal_flash_geometry_t g;
    assert_int_equal(stm32f4_flash_geometry(&dev_, &g), FW_OK);
    assert_int_equal(g.sector_size, SECTOR);
    assert_int_equal(g.sector_count, 2);
    assert_int_equal(g.write_align, 4);
    uint8_t buf[8];
    mem_[2 * SECTOR - 1] = 0x77;
    assert_int_equal(stm32f4_flash_read(&dev_, 2 * SECTOR - 8, buf, 8), FW_OK);
    assert_int_equal(buf[7], 0x77);
    assert_int_equal(stm32f4_flash_read(&dev_, 2 * SECTOR - 7, buf, 8), FW_ERR_INVAL);
    assert_int_equal(stm32f4_flash_read(&dev_, 0xFFFFFFF0u, buf, 32), FW_ERR_INVAL);  // wraps
    assert_int_equal(stm32f4_flash_read(&dev_, 2 * SECTOR, buf, 0), FW_OK);
    // No region (the part lacks the sectors): geometry says so, nothing else touches the flash.
    dev_.sector_count = 0;
    assert_int_equal(stm32f4_flash_geometry(&dev_, &g), FW_ERR_NOSYS);
    assert_int_equal(stm32f4_flash_read(&dev_, 0, buf, 4), FW_ERR_INVAL);
    assert_int_equal(stm32f4_flash_erase(&dev_, 0), FW_ERR_INVAL);
    assert_int_equal(stm32f4_flash_program(&dev_, 0, buf, 4), FW_ERR_INVAL);
    assert_true(fake_.regs.CR & FLASH_CR_LOCK);
    assert_int_equal(fake_.regs.KEYR, 0);  // never unlocked
}

// The paper-sim layout: bank-2 sectors 20-23, erased with SNB 24-27.
static void bank2_region_erases_the_right_sectors(void **state)
{
    (void)state;
    dev_.first_sector = fake_.first_sector = 20;
    dev_.sector_count = 4;
    for (uint32_t s = 0; s < 4u; s++) {
        memset(mem_, 0x5A, sizeof mem_);
        assert_int_equal(stm32f4_flash_erase(&dev_, s), FW_OK);
        assert_int_equal(fake_.last_snb, 24u + s);
        for (uint32_t i = 0; i < MEM_SECTORS * SECTOR; i++) {
            assert_int_equal(mem_[i], i / SECTOR == s ? 0xFF : 0x5A);
        }
    }
    assert_int_equal(stm32f4_flash_erase(&dev_, 4), FW_ERR_INVAL);
    const uint8_t data[4] = {9, 8, 7, 6};
    assert_int_equal(stm32f4_flash_program(&dev_, 3 * SECTOR + 12, data, 4), FW_OK);
    assert_memory_equal(&mem_[3 * SECTOR + 12], data, 4);
    assert_int_equal(stm32f4_flash_program(&dev_, 4 * SECTOR, data, 4), FW_ERR_INVAL);
}

// SNB 27 (sector 23) sets bit 7, the fifth SNB bit: the erase must clear the whole field
// afterwards (bit 7 is reserved on the F405/407) and must not have been coded as 23 (sector 19).
static void snb_cleared_after_bank2_erase(void **state)
{
    (void)state;
    dev_.first_sector = fake_.first_sector = 20;
    dev_.sector_count = 4;
    assert_int_equal(stm32f4_flash_erase(&dev_, 3), FW_OK);
    assert_int_equal(fake_.last_snb, 27);
    assert_int_equal(fake_.regs.CR & FLASH_CR_SNB_MASK, 0);
    assert_int_equal(fake_.regs.CR & (1u << 7), 0);
}

static void program_error_flag_is_io_error(void **state)
{
    (void)state;
    fake_.regs.SR = FLASH_SR_PGSERR;  // raised during programming; the fake cannot clear on write 1
    const uint8_t data[4] = {1, 2, 3, 4};
    assert_int_equal(stm32f4_flash_program(&dev_, 0, data, 4), FW_ERR_IO);
    assert_true(fake_.regs.CR & FLASH_CR_LOCK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(register_layout_matches_manual, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(erase_unlocks_erases_sector_and_locks, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(long_erase_calls_the_wait_hook, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(erase_refuses_bad_sector, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(locked_interface_is_io_error, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(stuck_busy_times_out, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(error_flag_is_io_error, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(program_writes_words_and_verifies, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(program_refuses_misaligned_and_out_of_range, setup_,
                                        stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(program_error_flag_is_io_error, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(sector_map_matches_manual, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(bank2_sectors_are_coded_from_16, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(region_checked_against_map_and_part_size, setup_,
                                        stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(geometry_and_read_of_the_region, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(bank2_region_erases_the_right_sectors, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(snb_cleared_after_bank2_erase, setup_, stm32f4_fake_teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
