// SPDX-License-Identifier: MIT
// Tests of the STM32F4 clock tree, reset cause, independent watchdog and SysTick time
// (hal/ports/stm32f4/src/stm32f4_{rcc,iwdg,time}.c) against fake register blocks.
#include "test_common.h"

#include <string.h>

#include "fw/fw_base.h"
#include "stm32f4/stm32f4_drivers.h"
#include "stm32f4_fake.h"

static stm32f4_rcc_t rcc_;
static stm32f4_flash_if_t flash_;
static uint32_t pwr_cr_;
static stm32f4_iwdg_t iwdg_;
static bool hse_present_;

// The RCC: ready flags follow their enables (HSE only if a crystal is fitted), SWS follows SW;
// the IWDG's update flags clear at once.
static void rcc_hw_(void)
{
    if ((rcc_.CR & RCC_CR_HSEON) && hse_present_) {
        rcc_.CR |= RCC_CR_HSERDY;
    }
    if (rcc_.CR & RCC_CR_PLLON) {
        rcc_.CR |= RCC_CR_PLLRDY;
    }
    rcc_.CFGR = (rcc_.CFGR & ~RCC_CFGR_SWS_MASK) | ((rcc_.CFGR & 3u) << 2);
    iwdg_.SR = 0;
}

static int setup_(void **state)
{
    (void)state;
    memset(&rcc_, 0, sizeof rcc_);
    memset(&flash_, 0, sizeof flash_);
    memset(&iwdg_, 0, sizeof iwdg_);
    pwr_cr_ = 0;
    hse_present_ = true;
    stm32f4_poll_hook = rcc_hw_;
    return 0;
}

static void register_layout_matches_manual(void **state)
{
    (void)state;
    assert_int_equal(offsetof(stm32f4_rcc_t, AHB1ENR), 0x30);
    assert_int_equal(offsetof(stm32f4_rcc_t, APB1ENR), 0x40);
    assert_int_equal(offsetof(stm32f4_rcc_t, CSR), 0x74);
    assert_int_equal(offsetof(stm32f4_iwdg_t, SR), 0x0C);
    assert_int_equal(offsetof(stm32f4_gpio_t, AFR), 0x20);
}

static void clock_168mhz_from_8mhz_hse(void **state)
{
    (void)state;
    assert_int_equal(stm32f4_clock_init(&rcc_, &flash_, &pwr_cr_), FW_OK);
    assert_int_equal(flash_.ACR & FLASH_ACR_LATENCY_MASK, 5);  // 5 wait states at 168 MHz
    assert_true(flash_.ACR & FLASH_ACR_PRFTEN);
    assert_true(pwr_cr_ & PWR_CR_VOS);
    const uint32_t pll = rcc_.PLLCFGR;
    const uint32_t m = pll & 0x3Fu;
    const uint32_t n = (pll >> 6) & 0x1FFu;
    const uint32_t p = 2u * (((pll >> 16) & 3u) + 1u);
    const uint32_t q = (pll >> 24) & 0xFu;
    assert_true(pll & RCC_PLLCFGR_PLLSRC_HSE);
    assert_int_equal(8000000u / m * n / p, STM32F4_SYSCLK_HZ);
    assert_int_equal(8000000u / m * n / q, 48000000u);  // USB needs exactly 48 MHz
    assert_int_equal(8000000u / m, 1000000u);  // VCO input 1-2 MHz
    assert_int_equal(rcc_.CFGR & 3u, RCC_CFGR_SW_PLL);
    assert_int_equal((rcc_.CFGR >> 4) & 0xFu, 0);  // AHB /1
    assert_int_equal((rcc_.CFGR >> 10) & 7u, 5);   // APB1 /4 = 42 MHz
    assert_int_equal((rcc_.CFGR >> 13) & 7u, 4);   // APB2 /2 = 84 MHz
}

static void missing_crystal_times_out(void **state)
{
    (void)state;
    hse_present_ = false;
    assert_int_equal(stm32f4_clock_init(&rcc_, &flash_, &pwr_cr_), FW_ERR_TIMEOUT);
    assert_int_equal(rcc_.CFGR & 3u, 0);  // still on HSI
}

