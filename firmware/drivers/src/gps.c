// SPDX-License-Identifier: MIT
// dynaqpc drivers: GPS_POSE (see gps.h).
#include "drivers/gps.h"

#include <string.h>

#include "dynaqpc_can.h"
#include "fw/fw_base.h"

void gps_init(gps_t *gps)
{
    FW_ASSERT(gps != NULL);
    memset(gps, 0, sizeof *gps);
    can_link_rx_init(&gps->rx);
}

int gps_rx_pose(gps_t *gps, const hal_can_frame_t *frame, uint64_t now_us)
{
    FW_ASSERT(gps != NULL && frame != NULL);
    struct dynaqpc_can_gps_pose_t msg;
    if (!can_link_frame_is(frame, DYNAQPC_CAN_GPS_POSE_FRAME_ID, DYNAQPC_CAN_GPS_POSE_LENGTH) ||
        dynaqpc_can_gps_pose_unpack(&msg, frame->data, frame->dlc) != 0 || !can_link_e2e_ok(frame, 8u) ||
        !dynaqpc_can_gps_pose_heading_is_in_range(msg.heading) ||
        !dynaqpc_can_gps_pose_fix_is_in_range(msg.fix)) {
        return can_link_rx_reject(&gps->rx);
    }
    // No rate-of-change check: the simulator puts the robot at each episode's start.
    const int err = can_link_rx_accept_e2e(&gps->rx, msg.counter, now_us, CAN_LINK_MAX_STEP);
    if (err < 0) {
        return err;
    }
    gps->pose.x_mm = msg.x;
    gps->pose.y_mm = msg.y;
    gps->pose.heading_cdeg = msg.heading;
    gps->pose.fix = msg.fix;
    return FW_OK;
}

int gps_encode_pose(uint8_t *counter, const gps_pose_t *pose, hal_can_frame_t *out)
{
    FW_ASSERT(counter != NULL && pose != NULL && out != NULL);
    struct dynaqpc_can_gps_pose_t msg;
    memset(&msg, 0, sizeof msg);
    msg.x = pose->x_mm;
    msg.y = pose->y_mm;
    msg.heading = pose->heading_cdeg;
    msg.fix = pose->fix;
    if (!dynaqpc_can_gps_pose_heading_is_in_range(msg.heading) ||
        !dynaqpc_can_gps_pose_fix_is_in_range(msg.fix)) {
        return FW_ERR_INVAL;
    }
    msg.counter = can_link_tx_counter_next(counter);
    can_link_frame_prepare(out, DYNAQPC_CAN_GPS_POSE_FRAME_ID, DYNAQPC_CAN_GPS_POSE_LENGTH);
    return can_link_tx_seal(out, dynaqpc_can_gps_pose_pack(out->data, &msg, sizeof out->data));
}
