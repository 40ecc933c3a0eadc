// SPDX-License-Identifier: MIT
// dynaqpc base layer: runtime assertions, all routed to one handler.
//
// FW_ASSERT(cond) checks a condition that only a programming error can make false (a caller
// breaking a documented precondition), never bad input from outside: that is a returned
// FW_ERR_*. A false condition calls fw_assert_failed(), which calls the handler installed with
// fw_assert_set_handler() and, if that returns or none is installed, stops: on a hosted build
// (the host port, the tests, the simulator) it prints "file:line: assertion failed" to stderr
// and aborts; on the MCU it spins with interrupts left as they are, so the watchdog resets the
// board.
//
// Where they stand (QP's REQUIRE style): at the entry of the public functions of sched, pqueue,
// cmac, model, the drivers, the robot application and the ports, on what a caller must never
// pass (a NULL object, an action out of range); and on the robot's boot calls that can only
// fail by a programming error (robot_app.c). On the MCU a site costs a compare, a branch and a
// call with the file's name (a string in flash, relative to the source tree) and the line: no
// RAM. unit.contract shows a broken one stopping the host build with the file and line.
//
// A condition must have no side effect: FW_CFG_ASSERT 0 (in FW_CONFIG_FILE or -D) compiles
// every FW_ASSERT out, condition included, as Q_NASSERT does for Q_ASSERT and LFS_NO_ASSERT for
// LFS_ASSERT. Keep a call's result in a FW_UNUSED variable and assert on the variable.
#ifndef FW_ASSERT_H
#define FW_ASSERT_H

#include "fw/fw_user_config.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifndef FW_CFG_ASSERT
#define FW_CFG_ASSERT 1
#endif

#if FW_CFG_ASSERT
#define FW_ASSERT(cond) ((cond) ? (void)0 : fw_assert_failed(__FILE__, __LINE__))
#else
#define FW_ASSERT(cond) ((void)0)
#endif

/// Called with the source file and line of the failed FW_ASSERT. May log, reset or longjmp out
/// (a test's way to check that an assertion fires); if it returns, fw_assert_failed() stops.
typedef void (*fw_assert_handler_t)(const char *file, int line);

/// Installs the handler every failed assertion goes to (NULL: the default stop). Returns the
/// handler it replaces.
fw_assert_handler_t fw_assert_set_handler(fw_assert_handler_t handler);

/// Where FW_ASSERT goes when its condition is false. Does not return.
#if defined(__GNUC__)
__attribute__((noreturn))
#endif
void fw_assert_failed(const char *file, int line);

#ifdef __cplusplus
}
#endif

#endif // FW_ASSERT_H
