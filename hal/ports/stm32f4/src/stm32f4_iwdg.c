// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 port: the independent watchdog (clocked by the ~32 kHz LSI, RM0090 19).
#include "stm32f4/stm32f4_drivers.h"

#define IWDG_RELOAD_MAX 4095u
#define IWDG_PR_MAX 6u  // /256

int stm32f4_iwdg_divider(uint32_t timeout_ms, uint32_t *pr, uint32_t *rlr)
{
    if (timeout_ms == 0u) {
        return FW_ERR_INVAL;
    }
    for (uint32_t code = 0; code <= IWDG_PR_MAX; code++) {
        const uint64_t div = 4ull << code;
        // Counter ticks in the timeout, rounded down so the watchdog never fires later than asked.
        const uint64_t ticks = (uint64_t)timeout_ms * IWDG_LSI_HZ / (1000ull * div);
        if (ticks >= 1u && ticks <= IWDG_RELOAD_MAX + 1u) {
            *pr = code;
            *rlr = (uint32_t)ticks - 1u;
            return FW_OK;
        }
    }
    return FW_ERR_INVAL;
}

int stm32f4_iwdg_start(stm32f4_iwdg_t *iwdg, uint32_t timeout_ms)
{
    uint32_t pr = 0;
    uint32_t rlr = 0;
    if (stm32f4_iwdg_divider(timeout_ms, &pr, &rlr) != FW_OK) {
        return FW_ERR_INVAL;
    }
    iwdg->KR = IWDG_KEY_START;  // starts the LSI and the counter (RM0090 19.3.2)
    iwdg->KR = IWDG_KEY_ACCESS;
    iwdg->PR = pr;
    iwdg->RLR = rlr;
    if (stm32f4_wait_bits(&iwdg->SR, IWDG_SR_PVU | IWDG_SR_RVU, 0u,
                          STM32F4_CFG_SHORT_WAIT_POLLS) != FW_OK) {
        return FW_ERR_TIMEOUT;
    }
    iwdg->KR = IWDG_KEY_RELOAD;
    return FW_OK;
}

void stm32f4_iwdg_kick(stm32f4_iwdg_t *iwdg)
{
    iwdg->KR = IWDG_KEY_RELOAD;
}
