// SPDX-License-Identifier: MIT
// dynaqpc netduinoplus2 board: its hooks in the STM32F4 family's reset handler
// (startup/startup_stm32f4.c, which includes this file: board.cmake names it). Before the FPU is
// on, the stack below what the reset handler uses (a 256-byte margin) is painted, for the
// high-water mark (nd2_stack_unused_bytes); if main() returns the emulation ends with
// ND2_EXIT_INIT; a fault or an unexpected interrupt is reported over semihosting and ends it with
// ND2_EXIT_HARD_FAULT, so a test sees it at once.
#ifndef NETDUINOPLUS2_STARTUP_HOOKS_H
#define NETDUINOPLUS2_STARTUP_HOOKS_H

#include "netduinoplus2/board.h"
#include "stm32f4/semihost.h"

#define STM32F4_STARTUP_BEFORE_FPU()                                          \
    do {                                                                      \
        uint32_t sp_;                                                         \
        __asm__ volatile("mov %0, sp" : "=r"(sp_));                           \
        for (volatile uint32_t *w_ = &_sstack; (uintptr_t)w_ < sp_ - 256u;) { \
            *w_++ = ND2_STACK_PAINT;                                          \
        }                                                                     \
    } while (0)
#define STM32F4_STARTUP_MAIN_RETURNED() semihost_exit(ND2_EXIT_INIT)
#define STM32F4_STARTUP_FAULT(what) nd2_fault(what)

#endif  // NETDUINOPLUS2_STARTUP_HOOKS_H
