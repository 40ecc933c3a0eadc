// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 family: the Cortex-M4 primitives every board's hal_* files use, inline so that
// a board's own critical sections cost what the instructions cost: interrupt masking (PRIMASK)
// and enabling a device interrupt in the NVIC. Fixed addresses and CPU instructions: not for the
// drivers, which the host tests run.
#ifndef STM32F4_CPU_H
#define STM32F4_CPU_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "stm32f4/stm32f4_regs.h"

/// Masks interrupts; returns the previous PRIMASK (hal_irq_save, hal_stm32f4_cpu.c).
static inline uint32_t stm32f4_irq_save(void)
{
    uint32_t primask;
    __asm__ volatile("mrs %0, primask\n\tcpsid i" : "=r"(primask)::"memory");
    return primask;
}

/// Restores PRIMASK as stm32f4_irq_save() found it (hal_irq_restore).
static inline void stm32f4_irq_restore(uint32_t primask)
{
    __asm__ volatile("msr primask, %0" ::"r"(primask) : "memory");
}

/// Copies n bytes that an interrupt handler updates (a driver's statistics) with interrupts
/// masked, so that the copy is of one moment.
static inline void stm32f4_irq_copy(void *dst, const void *src, size_t n)
{
    const uint32_t primask = stm32f4_irq_save();
    memcpy(dst, src, n);
    stm32f4_irq_restore(primask);
}

/// Sets the priority of device interrupt `irq` (0 highest, 15 lowest: 4 bits, in the high nibble)
/// and enables it (PM0214 4.3).
static inline void stm32f4_nvic_enable(uint32_t irq, uint32_t prio)
{
    ((volatile uint8_t *)STM32F4_NVIC_IPR_BASE)[irq] = (uint8_t)(prio << 4);
    ((volatile uint32_t *)STM32F4_NVIC_ISER_BASE)[irq / 32u] = 1u << (irq % 32u);
}

#endif  // STM32F4_CPU_H
