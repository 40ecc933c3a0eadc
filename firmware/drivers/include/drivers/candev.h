// SPDX-License-Identifier: MIT
// dynaqpc drivers: every device on the bus, as the firmware sees it, behind one receive call.
//
//   static candev_t bus;                               // fixed memory
//   candev_init(&bus);
//   hal_can_init(500000, candev_rx_ids, CANDEV_RX_ID_COUNT, on_rx_isr, ctx);  // ISR posts frames
//   ...in the task that drains the posted frames:
//   switch (candev_rx(&bus, &frame, rx_time_us, &cmd)) { case CANDEV_RX_TOOL_CMD: ...act on cmd }
//   ...each control period:
//   if (can_link_rx_silent(&bus.motor.rx, now, 3 * 48000)) { motor silent: safe stop }
//   motor_encode_cmd(&bus.motor, &cmd, &f); hal_can_send(&f);
//
// Context: one thread (not the ISR: decode outside the interrupt). Nothing blocks.
#ifndef DRIVERS_CANDEV_H
#define DRIVERS_CANDEV_H

#include <stdint.h>

#include "drivers/gps.h"
#include "drivers/gyro.h"
#include "drivers/motor.h"
#include "drivers/ranges.h"
#include "drivers/telemetry.h"
#include "hal/hal_can.h"

#ifdef __cplusplus
extern "C" {
#endif

/// What candev_rx() did with a frame (>= 0), or a negative fw_err_t.
enum candev_rx_result {
    CANDEV_RX_MOTOR = 0,     ///< bus.motor.status updated
    CANDEV_RX_GYRO = 1,      ///< bus.gyro updated (heading integrated)
    CANDEV_RX_IR = 2,        ///< bus.ranges.ir_* updated
    CANDEV_RX_SONAR = 3,     ///< bus.ranges.sonar_mm updated: a scan's three frames are in
    CANDEV_RX_GPS = 4,       ///< bus.gps.pose updated
    CANDEV_RX_TOOL_CMD = 5,  ///< a new operator command in *cmd
    CANDEV_RX_IGNORED = 6,   ///< a frame not for the firmware (its own, or an unknown id): counted
    CANDEV_RX_SONAR_PART = 7, ///< a sonar frame kept; its scan waits for its other parts
};

/// Standard ids the firmware receives (for hal_can_init's acceptance filter).
#define CANDEV_RX_ID_COUNT 8u
extern const uint32_t candev_rx_ids[CANDEV_RX_ID_COUNT];

typedef struct candev {
    motor_t motor;
    gyro_t gyro;
    ranges_t ranges;
    gps_t gps;
    tlm_t tlm;              ///< the firmware's transmit counters and TOOL_CMD receive state
    uint32_t ignored;       ///< frames with an id the firmware does not receive
} candev_t;

void candev_init(candev_t *bus);

/// Decodes one received frame (received at `now_us`) into the device it comes from. Returns an
/// enum candev_rx_result, or FW_ERR_INVAL (malformed: counted in that device's rx.malformed) or
/// FW_ERR_NOENT (repeated counter: ignored, counted). `cmd` receives a TOOL_CMD; it may be NULL
/// when the app takes no commands (a TOOL_CMD is then counted and ignored).
int candev_rx(candev_t *bus, const hal_can_frame_t *frame, uint64_t now_us, tlm_tool_cmd_t *cmd);

#ifdef __cplusplus
}
#endif

#endif // DRIVERS_CANDEV_H
