// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 port: the vector table and the reset handler (also used by the QEMU images).
//
// Reset: copy .data from its load address in flash, zero .bss, enable the FPU (CPACR CP10/CP11
// full access, then DSB/ISB so no floating-point instruction runs before it takes effect), call
// main(). The firmware is compiled with -mfloat-abi=hard: a float instruction with the FPU off
// faults, so nothing before fpu_enable_() may use one (this file has none).
#include <stdint.h>

#include "stm32f4/stm32f4_regs.h"

int main(void);
void Reset_Handler(void);
void Default_Handler(void);

// Symbols of the linker script (ld/sections.ld).
extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;

// Core exceptions and device interrupts default to Default_Handler; a driver that defines a
// handler of the same name (hal_stm32f4.c) replaces the weak alias.
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
void USART2_IRQHandler(void) WEAK_DEFAULT;

typedef void (*vector_t)(void);

// Only the entries the port uses are named; the others fall to Default_Handler.
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
    fpu_enable_();
    (void)main();
    for (;;) {
        __asm__ volatile("wfi");
    }
}

// An unexpected interrupt or a fault: stop here, where a debugger shows it (and the watchdog,
// if running, resets the MCU).
void Default_Handler(void)
{
    for (;;) {
        __asm__ volatile("nop");
    }
}
