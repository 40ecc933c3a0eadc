// SPDX-License-Identifier: MIT
// dynaqpc drivers: what every frame of docs/dynaqpc.dbc shares — the 4-bit rolling counter, the
// end-to-end check (Crc over the data id and the data) of the command frames and of the frames
// that feed estimation, and the receive bookkeeping of one periodic frame.
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
/// The largest counter step an end-to-end protected frame may take by default (AUTOSAR E2E's
/// MaxDeltaCounter): up to 2 frames lost between two accepted ones. A larger jump is refused as
/// implausible and the frame that follows it in sequence resynchronises (can_link_rx_accept_e2e).
#define CAN_LINK_MAX_STEP 3u
/// can_link_rx_accept_e2e()'s result for a frame taken to resynchronise after a refused jump.
#define CAN_LINK_RESYNC 1

/// Receive bookkeeping of one periodic frame.
typedef struct can_link_rx {
    uint32_t frames;     ///< frames accepted
    uint32_t malformed;  ///< frames rejected: wrong dlc, extended/remote, value out of range, CRC
    uint32_t lost;       ///< frames missed, from counter gaps (a gap of k counts k - 1 frames)
    uint32_t repeated;   ///< frames rejected because their counter did not advance (stuck sender)
    uint64_t last_ok_us; ///< receive time of the last accepted frame (valid once `seen`)
    uint8_t counter;     ///< counter of the last accepted frame
    bool seen;           ///< a frame has been accepted since init
    uint8_t sync_counter; ///< counter of the last frame refused as implausible (valid while sync_pending)
    bool sync_pending;   ///< a frame was refused as implausible: one in sequence after it resynchronises
    uint16_t implausible; ///< frames refused for a counter jump (can_link_rx_accept_e2e); saturated
} can_link_rx_t;

/// CRC-8/SAE-J1850 (poly 0x1D, init 0xFF, xorout 0xFF) over the identifier, low byte then high
/// byte, followed by `len` data bytes. The command frames carry it in their Crc signal.
uint8_t can_link_crc8(uint32_t id, const uint8_t *data, size_t len);

/// CRC-32 (IEEE 802.3, reflected, as zlib's crc32()) over the identifier, low byte then high
/// byte, then `len` data bytes: TOOL_CMD's 32-bit Crc, which no random frame passes with a
/// probability above 2^-32 (docs/can-protocol.md).
uint32_t can_link_crc32(uint32_t id, const uint8_t *data, size_t len);

/// End-to-end check of a received frame whose Crc ends it: the last byte is can_link_crc8() over
/// the id and the bytes before it (Counter included: AUTOSAR E2E profile 1 style, the frame id as
/// data id). `crc_bits` is the Crc's width: 8, the only one the frames use (any other: false).
/// True when it matches.
bool can_link_e2e_ok(const hal_can_frame_t *frame, unsigned crc_bits);

/// Sender side: writes the Crc that can_link_e2e_ok() checks into a packed frame's last byte.
/// `crc_bits` must be 8.
void can_link_e2e_protect(hal_can_frame_t *frame, unsigned crc_bits);

/// Sender side, the end of every end-to-end protected encoder: `packed` is what the generated
/// codec's pack function returned for `frame->data` (the frame prepared by
/// can_link_frame_prepare(), the message's Counter set). When it packed exactly `frame->dlc`
/// bytes, writes the 8-bit Crc (can_link_e2e_protect) and returns FW_OK; otherwise returns
/// FW_ERR_INVAL and leaves the frame unsealed, not to be sent.
int can_link_tx_seal(hal_can_frame_t *frame, int packed);

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

/// can_link_rx_accept() for an end-to-end protected frame whose Crc is already checked, with the
/// counter's plausibility: a counter that jumps by more than `max_step` (2..15; CAN_LINK_MAX_STEP
/// unless the receiver bridges more) refuses the frame (FW_ERR_INVAL, counted in `implausible`,
/// nothing else changes) and remembers its counter; the next frame whose counter follows that
/// one by 1 is taken (CAN_LINK_RESYNC): the sender did jump, as a rebooted one does. A random
/// frame that passed the Crc is so taken with probability max_step/16 at most. Otherwise as
/// can_link_rx_accept(): FW_OK or FW_ERR_NOENT (repeated).
int can_link_rx_accept_e2e(can_link_rx_t *rx, uint8_t counter, uint64_t now_us, uint8_t max_step);

/// Counts a malformed frame. Always returns FW_ERR_INVAL, for `return can_link_rx_reject(rx);`.
int can_link_rx_reject(can_link_rx_t *rx);

/// A frame whose values the receiver's plausibility check refused (a rate, a speed beyond what
/// the robot can do): counted in rx->implausible (saturated), the counter not advanced, so the
/// next good frame bridges it. Returns FW_ERR_INVAL.
int can_link_rx_implausible(can_link_rx_t *rx);


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
