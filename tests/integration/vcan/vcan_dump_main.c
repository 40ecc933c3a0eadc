// SPDX-License-Identifier: MIT
// vcan-dump: prints the virtual CAN bus's frames in cansend notation, one per line.
//   vcan-dump [--port P] [--count N] [--timeout-ms T]
// Prints "ready" once it has joined the bus, then frames; stops after N frames (exit 0) or T ms
// without a frame (exit 0 without --count, 1 if fewer than N arrived). Counters go to stderr.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vcan.h"
#include "vcan_cli.h"

int main(int argc, char **argv)
{
    vcan_config_t cfg;
    vcan_t bus;
    long count = -1, timeout_ms = 5000;
    vcan_default_config(&cfg);
    for (int i = 1; i < argc; i += 2) {
        long v = i + 1 < argc ? strtol(argv[i + 1], NULL, 0) : -1;
        if (strcmp(argv[i], "--port") == 0 && v > 0 && v < 65536) {
            cfg.port = (uint16_t)v;
        } else if (strcmp(argv[i], "--count") == 0 && v > 0) {
            count = v;
        } else if (strcmp(argv[i], "--timeout-ms") == 0 && v >= 0) {
            timeout_ms = v;
        } else {
            fprintf(stderr, "usage: vcan-dump [--port P] [--count N] [--timeout-ms T]\n");
            return 2;
        }
    }
    if (vcan_open(&bus, &cfg) != FW_OK) {
        perror("vcan-dump: vcan_open");
        return 1;
    }
    printf("ready\n");
    fflush(stdout);
    long got = 0;
    hal_can_frame_t f;
    int rc;
    while ((count < 0 || got < count) && (rc = vcan_recv(&bus, &f, (int)timeout_ms)) == 1) {
        cli_print_frame_(stdout, &f);
        fflush(stdout);
        got++;
    }
    vcan_stats_t st;
    vcan_get_stats(&bus, &st);
    fprintf(stderr, "vcan-dump: %u frames, %u malformed, %u unsupported\n", (unsigned)st.rx_frames,
            (unsigned)st.rx_malformed, (unsigned)st.rx_unsupported);
    vcan_close(&bus);
    return (count >= 0 && got < count) ? 1 : 0;
}
