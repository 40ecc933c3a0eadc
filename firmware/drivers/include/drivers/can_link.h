// SPDX-License-Identifier: MIT
// dynaqpc drivers: what every frame of docs/dynaqpc.dbc shares — the 4-bit rolling counter, the
// CRC-8 of the command frames, and the receive bookkeeping of one periodic frame.
//
// Context: all functions are plain computations on caller-owned structs; call them from one
// thread (the task that drains the CAN event queue). None blocks.
#ifndef DRIVERS_CAN_LINK_H
#define DRIVERS_CAN_LINK_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "hal/hal_can.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Rolling counters count 0..15 and wrap.
#define CAN_LINK_COUNTER_MOD 16u

/// Receive bookkeeping of one periodic frame.
typedef struct can_link_rx {
    uint32_t frames;     ///< frames accepted
    uint32_t malformed;  ///< frames rejected: wrong dlc, extended/remote, value out of range, CRC
    uint32_t lost;       ///< frames missed, from counter gaps (a gap of k counts k - 1 frames)
    uint32_t repeated;   ///< frames rejected because their counter did not advance (stuck sender)
    uint64_t last_ok_us; ///< receive time of the last accepted frame (valid once `seen`)
    uint8_t counter;     ///< counter of the last accepted frame
    bool seen;           ///< a frame has been accepted since init
} can_link_rx_t;

/// CRC-8/SAE-J1850 (poly 0x1D, init 0xFF, xorout 0xFF) over the identifier, low byte then high
/// byte, followed by `len` data bytes. The command frames carry it in their Crc signal.
uint8_t can_link_crc8(uint32_t id, const uint8_t *data, size_t len);

/// CRC-32 (IEEE 802.3, reflected, as zlib's crc32()) over the identifier, low byte then high
/// byte, then `len` data bytes: TOOL_CMD's 32-bit Crc, which no random frame passes with a
/// probability above 2^-32 (docs/can-protocol.md).
uint32_t can_link_crc32(uint32_t id, const uint8_t *data, size_t len);

/// Clears `rx` (nothing seen).
void can_link_rx_init(can_link_rx_t *rx);

/// True when `frame` is a classic data frame with a standard id and exactly `dlc` bytes.
bool can_link_frame_is(const hal_can_frame_t *frame, uint32_t id, uint8_t dlc);

/// Checks the rolling `counter` of a frame received at `now_us` whose content is already known
/// good. Returns FW_OK (accepted: count, timestamp and gap bookkeeping updated) or FW_ERR_NOENT
/// (counter repeated: the frame is stale and must be ignored; counted in `repeated`).
/// The first frame after init is accepted whatever its counter. A gap of 16 or more frames
/// cannot be seen by a 4-bit counter; the app sees it as silence (can_link_rx_silent).
int can_link_rx_accept(can_link_rx_t *rx, uint8_t counter, uint64_t now_us);

/// Counts a malformed frame. Always returns FW_ERR_INVAL, for `return can_link_rx_reject(rx);`.
int can_link_rx_reject(can_link_rx_t *rx);

/// True when no frame was accepted within `max_age_us` before `now_us` (or ever).
bool can_link_rx_silent(const can_link_rx_t *rx, uint64_t now_us, uint64_t max_age_us);

/// Returns the counter value to send and advances `*counter` (modulo 16).
uint8_t can_link_tx_counter_next(uint8_t *counter);

/// Fills the header of a standard-id data frame and zeroes its data bytes.
void can_link_frame_prepare(hal_can_frame_t *frame, uint32_t id, uint8_t dlc);

#ifdef __cplusplus
}
#endif

#endif // DRIVERS_CAN_LINK_H
