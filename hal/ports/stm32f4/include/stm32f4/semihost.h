// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 family: console output, the command line and exit through ARM semihosting (no
// newlib stdio: its printf family links an allocator). Needs QEMU's -semihosting-config
// enable=on; on a board without a debugger attached the BKPT would fault, so only the emulated
// images use this (boards/netduinoplus2, targets/qemu-agent).
#ifndef STM32F4_SEMIHOST_H
#define STM32F4_SEMIHOST_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

void semihost_puts(const char *s);
void semihost_put_u64(uint64_t v);
void semihost_put_i64(int64_t v);
/// key=value and a space, e.g. "steps=12 ".
void semihost_kv(const char *key, uint64_t v);
/// The command line QEMU passes with -append (up to cap - 1 bytes, NUL-terminated); "" if none.
void semihost_cmdline(char *buf, uint32_t cap);
/// Ends the emulation; `status` becomes QEMU's exit code.
__attribute__((noreturn)) void semihost_exit(uint32_t status);

#ifdef __cplusplus
}
#endif

#endif  // STM32F4_SEMIHOST_H
