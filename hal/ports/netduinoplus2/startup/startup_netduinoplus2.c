// SPDX-License-Identifier: MIT
// dynaqpc netduinoplus2 board: the vector table and the reset handler.
//
// Reset: copy .data from its load address in flash, zero .bss, paint the unused stack (for the
// high-water mark), enable the FPU (CPACR CP10/CP11, then DSB/ISB: the firmware is compiled with
// -mfloat-abi=hard and a float instruction with the FPU off faults), call main(). A fault or an
// interrupt without a handler reports over semihosting and ends the emulation with
// ND2_EXIT_HARD_FAULT, so a test sees it at once.
#include <stdint.h>

#include "netduinoplus2/board.h"
#include "stm32f4/stm32f4_regs.h"

int main(void);
void Reset_Handler(void);
void Default_Handler(void);
void HardFault_Handler(void);

// Symbols of the linker script (ld/netduinoplus2.ld).
extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _sstack, _estack;

#define STACK_PAINT 0xA5A5A5A5u
#define USART1_IRQ 37u  // STM32F405 position of USART1 (RM0090 table 61); USART2 is 38

#define WEAK_DEFAULT __attribute__((weak, alias("Default_Handler")))
void NMI_Handler(void) WEAK_DEFAULT;
void MemManage_Handler(void) WEAK_DEFAULT;
void BusFault_Handler(void) WEAK_DEFAULT;
void UsageFault_Handler(void) WEAK_DEFAULT;
void SVC_Handler(void) WEAK_DEFAULT;
void DebugMon_Handler(void) WEAK_DEFAULT;
void PendSV_Handler(void) WEAK_DEFAULT;
void SysTick_Handler(void) WEAK_DEFAULT;
void USART1_IRQHandler(void) WEAK_DEFAULT;
void USART2_IRQHandler(void) WEAK_DEFAULT;

typedef void (*vector_t)(void);

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
    [16u + USART1_IRQ] = USART1_IRQHandler,
    [16u + STM32F4_IRQ_USART2] = USART2_IRQHandler,
};

static void fpu_enable_(void)
{
    volatile uint32_t *cpacr = (volatile uint32_t *)STM32F4_SCB_CPACR;
    *cpacr |= 0xFu << 20;
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
    // The stack below what this function uses (a 256-byte margin) is painted.
    uint32_t sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    for (volatile uint32_t *w = &_sstack; (uintptr_t)w < sp - 256u;) {
        *w++ = STACK_PAINT;
    }
    fpu_enable_();
    (void)main();
    nd2_exit(ND2_EXIT_INIT);
}

uint32_t nd2_stack_unused_bytes(void)
{
    const volatile uint32_t *w = &_sstack;
    while (w < &_estack && *w == STACK_PAINT) {
        w++;
    }
    return (uint32_t)((uintptr_t)w - (uintptr_t)&_sstack);
}

static void fault_(const char *what)
{
    uint32_t ipsr;
    __asm__ volatile("mrs %0, ipsr" : "=r"(ipsr));
    nd2_puts("\nnetduinoplus2: ");
    nd2_puts(what);
    nd2_puts(" ");
    nd2_kv("exception", ipsr & 0x1FFu);
    nd2_kv("cfsr", *(volatile uint32_t *)0xE000ED28u);
    nd2_kv("hfsr", *(volatile uint32_t *)0xE000ED2Cu);
    nd2_puts("\n");
    nd2_exit(ND2_EXIT_HARD_FAULT);
}

void HardFault_Handler(void)
{
    fault_("HARD FAULT");
}

void Default_Handler(void)
{
    fault_("UNEXPECTED EXCEPTION");
}
