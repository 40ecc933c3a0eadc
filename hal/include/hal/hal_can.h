// SPDX-License-Identifier: MIT
// dynaqpc HAL: the CAN controller (classic CAN 2.0, 8-byte frames).
//
// The robot's devices (motor controller, gyro, IR or sonar board, GPS) and the firmware talk over
// one bus; docs/dynaqpc.dbc defines every frame. The host port carries frames through in-process
// queues in lock-step, or over the virtual CAN bus (python-can udp_multicast) between processes.
#ifndef HAL_CAN_H
#define HAL_CAN_H

#include <stdbool.h>
#include <stdint.h>

#include "fw/fw_base.h"  // FW_OK and the FW_ERR_* codes the functions return

#ifdef __cplusplus
extern "C" {
#endif

#define HAL_CAN_MAX_DLC 8u
#define HAL_CAN_STD_ID_MAX 0x7FFu
#define HAL_CAN_EXT_ID_MAX 0x1FFFFFFFu

/// hal_can_frame_t.flags
#define HAL_CAN_FLAG_EXTENDED 0x01u ///< 29-bit identifier
#define HAL_CAN_FLAG_REMOTE 0x02u   ///< remote transmission request (no data)

/// One classic CAN frame.
typedef struct hal_can_frame {
    uint32_t id;     ///< 11-bit, or 29-bit with HAL_CAN_FLAG_EXTENDED
    uint8_t dlc;     ///< 0..8 data bytes
    uint8_t flags;   ///< HAL_CAN_FLAG_*
    uint8_t data[HAL_CAN_MAX_DLC];
} hal_can_frame_t;

/// Called by the port for each received frame that passes the filters.
/// Context: interrupt. Must not block; copy the frame (post it into the scheduler's event queue).
typedef void (*hal_can_rx_fn)(const hal_can_frame_t *frame, void *ctx);

/// Counters a port keeps; telemetry reports them.
typedef struct hal_can_stats {
    uint32_t tx_frames;     ///< frames handed to the controller
    uint32_t tx_dropped;    ///< hal_can_send() refusals (no free mailbox or queue slot)
    uint32_t rx_frames;     ///< frames delivered to the handler
    uint32_t rx_overruns;   ///< frames lost because the receive FIFO was full
    uint32_t bus_errors;    ///< error frames, bus-off events
} hal_can_stats_t;

/// Configures the controller at `bitrate` (bit/s; the robot's bus runs 500 kbit/s) to accept
/// only the standard ids listed (an empty list accepts every frame), delivering each to
/// `on_rx`. Returns FW_OK, FW_ERR_INVAL (bitrate not reachable, too many ids for the filter
/// bank), or FW_ERR_IO (controller did not leave initialisation mode).
/// Context: thread, at boot, before interrupts are enabled.
FW_CHECK_RETURN int hal_can_init(uint32_t bitrate, const uint32_t *accept_ids, uint32_t n_ids, hal_can_rx_fn on_rx,
                 void *ctx);

/// Queues a frame for transmission. Never blocks and never waits for the bus.
/// Returns FW_OK, FW_ERR_INVAL (bad id or dlc), or FW_ERR_FULL (every TX mailbox busy: the frame
/// is dropped and counted; periodic frames are simply sent again next cycle).
/// Context: thread or interrupt.
int hal_can_send(const hal_can_frame_t *frame);

/// A snapshot of the counters. Context: thread.
void hal_can_get_stats(hal_can_stats_t *out);

#ifdef __cplusplus
}
#endif

#endif // HAL_CAN_H
