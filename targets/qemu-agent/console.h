// SPDX-License-Identifier: MIT
// dynaqpc qemu-agent: where the program prints and how it exits. Two implementations:
// console_semihost.c (the emulator image: ARM semihosting) and console_stdio.c (its host build).
#ifndef QEMU_AGENT_CONSOLE_H
#define QEMU_AGENT_CONSOLE_H

#include <stdint.h>

void console_puts(const char *s);
void console_put_u64(uint64_t v);
/// key=value and a space, e.g. "steps=12 ".
void console_kv(const char *key, uint64_t v);
/// Ends the program; `status` becomes the exit code (QEMU's, with semihosting).
#if defined(__GNUC__)
__attribute__((noreturn))
#endif
void console_exit(uint32_t status);

#endif // QEMU_AGENT_CONSOLE_H