static void reset_cause_from_flags(void **state)
{
    (void)state;
    assert_int_equal(stm32f4_reset_cause_from_csr(RCC_CSR_PORRSTF | RCC_CSR_BORRSTF |
                                                  RCC_CSR_PINRSTF),
                     HAL_RESET_POWER_ON);
    assert_int_equal(stm32f4_reset_cause_from_csr(RCC_CSR_PINRSTF), HAL_RESET_PIN);
    assert_int_equal(stm32f4_reset_cause_from_csr(RCC_CSR_IWDGRSTF | RCC_CSR_PINRSTF),
                     HAL_RESET_WATCHDOG);
    assert_int_equal(stm32f4_reset_cause_from_csr(RCC_CSR_WWDGRSTF), HAL_RESET_WATCHDOG);
    assert_int_equal(stm32f4_reset_cause_from_csr(RCC_CSR_SFTRSTF | RCC_CSR_PINRSTF),
                     HAL_RESET_SOFTWARE);
    assert_int_equal(stm32f4_reset_cause_from_csr(RCC_CSR_LPWRRSTF), HAL_RESET_OTHER);
    assert_int_equal(stm32f4_reset_cause_from_csr(0), HAL_RESET_OTHER);
}

static void watchdog_divider_never_later_than_asked(void **state)
{
    (void)state;
    uint32_t pr = 9;
    uint32_t rlr = 0;
    // 100 ms at 32 kHz: /4 gives 800 ticks.
    assert_int_equal(stm32f4_iwdg_divider(100u, &pr, &rlr), FW_OK);
    assert_int_equal(pr, 0);
    assert_int_equal(rlr, 799);
    // 1 s: /4 would need 8000 > 4096 ticks; /8 gives 4000.
    assert_int_equal(stm32f4_iwdg_divider(1000u, &pr, &rlr), FW_OK);
    assert_int_equal(pr, 1);
    assert_int_equal(rlr, 3999);
    for (uint32_t ms = 1; ms <= 32768u; ms += 97u) {
        assert_int_equal(stm32f4_iwdg_divider(ms, &pr, &rlr), FW_OK);
        const uint64_t actual_us = (uint64_t)(rlr + 1u) * (4u << pr) * 1000000u / IWDG_LSI_HZ;
        assert_true(actual_us <= (uint64_t)ms * 1000u);
        assert_true(rlr <= 4095u && pr <= 6u);
    }
    assert_int_equal(stm32f4_iwdg_divider(0u, &pr, &rlr), FW_ERR_INVAL);
    assert_int_equal(stm32f4_iwdg_divider(40000u, &pr, &rlr), FW_ERR_INVAL);
}

static void watchdog_start_and_kick(void **state)
{
    (void)state;
    assert_int_equal(stm32f4_iwdg_start(&iwdg_, 500u), FW_OK);
    assert_int_equal(iwdg_.PR, 0);
    assert_int_equal(iwdg_.RLR, 3999);
    assert_int_equal(iwdg_.KR, IWDG_KEY_RELOAD);
    iwdg_.KR = 0;
    stm32f4_iwdg_kick(&iwdg_);
    assert_int_equal(iwdg_.KR, IWDG_KEY_RELOAD);
    assert_int_equal(stm32f4_iwdg_start(&iwdg_, 0u), FW_ERR_INVAL);
}

static void watchdog_update_flag_stuck_times_out(void **state)
{
    (void)state;
    stm32f4_poll_hook = NULL;
    iwdg_.SR = IWDG_SR_RVU;
    assert_int_equal(stm32f4_iwdg_start(&iwdg_, 500u), FW_ERR_TIMEOUT);
}

static void systick_microseconds(void **state)
{
    (void)state;
    const uint32_t load = 168000u - 1u;
    assert_int_equal(stm32f4_time_us(0, load, load, 168), 0);
    assert_int_equal(stm32f4_time_us(7, load, load - 168u * 250u, 168), 7250);
    assert_int_equal(stm32f4_time_us(7, load, 0, 168), 7999);  // never reaches the next ms
    // Monotonic across a millisecond boundary.
    uint64_t last = 0;
    for (uint32_t ms = 0; ms < 3u; ms++) {
        for (uint32_t val = load + 1u; val-- > 0u;) {
            const uint64_t t = stm32f4_time_us(ms, load, val, 168);
            assert_true(t >= last);
            last = t;
            if (val > 1000u) {
                val -= 997u;  // sample the millisecond sparsely
            }
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(register_layout_matches_manual, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(clock_168mhz_from_8mhz_hse, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(missing_crystal_times_out, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(reset_cause_from_flags, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(watchdog_divider_never_later_than_asked, setup_,
                                        stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(watchdog_start_and_kick, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(watchdog_update_flag_stuck_times_out, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(systick_microseconds, setup_, stm32f4_fake_teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
