// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 family: console, command line and exit over ARM semihosting ("Semihosting for
// AArch32 and AArch64", v2: BKPT 0xAB with the operation in r0 and its argument in r1), for the
// images that run under QEMU (the netduinoplus2 board, targets/qemu-agent). No newlib stdio (its
// printf family links an allocator).
#include "stm32f4/semihost.h"

#define SYS_WRITE0 0x04u
#define SYS_GET_CMDLINE 0x15u
#define SYS_EXIT_EXTENDED 0x20u
#define ADP_STOPPED_APPLICATION_EXIT 0x20026u

static uint32_t call_(uint32_t op, const void *arg)
{
    register uint32_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

void semihost_puts(const char *s)
{
    (void)call_(SYS_WRITE0, s);
}

void semihost_put_u64(uint64_t v)
{
    char buf[21];
    char *p = &buf[sizeof buf - 1u];
    *p = '\0';
    do {
        *--p = (char)('0' + (int)(v % 10u));
        v /= 10u;
    } while (v != 0u);
    semihost_puts(p);
}

void semihost_put_i64(int64_t v)
{
    if (v < 0) {
        semihost_puts("-");
        semihost_put_u64((uint64_t)0 - (uint64_t)v);
    } else {
        semihost_put_u64((uint64_t)v);
    }
}

void semihost_kv(const char *key, uint64_t v)
{
    semihost_puts(key);
    semihost_puts("=");
    semihost_put_u64(v);
    semihost_puts(" ");
}

void semihost_cmdline(char *buf, uint32_t cap)
{
    if (cap == 0u) {
        return;
    }
    buf[0] = '\0';
    uint32_t block[2] = {(uint32_t)(uintptr_t)buf, cap};
    if (call_(SYS_GET_CMDLINE, block) != 0u) {
        buf[0] = '\0';
    }
    buf[cap - 1u] = '\0';
}

void semihost_exit(uint32_t status)
{
    const uint32_t block[2] = {ADP_STOPPED_APPLICATION_EXIT, status};
    (void)call_(SYS_EXIT_EXTENDED, block);
    for (;;) {
    }
}
