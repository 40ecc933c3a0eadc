// SPDX-License-Identifier: MIT
// Tests of the STM32F4 flash driver (hal/ports/stm32f4/src/stm32f4_flash.c) against a fake flash
// interface: a RAM register block plus a small "flash" array, with a poll hook that plays the
// hardware (unlock on the key sequence, NOR erase, busy and error flags driven by the test).
#include "test_common.h"

#include <string.h>

#include "fw/fw_base.h"
#include "stm32f4/stm32f4_drivers.h"

#define SECTOR 256u

static stm32f4_flash_if_t regs_;
static uint8_t mem_[2 * SECTOR];
static stm32f4_flash_dev_t dev_;
static uint32_t erased_snb_;      // SNB of the last erase the fake performed
static uint32_t erase_psize_;     // PSIZE it saw
static uint32_t busy_polls_;      // the fake stays busy this many polls after a start
static uint32_t error_on_start_;  // SR error bits the fake raises on an operation
static bool never_unlock_;
static uint32_t waits_;

static void flash_hw_(void)
{
    if ((regs_.CR & FLASH_CR_LOCK) && regs_.KEYR == FLASH_KEY2 && !never_unlock_) {
        regs_.CR &= ~FLASH_CR_LOCK;
    }
    if (regs_.CR & FLASH_CR_STRT) {
        regs_.CR &= ~FLASH_CR_STRT;
        erased_snb_ = (regs_.CR & FLASH_CR_SNB_MASK) >> FLASH_CR_SNB_SHIFT;
        erase_psize_ = regs_.CR & FLASH_CR_PSIZE_MASK;
        const uint32_t s = erased_snb_ - dev_.first_sector;
        if (s < 2u && !error_on_start_) {
            memset(&mem_[s * SECTOR], 0xFF, SECTOR);
        }
        regs_.SR |= FLASH_SR_BSY | error_on_start_;
        return;
    }
    if (regs_.SR & FLASH_SR_BSY) {
        if (busy_polls_ > 0u) {
            busy_polls_--;
        } else {
            regs_.SR &= ~FLASH_SR_BSY;
        }
    }
}

static void on_wait_(void)
{
    waits_++;
}

static int setup_(void **state)
{
    (void)state;
    memset(&regs_, 0, sizeof regs_);
    regs_.CR = FLASH_CR_LOCK;  // reset value
    regs_.ACR = FLASH_ACR_DCEN | FLASH_ACR_ICEN | 5u;
    memset(mem_, 0x5A, sizeof mem_);
    dev_.regs = &regs_;
    dev_.mem = mem_;
    dev_.first_sector = 10;
    dev_.sector_count = 2;
    dev_.sector_size = SECTOR;
    dev_.on_wait = on_wait_;
    erased_snb_ = 0;
    erase_psize_ = 0;
    busy_polls_ = 0;
    error_on_start_ = 0;
    never_unlock_ = false;
    waits_ = 0;
    stm32f4_poll_hook = flash_hw_;
    return 0;
}

static int teardown_(void **state)
{
    (void)state;
    stm32f4_poll_hook = NULL;
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
    assert_int_equal(regs_.KEYR, FLASH_KEY2);  // the second key was the last written
    assert_int_equal(erased_snb_, 11);         // region sector 1 = RM0090 sector 11
    assert_int_equal(erase_psize_, FLASH_CR_PSIZE_X32);
    for (uint32_t i = 0; i < SECTOR; i++) {
        assert_int_equal(mem_[SECTOR + i], 0xFF);
        assert_int_equal(mem_[i], 0x5A);  // the other sector untouched
    }
    assert_true(regs_.CR & FLASH_CR_LOCK);
    assert_int_equal(regs_.CR & (FLASH_CR_SER | FLASH_CR_SNB_MASK), 0);
    assert_true(regs_.ACR & FLASH_ACR_DCEN);  // data cache reset and back on
    assert_int_equal(regs_.ACR & FLASH_ACR_DCRST, 0);
}

static void long_erase_calls_the_wait_hook(void **state)
{
    (void)state;
    busy_polls_ = 3u * STM32F4_FLASH_WAIT_SLICE;
    assert_int_equal(stm32f4_flash_erase(&dev_, 0), FW_OK);
    assert_true(waits_ >= 3u);  // the port kicks the watchdog there
}

static void erase_refuses_bad_sector(void **state)
{
    (void)state;
    assert_int_equal(stm32f4_flash_erase(&dev_, 2), FW_ERR_INVAL);
    assert_true(regs_.CR & FLASH_CR_LOCK);
}

static void locked_interface_is_io_error(void **state)
{
    (void)state;
    never_unlock_ = true;  // a wrong key sequence locks until reset
    assert_int_equal(stm32f4_flash_erase(&dev_, 0), FW_ERR_IO);
    assert_int_equal(regs_.CR & FLASH_CR_STRT, 0);
    assert_int_equal(mem_[0], 0x5A);
}

static void stuck_busy_times_out(void **state)
{
    (void)state;
    regs_.SR = FLASH_SR_BSY;
    busy_polls_ = 0xFFFFFFFFu;
    assert_int_equal(stm32f4_flash_erase(&dev_, 0), FW_ERR_TIMEOUT);
}

static void error_flag_is_io_error(void **state)
{
    (void)state;
    error_on_start_ = FLASH_SR_WRPERR;  // write-protected sector
    assert_int_equal(stm32f4_flash_erase(&dev_, 0), FW_ERR_IO);
    assert_true(regs_.CR & FLASH_CR_LOCK);
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
    assert_true(regs_.CR & FLASH_CR_LOCK);
    assert_int_equal(regs_.CR & FLASH_CR_PG, 0);
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

static void program_error_flag_is_io_error(void **state)
{
    (void)state;
    regs_.SR = FLASH_SR_PGSERR;  // raised during programming; the fake cannot clear on write 1
    const uint8_t data[4] = {1, 2, 3, 4};
    assert_int_equal(stm32f4_flash_program(&dev_, 0, data, 4), FW_ERR_IO);
    assert_true(regs_.CR & FLASH_CR_LOCK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(register_layout_matches_manual, setup_, teardown_),
        cmocka_unit_test_setup_teardown(erase_unlocks_erases_sector_and_locks, setup_, teardown_),
        cmocka_unit_test_setup_teardown(long_erase_calls_the_wait_hook, setup_, teardown_),
        cmocka_unit_test_setup_teardown(erase_refuses_bad_sector, setup_, teardown_),
        cmocka_unit_test_setup_teardown(locked_interface_is_io_error, setup_, teardown_),
        cmocka_unit_test_setup_teardown(stuck_busy_times_out, setup_, teardown_),
        cmocka_unit_test_setup_teardown(error_flag_is_io_error, setup_, teardown_),
        cmocka_unit_test_setup_teardown(program_writes_words_and_verifies, setup_, teardown_),
        cmocka_unit_test_setup_teardown(program_refuses_misaligned_and_out_of_range, setup_,
                                        teardown_),
        cmocka_unit_test_setup_teardown(program_error_flag_is_io_error, setup_, teardown_),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
