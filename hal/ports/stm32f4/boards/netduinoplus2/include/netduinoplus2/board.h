// SPDX-License-Identifier: MIT
// dynaqpc netduinoplus2 board: the robot's firmware on QEMU's `-M netduinoplus2` (an STM32F405
// with the peripherals QEMU 7.2 models: SysTick, NVIC, USARTs, TIM2-5; no RCC, no bxCAN, no flash
// interface, no IWDG). What stands in for the missing ones:
//   CAN    SLCAN (Lawicel) lines on USART1 (QEMU's first -serial): tools/dynaqpc_tools/emu
//          bridges them to the virtual CAN bus (python-can's slcan interface)
//   UART   the Cricket listener on USART2 (QEMU's second -serial), as on the robot
//   flash  the hal_flash region in SRAM (NOR semantics kept; erased at power-on)
// and the board's console is ARM semihosting (QEMU's -semihosting-config; the family's
// stm32f4/semihost.h): reports, the command line (-append), exit codes, a hard fault's report.
#ifndef NETDUINOPLUS2_BOARD_H
#define NETDUINOPLUS2_BOARD_H

#include <stdint.h>

#include "hal/hal_can.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Exit codes the board gives QEMU (semihosting SYS_EXIT_EXTENDED).
#define ND2_EXIT_OK 0u
#define ND2_EXIT_FAILED 1u      ///< the run's checks failed (the caller's)
#define ND2_EXIT_INIT 2u        ///< the firmware did not start
#define ND2_EXIT_HARD_FAULT 3u  ///< a fault or an unexpected interrupt

/// Board bring-up before the application: the reset cause and the erased flash region. QEMU models
/// no clock tree, so there is nothing to wait for. Returns 0.
int nd2_board_init(void);

/// Firmware time runs `speed` times faster than the emulated clock (1, the default: as on the
/// robot): hal_time_us() is TIM2's microsecond count times speed, and SysTick interrupts every
/// 168,000 / speed core cycles (a firmware millisecond). With QEMU's
/// -icount shift=S, the firmware then sees a CPU of 1e9 / (2^S x speed) instructions per second
/// of its own time (shift 0 at speed 8, or shift 3 at speed 1: 125 M), while the simulated devices
/// run `--speed` times faster than real time alongside. speed must divide 168 (1, 2, 4, 6, 7, 8,
/// 12, 14, ...); call before hal_time_init(). Returns 0, or -1 for a speed it cannot do.
int nd2_set_time_speed(uint32_t speed);

/// The main stack's bytes never written since reset (the reset handler paints them with
/// ND2_STACK_PAINT: startup_hooks.h).
#define ND2_STACK_PAINT 0xA5A5A5A5u
uint32_t nd2_stack_unused_bytes(void);

/// A fault or an unexpected interrupt: reports `what`, the exception number, CFSR and HFSR over
/// semihosting and ends the emulation with ND2_EXIT_HARD_FAULT.
__attribute__((noreturn)) void nd2_fault(const char *what);

/// SLCAN lines received that were neither a frame nor a command.
uint32_t nd2_slcan_errors(void);

#ifdef __cplusplus
}
#endif

#endif // NETDUINOPLUS2_BOARD_H
