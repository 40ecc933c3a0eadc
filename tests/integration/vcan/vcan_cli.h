// SPDX-License-Identifier: MIT
// Shared by vcan-send and vcan-dump: frames in can-utils' cansend notation.
//   123#0102AB      standard id (3 hex digits), data bytes in hex
//   1ABCDE00#01     extended id (8 hex digits)
//   123#R4          remote frame asking for 4 bytes
#ifndef VCAN_CLI_H
#define VCAN_CLI_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fw/fw_util.h"
#include "hal/hal_can.h"

/// Returns 0 and fills *f, or -1 when `s` is not cansend notation.
static inline int cli_parse_frame_(const char *s, hal_can_frame_t *f)
{
    const char *hash = strchr(s, '#');
    size_t id_len = hash ? (size_t)(hash - s) : 0u;
    memset(f, 0, sizeof *f);
    if (hash == NULL || (id_len != 3u && id_len != 8u)) {
        return -1;
    }
    for (size_t i = 0; i < id_len; i++) {
        int v = fw_hex_digit(s[i]);
        if (v < 0) {
            return -1;
        }
        f->id = (f->id << 4) | (uint32_t)v;
    }
    if (id_len == 8u) {
        f->flags |= HAL_CAN_FLAG_EXTENDED;
    }
    if (f->id > (id_len == 8u ? HAL_CAN_EXT_ID_MAX : HAL_CAN_STD_ID_MAX)) {
        return -1;
    }
    const char *d = hash + 1;
    if (*d == 'R') {
        f->flags |= HAL_CAN_FLAG_REMOTE;
        f->dlc = d[1] ? (uint8_t)(d[1] - '0') : 0u;
        return (d[1] && (d[2] || f->dlc > HAL_CAN_MAX_DLC)) ? -1 : 0;
    }
    while (d[0] && d[1] && f->dlc < HAL_CAN_MAX_DLC) {
        int hi = fw_hex_digit(d[0]), lo = fw_hex_digit(d[1]);
        if (hi < 0 || lo < 0) {
            return -1;
        }
        f->data[f->dlc++] = (uint8_t)(hi * 16 + lo);
        d += 2;
    }
    return *d ? -1 : 0;
}

static inline void cli_print_frame_(FILE *out, const hal_can_frame_t *f)
{
    if (f->flags & HAL_CAN_FLAG_EXTENDED) {
        fprintf(out, "%08X#", (unsigned)f->id);
    } else {
        fprintf(out, "%03X#", (unsigned)f->id);
    }
    if (f->flags & HAL_CAN_FLAG_REMOTE) {
        fprintf(out, "R%u", (unsigned)f->dlc);
    } else {
        for (unsigned i = 0; i < f->dlc; i++) {
            fprintf(out, "%02X", (unsigned)f->data[i]);
        }
    }
    fputc('\n', out);
}

#endif // VCAN_CLI_H
