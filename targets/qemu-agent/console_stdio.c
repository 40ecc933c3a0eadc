// SPDX-License-Identifier: MIT
// dynaqpc qemu-agent on the host: the console is stdout.
#include "console.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>

void console_puts(const char *s)
{
    (void)fputs(s, stdout);
}

void console_put_u64(uint64_t v)
{
    (void)printf("%" PRIu64, v);
}

void console_kv(const char *key, uint64_t v)
{
    (void)printf("%s=%" PRIu64 " ", key, v);
}

void console_exit(uint32_t status)
{
    (void)fflush(stdout);
    exit((int)status);
}
