// SPDX-License-Identifier: MIT
// Breaks a contract on purpose: pq_pop() on no queue. FW_ASSERT at pq_pop's entry must stop the
// program with "…/pqueue.c:<line>: assertion failed" (check_stop.cmake runs it; unit.contract).
#include <stdio.h>

#include "agent/pqueue.h"

int main(void)
{
    uint32_t key = 0;
    (void)pq_pop(NULL, &key, NULL);
    (void)fprintf(stderr, "pq_pop(NULL) returned: the contract did not stop the program\n");
    return 0;
}
