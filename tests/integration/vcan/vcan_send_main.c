// SPDX-License-Identifier: MIT
// vcan-send: sends frames on the virtual CAN bus.
//   vcan-send [--port P] [--repeat N] [--gap-us U] FRAME...     (FRAME in cansend notation)
// Each FRAME is sent in order, the whole list N times, paced U us apart (default 50).
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vcan.h"
#include "vcan_cli.h"

int main(int argc, char **argv)
{
    vcan_config_t cfg;
    vcan_t bus;
    long repeat = 1;
    int first = 1;
    vcan_default_config(&cfg);
    while (first + 1 < argc && strncmp(argv[first], "--", 2) == 0) {
        long v = strtol(argv[first + 1], NULL, 0);
        if (strcmp(argv[first], "--port") == 0 && v > 0 && v < 65536) {
            cfg.port = (uint16_t)v;
        } else if (strcmp(argv[first], "--repeat") == 0 && v > 0) {
            repeat = v;
        } else if (strcmp(argv[first], "--gap-us") == 0 && v >= 0) {
            cfg.tx_gap_us = (uint32_t)v;
        } else {
            fprintf(stderr, "vcan-send: bad option %s %s\n", argv[first], argv[first + 1]);
            return 2;
        }
        first += 2;
    }
    if (first >= argc) {
        fprintf(stderr, "usage: vcan-send [--port P] [--repeat N] [--gap-us U] ID#DATA...\n");
        return 2;
    }
    for (int i = first; i < argc; i++) { // check all before sending any
        hal_can_frame_t f;
        if (cli_parse_frame_(argv[i], &f) != 0) {
            fprintf(stderr, "vcan-send: not a frame: %s (want 123#0102 or 1ABCDE00#01 or 123#R4)\n", argv[i]);
            return 2;
        }
    }
    if (vcan_open(&bus, &cfg) != FW_OK) {
        perror("vcan-send: vcan_open");
        return 1;
    }
    int rc = 0;
    for (long r = 0; r < repeat && rc == 0; r++) {
        for (int i = first; i < argc; i++) {
            hal_can_frame_t f;
            (void)cli_parse_frame_(argv[i], &f);
            if (vcan_send(&bus, &f, vcan_time_now()) != FW_OK) {
                perror("vcan-send: vcan_send");
                rc = 1;
                break;
            }
        }
    }
    vcan_close(&bus);
    return rc;
}
