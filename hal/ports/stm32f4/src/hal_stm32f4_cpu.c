// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 family: the Cortex-M side of the hal_cpu contract, for every board: interrupt
// masking (PRIMASK), the idle wait (WFI) and cost accounting. The watchdog and the reset cause
// are each board's (hal_stm32f4.c on the robot boards, the emulated board's own).
#include "hal/hal_cpu.h"
#include "hal/hal_time.h"
#include "stm32f4/stm32f4_cpu.h"

hal_irq_state_t hal_irq_save(void)
{
    return stm32f4_irq_save();
}

void hal_irq_restore(hal_irq_state_t state)
{
    stm32f4_irq_restore(state);
}

void hal_cpu_wait_until(uint64_t deadline_us)
{
    // Called with PRIMASK set from the scheduler's last look at its event queue (hal_cpu.h): an
    // interrupt that becomes pending after that look still wakes WFI (ARMv7-M B1.5.19: a pending
    // interrupt that PRIMASK keeps from being taken ends the wait), and its handler runs as soon
    // as the caller restores the mask: nothing waits for the next SysTick. As QP/C's QV does
    // (QV_CPU_SLEEP: WFI, then unmask). SysTick wakes the core every millisecond, so one WFI
    // never oversleeps by more than 1 ms; the contract allows the early return. (The emulated
    // board's SysTick does the same; QEMU halts the vCPU until then.)
    if (hal_time_us() < deadline_us) {
        __asm__ volatile("dsb\n\twfi\n\tisb" ::: "memory");
    }
}

// Real (or emulated) time passes by itself on the MCU: the scheduler's cost accounting is for the
// host's lock-step model only.
void hal_cpu_account(uint32_t cycles)
{
    (void)cycles;
}
