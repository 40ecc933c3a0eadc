// SPDX-License-Identifier: MIT
// dynaqpc drivers: the simulated robot's pose source (GPS_POSE, 96 ms).
// Context: one thread; nothing blocks.
#ifndef DRIVERS_GPS_H
#define DRIVERS_GPS_H

#include <stdint.h>

#include "drivers/can_link.h"
#include "hal/hal_can.h"

#ifdef __cplusplus
extern "C" {
#endif

/// GPS_POSE Fix values.
enum gps_fix { GPS_FIX_NONE = 0, GPS_FIX_POOR = 1, GPS_FIX_GOOD = 2 };

typedef struct gps_pose {
    int16_t x_mm;           ///< arena frame: origin lower-left corner, x east, y north
    int16_t y_mm;
    uint16_t heading_cdeg;  ///< 0..35999, 0.01 deg, counter-clockwise from +x
    uint8_t fix;            ///< enum gps_fix
} gps_pose_t;

typedef struct gps {
    gps_pose_t pose;  ///< last accepted GPS_POSE
    can_link_rx_t rx;
} gps_t;

void gps_init(gps_t *gps);

/// Decodes GPS_POSE. FW_OK, FW_ERR_INVAL (malformed: a Crc that fails, heading > 35999, fix 3,
/// counted in rx.malformed; a counter jump over CAN_LINK_MAX_STEP, counted in rx.implausible) or
/// FW_ERR_NOENT.
int gps_rx_pose(gps_t *gps, const hal_can_frame_t *frame, uint64_t now_us);

/// Device side: builds GPS_POSE. FW_OK or FW_ERR_INVAL.
int gps_encode_pose(uint8_t *counter, const gps_pose_t *pose, hal_can_frame_t *out);

#ifdef __cplusplus
}
#endif

#endif // DRIVERS_GPS_H
