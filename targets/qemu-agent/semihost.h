// SPDX-License-Identifier: MIT
// dynaqpc QEMU images: console output and exit through ARM semihosting (no newlib stdio: its
// printf family links an allocator). Needs QEMU's -semihosting-config enable=on; on a board
// without a debugger attached the BKPT would fault, so only the emulator images use this.
#ifndef SEMIHOST_H
#define SEMIHOST_H

#include <stdint.h>

void semihost_puts(const char *s);
void semihost_put_u64(uint64_t v);
void semihost_put_i64(int64_t v);
/// key=value and a space, e.g. "steps=12 ".
void semihost_kv(const char *key, uint64_t v);
/// Ends the emulation; `status` becomes QEMU's exit code.
__attribute__((noreturn)) void semihost_exit(uint32_t status);

#endif // SEMIHOST_H
