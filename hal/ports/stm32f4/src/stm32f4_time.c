// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 port: microseconds from the SysTick millisecond count and its down-counter.
#include "stm32f4/stm32f4_drivers.h"

uint64_t stm32f4_time_us(uint64_t ms, uint32_t load, uint32_t val, uint32_t ticks_per_us)
{
    // VAL counts load, load-1, ..., 0 within a millisecond; elapsed ticks are load - val.
    uint32_t sub_us = (val <= load ? load - val : 0u) / ticks_per_us;
    if (sub_us > 999u) {
        sub_us = 999u;  // never reach the next millisecond before the interrupt counts it
    }
    return ms * 1000u + sub_us;
}
