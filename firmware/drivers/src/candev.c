// SPDX-License-Identifier: MIT
// dynaqpc drivers: receive dispatch by identifier (see candev.h).
#include "drivers/candev.h"

#include "dynaqpc_can.h"
#include "fw/fw_base.h"

const uint32_t candev_rx_ids[CANDEV_RX_ID_COUNT] = {
    DYNAQPC_CAN_TOOL_CMD_FRAME_ID,       DYNAQPC_CAN_MOTOR_STATUS_FRAME_ID,
    DYNAQPC_CAN_GYRO_RATE_FRAME_ID,      DYNAQPC_CAN_IR_RANGES_FRAME_ID,
    DYNAQPC_CAN_SONAR_RANGES_A_FRAME_ID, DYNAQPC_CAN_SONAR_RANGES_B_FRAME_ID,
    DYNAQPC_CAN_GPS_POSE_FRAME_ID,       DYNAQPC_CAN_SONAR_RANGES_C_FRAME_ID,
};

void candev_init(candev_t *bus)
{
    FW_ASSERT(bus != NULL);
    motor_init(&bus->motor);
    gyro_init(&bus->gyro);
    ranges_init(&bus->ranges);
    gps_init(&bus->gps);
    tlm_init(&bus->tlm);
    bus->ignored = 0u;
}

static int done(int err, int what)
{
    return err == FW_OK ? what : err;
}

int candev_rx(candev_t *bus, const hal_can_frame_t *frame, uint64_t now_us, tlm_tool_cmd_t *cmd)
{
    FW_ASSERT(bus != NULL && frame != NULL);
    if ((frame->flags & HAL_CAN_FLAG_EXTENDED) != 0u) {
        bus->ignored++;
        return CANDEV_RX_IGNORED;
    }
    switch (frame->id) {
    case DYNAQPC_CAN_MOTOR_STATUS_FRAME_ID:
        return done(motor_rx_status(&bus->motor, frame, now_us), CANDEV_RX_MOTOR);
    case DYNAQPC_CAN_GYRO_RATE_FRAME_ID:
        return done(gyro_rx_rate(&bus->gyro, frame, now_us), CANDEV_RX_GYRO);
    case DYNAQPC_CAN_IR_RANGES_FRAME_ID:
        return done(ranges_rx_ir(&bus->ranges, frame, now_us), CANDEV_RX_IR);
    case DYNAQPC_CAN_SONAR_RANGES_A_FRAME_ID:
    case DYNAQPC_CAN_SONAR_RANGES_B_FRAME_ID:
    case DYNAQPC_CAN_SONAR_RANGES_C_FRAME_ID: {
        const int err = ranges_rx_sonar(&bus->ranges, frame, now_us);
        return err == RANGES_SONAR_PART ? CANDEV_RX_SONAR_PART : done(err, CANDEV_RX_SONAR);
    }
    case DYNAQPC_CAN_GPS_POSE_FRAME_ID:
        return done(gps_rx_pose(&bus->gps, frame, now_us), CANDEV_RX_GPS);
    case DYNAQPC_CAN_TOOL_CMD_FRAME_ID: {
        tlm_tool_cmd_t scratch;
        int err = tlm_rx_tool_cmd(&bus->tlm, frame, now_us, cmd != NULL ? cmd : &scratch);
        if (err == FW_OK && cmd == NULL) {
            bus->ignored++;
            return CANDEV_RX_IGNORED;
        }
        return done(err, CANDEV_RX_TOOL_CMD);
    }
    default:
        bus->ignored++;
        return CANDEV_RX_IGNORED;
    }
}
