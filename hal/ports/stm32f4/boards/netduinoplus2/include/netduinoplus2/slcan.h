// SPDX-License-Identifier: MIT
// dynaqpc netduinoplus2 board: CAN frames over a serial line in SLCAN (Lawicel) framing, the
// ASCII protocol of CANUSB-type adapters that python-can's `slcan` interface, slcand and
// can-utils speak. Pure code (no registers, no allocation): the host tests run it.
//
//   standard data frame   tIIILDD..\r    III: 3 hex digits, L: dlc 0-8, DD: 2 hex digits a byte
//   extended data frame   TIIIIIIIILDD..\r
//   remote frames         rIIIL\r, RIIIIIIIIL\r
//   commands              O (open), C (close), L (listen), Sn (bit rate), sxxyy, V, N, F, ...:
//                         answered OK (\r); nothing else of the adapter's state matters here
// A line that is none of these, too long, or with a bad digit is an error (answered \a).
#ifndef NETDUINOPLUS2_SLCAN_H
#define NETDUINOPLUS2_SLCAN_H

#include <stddef.h>
#include <stdint.h>

#include "hal/hal_can.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The longest line: "T" + 8 id digits + dlc + 16 data digits + "\r".
#define SLCAN_MAX_LINE 27u

/// Writes the frame as one SLCAN line (with its \r) into out (at least SLCAN_MAX_LINE bytes).
/// Returns its length, or 0 for a frame that cannot be written (dlc > 8).
size_t slcan_encode(const hal_can_frame_t *frame, uint8_t *out);

typedef enum slcan_result {
    SLCAN_NONE = 0,     ///< the line goes on
    SLCAN_FRAME = 1,    ///< a frame is complete: *frame holds it
    SLCAN_COMMAND = 2,  ///< a command line is complete: answer SLCAN_OK
    SLCAN_ERROR = 3,    ///< a bad line ended (or overflowed): answer SLCAN_ERR
} slcan_result_t;

#define SLCAN_OK '\r'
#define SLCAN_ERR '\a'

typedef struct slcan_parser {
    uint8_t line[SLCAN_MAX_LINE];
    uint32_t len;
    uint32_t overflow;  ///< the current line is too long: it ends as an error
} slcan_parser_t;

void slcan_parser_init(slcan_parser_t *p);
/// Feeds one received byte. On SLCAN_FRAME, *frame is the decoded frame.
slcan_result_t slcan_feed(slcan_parser_t *p, uint8_t byte, hal_can_frame_t *frame);

#ifdef __cplusplus
}
#endif

#endif // NETDUINOPLUS2_SLCAN_H
