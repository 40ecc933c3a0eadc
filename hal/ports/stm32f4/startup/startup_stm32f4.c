// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 family: the vector table and the reset handler of every board's images (and of
// the QEMU agent images, targets/qemu-agent).
//
// Reset: copy .data from its load address in flash, zero .bss, enable the FPU (CPACR CP10/CP11
// full access, then DSB/ISB so no floating-point instruction runs before it takes effect), call
// main(). The firmware is compiled with -mfloat-abi=hard: a float instruction with the FPU off
// faults, so nothing before fpu_enable_() may use one (this file has none).
//
// A board changes what happens around that with hooks, macros in a header its board.cmake names
// (STM32F4_STARTUP_HOOKS, e.g. boards/netduinoplus2/startup_hooks.h); without one, the defaults
// below are the reference robot's:
//   STM32F4_STARTUP_BEFORE_FPU()     after .data and .bss, before the FPU is on (no float here)
//   STM32F4_STARTUP_MAIN_RETURNED()  main() returned: sleep for ever
//   STM32F4_STARTUP_FAULT(what)      an unexpected interrupt or a fault: stop where a debugger
//                                    shows it (the watchdog, if running, resets the MCU)
#include <stdint.h>

#include "stm32f4/stm32f4_regs.h"

int main(void);
void Reset_Handler(void);
void Default_Handler(void);

// Symbols of the linker script (ld/sections.ld).
extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _sstack, _estack;

#ifdef STM32F4_STARTUP_HOOKS
#include STM32F4_STARTUP_HOOKS
#endif
#ifndef STM32F4_STARTUP_BEFORE_FPU
#define STM32F4_STARTUP_BEFORE_FPU() ((void)0)
#endif
#ifndef STM32F4_STARTUP_MAIN_RETURNED
#define STM32F4_STARTUP_MAIN_RETURNED() \
    for (;;) {                          \
        __asm__ volatile("wfi");        \
    }
#endif
#ifndef STM32F4_STARTUP_FAULT
#define STM32F4_STARTUP_FAULT(what) \
    for (;;) {                      \
        __asm__ volatile("nop");    \
    }
#endif

// Core exceptions and device interrupts default to Default_Handler; a driver or a board that
// defines a handler of the same name (hal_stm32f4.c) replaces the weak alias.
#define WEAK_DEFAULT __attribute__((weak, alias("Default_Handler")))
void NMI_Handler(void) WEAK_DEFAULT;
void HardFault_Handler(void) WEAK_DEFAULT;
void MemManage_Handler(void) WEAK_DEFAULT;
void BusFault_Handler(void) WEAK_DEFAULT;
void UsageFault_Handler(void) WEAK_DEFAULT;
void SVC_Handler(void) WEAK_DEFAULT;
void DebugMon_Handler(void) WEAK_DEFAULT;
void PendSV_Handler(void) WEAK_DEFAULT;
void SysTick_Handler(void) WEAK_DEFAULT;
void CAN1_TX_IRQHandler(void) WEAK_DEFAULT;
void CAN1_RX0_IRQHandler(void) WEAK_DEFAULT;
void CAN1_RX1_IRQHandler(void) WEAK_DEFAULT;
void CAN1_SCE_IRQHandler(void) WEAK_DEFAULT;
void USART1_IRQHandler(void) WEAK_DEFAULT;
void USART2_IRQHandler(void) WEAK_DEFAULT;

typedef void (*vector_t)(void);

// Only the entries some board uses are named; the others are 0.
__attribute__((section(".isr_vector"), used)) static const vector_t vectors_[16u + STM32F4_IRQ_COUNT] = {
    [0] = (vector_t)(uintptr_t)&_estack,
    [1] = Reset_Handler,
    [2] = NMI_Handler,
    [3] = HardFault_Handler,
    [4] = MemManage_Handler,
    [5] = BusFault_Handler,
    [6] = UsageFault_Handler,
    [11] = SVC_Handler,
    [12] = DebugMon_Handler,
    [14] = PendSV_Handler,
    [15] = SysTick_Handler,
    [16u + STM32F4_IRQ_CAN1_TX] = CAN1_TX_IRQHandler,
    [16u + STM32F4_IRQ_CAN1_RX0] = CAN1_RX0_IRQHandler,
    [16u + STM32F4_IRQ_CAN1_RX1] = CAN1_RX1_IRQHandler,
    [16u + STM32F4_IRQ_CAN1_SCE] = CAN1_SCE_IRQHandler,
    [16u + STM32F4_IRQ_USART1] = USART1_IRQHandler,
    [16u + STM32F4_IRQ_USART2] = USART2_IRQHandler,
};

static void fpu_enable_(void)
{
    volatile uint32_t *cpacr = (volatile uint32_t *)STM32F4_SCB_CPACR;
    *cpacr |= 0xFu << 20;  // CP10 and CP11: full access
    __asm__ volatile("dsb\n\tisb" ::: "memory");
}

void Reset_Handler(void)
{
    volatile uint32_t *src = &_sidata;
    for (volatile uint32_t *dst = &_sdata; dst < &_edata;) {
        *dst++ = *src++;
    }
    for (volatile uint32_t *dst = &_sbss; dst < &_ebss;) {
        *dst++ = 0u;
    }
    STM32F4_STARTUP_BEFORE_FPU();
    fpu_enable_();
    (void)main();
    STM32F4_STARTUP_MAIN_RETURNED();
}

void Default_Handler(void)
{
    STM32F4_STARTUP_FAULT("UNEXPECTED EXCEPTION");
}
