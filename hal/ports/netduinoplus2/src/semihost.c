// SPDX-License-Identifier: MIT
// dynaqpc netduinoplus2 board: the console over ARM semihosting ("Semihosting for AArch32 and
// AArch64", v2: BKPT 0xAB, the operation in r0, its argument block in r1). No newlib stdio (its
// printf family links an allocator). QEMU must run with -semihosting-config enable=on: without a
// debugger the BKPT would fault, so only the emulated board has this.
#include <stdint.h>

#include "netduinoplus2/board.h"

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

void nd2_puts(const char *s)
{
    (void)call_(SYS_WRITE0, s);
}

void nd2_kv(const char *key, uint64_t v)
{
    char buf[72];
    uint32_t n = 0;
    while (key[n] != '\0' && n < 40u) {
        buf[n] = key[n];
        n++;
    }
    buf[n++] = '=';
    char digits[21];
    uint32_t d = 0;
    do {
        digits[d++] = (char)('0' + (int)(v % 10u));
        v /= 10u;
    } while (v != 0u);
    while (d > 0u) {
        buf[n++] = digits[--d];
    }
    buf[n++] = ' ';
    buf[n] = '\0';
    nd2_puts(buf);
}

void nd2_cmdline(char *buf, uint32_t cap)
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

void nd2_exit(uint32_t status)
{
    const uint32_t block[2] = {ADP_STOPPED_APPLICATION_EXIT, status};
    (void)call_(SYS_EXIT_EXTENDED, block);
    for (;;) {
    }
}
