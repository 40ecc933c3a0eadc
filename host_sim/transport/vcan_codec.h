// SPDX-License-Identifier: MIT
// dynaqpc host_sim transport: one CAN frame <-> one python-can `udp_multicast` datagram, a msgpack
// map with python-can's eleven keys (see vcan.h for the bus). Pure functions: no sockets, no heap.
#ifndef VCAN_CODEC_H
#define VCAN_CODEC_H

#include <stddef.h>
#include <stdint.h>

#include "fw/fw_base.h"
#include "hal/hal_can.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The longest datagram vcan_encode() writes (a classic frame with 8 data bytes and a nil
/// channel is 164 bytes).
#define VCAN_DATAGRAM_MAX 192u

/// Encodes `frame` as python-can does, keys in python-can's order, into `buf`.
/// Returns the datagram length, or FW_ERR_INVAL (bad frame or timestamp) or FW_ERR_NOMEM
/// (`cap` too small; VCAN_DATAGRAM_MAX always suffices). Pure function.
int vcan_encode(const hal_can_frame_t *frame, double timestamp, uint8_t *buf, size_t cap);

/// Decodes one datagram. Accepts what python-can's receiver accepts (any subset and order of
/// the eleven keys, python-can's defaults for missing ones, ints for the timestamp) and applies
/// python-can's checks (dlc equals the data length, remote frames carry no data, id range).
/// Returns FW_OK, FW_ERR_CORRUPT (truncated, trailing bytes, unknown or repeated key, wrong
/// type, values out of range) or FW_ERR_NOSYS (a valid CAN FD or error frame: not a classic
/// frame). `timestamp` may be NULL. Never reads outside [buf, buf + len). Pure function.
int vcan_decode(const uint8_t *buf, size_t len, hal_can_frame_t *frame, double *timestamp);

#ifdef __cplusplus
}
#endif

#endif // VCAN_CODEC_H
