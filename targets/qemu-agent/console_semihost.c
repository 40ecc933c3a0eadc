// SPDX-License-Identifier: MIT
// dynaqpc qemu-agent on the emulator: the console is the STM32F4 family's semihosting
// (hal/ports/stm32f4/src/semihost.c; no newlib stdio: its printf family links an allocator).
#include "console.h"

#include "stm32f4/semihost.h"

void console_puts(const char *s)
{
    semihost_puts(s);
}

void console_put_u64(uint64_t v)
{
    semihost_put_u64(v);
}

void console_kv(const char *key, uint64_t v)
{
    semihost_kv(key, v);
}

void console_exit(uint32_t status)
{
    semihost_exit(status);
}
