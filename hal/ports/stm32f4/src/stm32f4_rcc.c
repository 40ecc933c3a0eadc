// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 port: the clock tree and the reset cause.
//
// Order (RM0090 3.5.1, 5.1.4, 6.3.2): voltage scale 1 for 168 MHz, the flash wait states raised
// before the clock is, HSE on, PLL configured while off, PLL on, bus prescalers, then the switch.
#include "stm32f4/stm32f4_drivers.h"

// PLL: VCO in = 8 MHz / M 8 = 1 MHz; VCO out = x N 336 = 336 MHz; SYSCLK = / P 2 = 168 MHz;
// USB/SDIO = / Q 7 = 48 MHz.
#define PLL_M 8u
#define PLL_N 336u
#define PLL_P_DIV2 0u
#define PLL_Q 7u
#define FLASH_WAIT_STATES_168MHZ 5u

int stm32f4_clock_init(stm32f4_rcc_t *rcc, stm32f4_flash_if_t *flash, volatile uint32_t *pwr_cr)
{
    rcc->APB1ENR |= RCC_APB1ENR_PWREN;
    *pwr_cr |= PWR_CR_VOS;
    flash->ACR = (flash->ACR & ~FLASH_ACR_LATENCY_MASK) | FLASH_WAIT_STATES_168MHZ |
                 FLASH_ACR_PRFTEN | FLASH_ACR_ICEN | FLASH_ACR_DCEN;
    if ((flash->ACR & FLASH_ACR_LATENCY_MASK) != FLASH_WAIT_STATES_168MHZ) {
        return FW_ERR_IO;  // the manual asks to read the latency back before raising the clock
    }
    rcc->CR |= RCC_CR_HSEON;
    if (stm32f4_wait_bits(&rcc->CR, RCC_CR_HSERDY, RCC_CR_HSERDY, STM32F4_CFG_SHORT_WAIT_POLLS) !=
        FW_OK) {
        return FW_ERR_TIMEOUT;
    }
    rcc->CR &= ~RCC_CR_PLLON;
    rcc->PLLCFGR = PLL_M | (PLL_N << 6) | (PLL_P_DIV2 << 16) | RCC_PLLCFGR_PLLSRC_HSE |
                   (PLL_Q << 24);
    rcc->CR |= RCC_CR_PLLON;
    if (stm32f4_wait_bits(&rcc->CR, RCC_CR_PLLRDY, RCC_CR_PLLRDY, STM32F4_CFG_SHORT_WAIT_POLLS) !=
        FW_OK) {
        return FW_ERR_TIMEOUT;
    }
    rcc->CFGR = RCC_CFGR_PPRE1_DIV4 | RCC_CFGR_PPRE2_DIV2 | RCC_CFGR_SW_PLL;  // AHB /1
    return stm32f4_wait_bits(&rcc->CFGR, RCC_CFGR_SWS_MASK, RCC_CFGR_SWS_PLL,
                             STM32F4_CFG_SHORT_WAIT_POLLS);
}

hal_reset_cause_t stm32f4_reset_cause_from_csr(uint32_t csr)
{
    // A watchdog or software reset also pulls NRST, so PINRSTF comes with them: the specific
    // flags are tested first. A power-on sets POR and BOR (and PIN).
    if (csr & (RCC_CSR_IWDGRSTF | RCC_CSR_WWDGRSTF)) {
        return HAL_RESET_WATCHDOG;
    }
    if (csr & RCC_CSR_SFTRSTF) {
        return HAL_RESET_SOFTWARE;
    }
    if (csr & (RCC_CSR_PORRSTF | RCC_CSR_BORRSTF)) {
        return HAL_RESET_POWER_ON;
    }
    if (csr & RCC_CSR_PINRSTF) {
        return HAL_RESET_PIN;
    }
    return HAL_RESET_OTHER;
}
