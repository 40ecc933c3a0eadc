// SPDX-License-Identifier: MIT
// dynaqpc netduinoplus2 board: SLCAN (Lawicel) framing of CAN frames (see slcan.h).
#include "netduinoplus2/slcan.h"

#include <stdbool.h>

#include "fw/fw_util.h"

static const char hex_[] = "0123456789ABCDEF";

static uint8_t *put_hex_(uint8_t *out, uint32_t v, uint32_t digits)
{
    for (uint32_t i = 0; i < digits; i++) {
        out[digits - 1u - i] = (uint8_t)hex_[v & 0xFu];
        v >>= 4;
    }
    return out + digits;
}

size_t slcan_encode(const hal_can_frame_t *frame, uint8_t *out)
{
    if (frame->dlc > HAL_CAN_MAX_DLC) {
        return 0u;
    }
    const bool ext = (frame->flags & HAL_CAN_FLAG_EXTENDED) != 0u;
    const bool rtr = (frame->flags & HAL_CAN_FLAG_REMOTE) != 0u;
    uint8_t *p = out;
    *p++ = (uint8_t)(rtr ? (ext ? 'R' : 'r') : (ext ? 'T' : 't'));
    p = put_hex_(p, ext ? (frame->id & 0x1FFFFFFFu) : (frame->id & 0x7FFu), ext ? 8u : 3u);
    *p++ = (uint8_t)('0' + frame->dlc);
    if (!rtr) {
        for (uint32_t i = 0; i < frame->dlc; i++) {
            p = put_hex_(p, frame->data[i], 2u);
        }
    }
    *p++ = (uint8_t)SLCAN_OK;
    return (size_t)(p - out);
}

void slcan_parser_init(slcan_parser_t *p)
{
    p->len = 0u;
    p->overflow = 0u;
}

static bool hex_field_(const uint8_t *s, uint32_t digits, uint32_t *out)
{
    uint32_t v = 0;
    for (uint32_t i = 0; i < digits; i++) {
        const int d = fw_hex_digit(s[i]);
        if (d < 0) {
            return false;
        }
        v = (v << 4) | (uint32_t)d;
    }
    *out = v;
    return true;
}

static slcan_result_t decode_(const uint8_t *s, uint32_t len, hal_can_frame_t *frame)
{
    const uint8_t kind = s[0];
    const bool ext = kind == 'T' || kind == 'R';
    const bool rtr = kind == 'r' || kind == 'R';
    const uint32_t id_digits = ext ? 8u : 3u;
    if (len < 1u + id_digits + 1u) {
        return SLCAN_ERROR;
    }
    uint32_t id = 0, dlc = 0;
    if (!hex_field_(&s[1], id_digits, &id) || !hex_field_(&s[1u + id_digits], 1u, &dlc) || dlc > 8u) {
        return SLCAN_ERROR;
    }
    if (ext ? id > 0x1FFFFFFFu : id > 0x7FFu) {
        return SLCAN_ERROR;
    }
    const uint32_t data_at = 2u + id_digits;
    if (len != data_at + (rtr ? 0u : 2u * dlc)) {
        return SLCAN_ERROR;
    }
    hal_can_frame_t f = {0};
    f.id = id;
    f.dlc = (uint8_t)dlc;
    f.flags = (uint8_t)((ext ? HAL_CAN_FLAG_EXTENDED : 0u) | (rtr ? HAL_CAN_FLAG_REMOTE : 0u));
    for (uint32_t i = 0; !rtr && i < dlc; i++) {
        uint32_t b = 0;
        if (!hex_field_(&s[data_at + 2u * i], 2u, &b)) {
            return SLCAN_ERROR;
        }
        f.data[i] = (uint8_t)b;
    }
    *frame = f;
    return SLCAN_FRAME;
}

slcan_result_t slcan_feed(slcan_parser_t *p, uint8_t byte, hal_can_frame_t *frame)
{
    if (byte != (uint8_t)SLCAN_OK) {
        if (p->len < SLCAN_MAX_LINE) {
            p->line[p->len++] = byte;
        } else {
            p->overflow = 1u;
        }
        return SLCAN_NONE;
    }
    const uint32_t len = p->len;
    const bool overflow = p->overflow != 0u;
    slcan_parser_init(p);
    if (overflow) {
        return SLCAN_ERROR;
    }
    if (len == 0u) {
        return SLCAN_NONE;  // an empty line (a bare \r, which adapters send to resync): nothing
    }
    switch (p->line[0]) {
    case 't':
    case 'T':
    case 'r':
    case 'R':
        return decode_(p->line, len, frame);
    case 'O':  // open, close, listen-only, bit rate, BTR registers, version, serial number,
    case 'C':  // status flags, time stamps, acceptance code and mask, auto-poll
    case 'L':
    case 'S':
    case 's':
    case 'V':
    case 'v':
    case 'N':
    case 'F':
    case 'Z':
    case 'M':
    case 'm':
    case 'X':
        return SLCAN_COMMAND;
    default:
        return SLCAN_ERROR;
    }
}
