// SPDX-License-Identifier: MIT
// can_vectors: the firmware's CAN codecs behind a line protocol, so that tests/python/
// test_codecs.py can hold them against cantools' reading of docs/dynaqpc.dbc.
//
//   decode <id hex> <data hex>      ->  OK <FRAME> <Signal>=<physical value> ...   |  ERR <code>
//   encode <FRAME> <Signal>=<v> ... ->  OK <id hex> <data hex>                      |  ERR <code>
//
// Decoding goes through the same calls the firmware (candev_rx) or a tool (tlm_decode_*,
// motor_decode_cmd) makes, each frame into fresh state; values are printed in the DBC's physical
// units, converted from the drivers' own units, so a scaling slip on either side shows.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "drivers/candev.h"
#include "dynaqpc_can.h"
#include "fw/fw_base.h"

static int parse_frame(const char *id_s, const char *hex, hal_can_frame_t *f)
{
    memset(f, 0, sizeof *f);
    f->id = (uint32_t)strtoul(id_s, NULL, 16);
    size_t n = strlen(hex);
    if (n % 2u != 0u || n / 2u > 8u) {
        return -1;
    }
    f->dlc = (uint8_t)(n / 2u);
    for (size_t i = 0; i < f->dlc; i++) {
        char b[3] = {hex[2 * i], hex[2 * i + 1], 0};
        f->data[i] = (uint8_t)strtoul(b, NULL, 16);
    }
    return 0;
}

static void decode(const hal_can_frame_t *f)
{
    static candev_t bus;  // fresh per frame
    candev_init(&bus);
    tlm_tool_cmd_t cmd;
    int rc;
    switch (f->id) {
    case DYNAQPC_CAN_MOTOR_CMD_FRAME_ID: {
        motor_cmd_t m;
        uint8_t counter;
        rc = motor_decode_cmd(f, &m, &counter);
        if (rc == FW_OK) {
            printf("OK MOTOR_CMD SpeedLeft=%d SpeedRight=%d Enable=%d Counter=%u\n", m.speed_left_mm_s,
                   m.speed_right_mm_s, m.enable, counter);
            return;
        }
        break;
    }
    case DYNAQPC_CAN_TLM_POSE_FRAME_ID: {
        tlm_pose_t p;
        if ((rc = tlm_decode_pose(f, &p)) == FW_OK) {
            printf("OK TLM_POSE X=%d Y=%d Heading=%.2f FixState=%u\n", (int)p.x_mm, (int)p.y_mm,
                   p.heading_cdeg / 100.0, p.fix_state);
            return;
        }
        break;
    }
    case DYNAQPC_CAN_TLM_LEARN_FRAME_ID: {
        tlm_learn_t l;
        if ((rc = tlm_decode_learn(f, &l)) == FW_OK) {
            printf("OK TLM_LEARN State=%u Action=%u Reward=%d Episode=%u Step=%u\n", (unsigned)l.state,
                   l.action, (int)l.reward, (unsigned)l.episode, (unsigned)l.step);
            return;
        }
        break;
    }
    case DYNAQPC_CAN_TLM_SCHED_FRAME_ID: {
        tlm_sched_t s;
        if ((rc = tlm_decode_sched(f, &s)) == FW_OK) {
            printf("OK TLM_SCHED PlanUpdates=%u DeadlineMisses=%u IdlePercent=%.1f QueueLength=%u\n",
                   (unsigned)s.plan_updates, (unsigned)s.deadline_misses, s.idle_permille / 10.0,
                   (unsigned)s.queue_length);
            return;
        }
        break;
    }
    case DYNAQPC_CAN_TLM_EPISODE_FRAME_ID: {
        tlm_episode_t e;
        if ((rc = tlm_decode_episode(f, &e)) == FW_OK) {
            printf("OK TLM_EPISODE Episode=%u Steps=%u TotalReward=%d ReachedGoal=%d Bumps=%u Interrupted=%d\n",
                   (unsigned)e.episode, (unsigned)e.steps, (int)e.total_reward, e.reached_goal,
                   (unsigned)e.bumps, e.interrupted);
            return;
        }
        break;
    }
    case DYNAQPC_CAN_TLM_VALUE_FRAME_ID: {
        tlm_value_t v;
        if ((rc = tlm_decode_value(f, &v)) == FW_OK) {
            printf("OK TLM_VALUE State=%lu Action=%u Value=%.1f Aliasing=%u\n", (unsigned long)v.state, v.action,
                   v.value, v.aliasing);
            return;
        }
        break;
    }
    case DYNAQPC_CAN_TOOL_ACK_FRAME_ID: {
        tlm_ack_t a;
        if ((rc = tlm_decode_ack(f, &a)) == FW_OK) {
            printf("OK TOOL_ACK Command=%u Counter=%u Result=%u Reason=%u Sequence=%lu Episodes=%lu\n", a.command,
                   a.counter, a.result, a.reason, (unsigned long)a.sequence, (unsigned long)a.episodes);
            return;
        }
        break;
    }
    case DYNAQPC_CAN_FW_STATUS_FRAME_ID: {
        tlm_status_t s;
        if ((rc = tlm_decode_status(f, &s)) == FW_OK) {
            printf("OK FW_STATUS Mode=%u ErrMotorSilent=%d ErrGyroSilent=%d ErrRangeSilent=%d "
                   "ErrPoseLost=%d ErrCanBus=%d ErrUart=%d ErrFlash=%d ErrDeadlineMiss=%d Uptime=%u "
                   "PoseTrusted=%d TrustReason=%u ResetCause=%u BootCount=%u\n",
                   s.mode, !!(s.errors & TLM_ERR_MOTOR_SILENT), !!(s.errors & TLM_ERR_GYRO_SILENT),
                   !!(s.errors & TLM_ERR_RANGE_SILENT), !!(s.errors & TLM_ERR_POSE_LOST),
                   !!(s.errors & TLM_ERR_CAN_BUS), !!(s.errors & TLM_ERR_UART),
                   !!(s.errors & TLM_ERR_FLASH), !!(s.errors & TLM_ERR_DEADLINE_MISS),
                   (unsigned)s.uptime_s, s.pose_trusted, s.trust_reason, s.reset_cause,
                   (unsigned)s.boot_count);
            return;
        }
        break;
    }
    default:
        rc = candev_rx(&bus, f, 1000u, &cmd);
        switch (rc) {
        case CANDEV_RX_MOTOR: {
            const motor_status_t *s = &bus.motor.status;
            printf("OK MOTOR_STATUS SpeedLeft=%d SpeedRight=%d BumpFront=%d BumpRear=%d "
                   "FaultOverCurrent=%d FaultStall=%d FaultUnderVoltage=%d FaultCmdTimeout=%d "
                   "Enabled=%d Counter=%u\n",
                   s->speed_left_mm_s, s->speed_right_mm_s, s->bump_front, s->bump_rear,
                   !!(s->faults & MOTOR_FAULT_OVERCURRENT), !!(s->faults & MOTOR_FAULT_STALL),
                   !!(s->faults & MOTOR_FAULT_UNDERVOLTAGE), !!(s->faults & MOTOR_FAULT_CMD_TIMEOUT),
                   s->enabled, bus.motor.rx.counter);
            return;
        }
        case CANDEV_RX_GYRO:
            printf("OK GYRO_RATE YawRate=%.2f Temperature=%d Status=%u Counter=%u\n",
                   bus.gyro.rate_cdeg_s / 100.0, bus.gyro.temperature_c, bus.gyro.status,
                   bus.gyro.rx.counter);
            return;
        case CANDEV_RX_IR: {
            const ranges_t *r = &bus.ranges;
            printf("OK IR_RANGES RangeLeft=%u RangeFront=%u RangeRight=%u ValidLeft=%d ValidFront=%d "
                   "ValidRight=%d Counter=%u\n",
                   r->ir_mm[0], r->ir_mm[1], r->ir_mm[2], r->ir_valid[0], r->ir_valid[1],
                   r->ir_valid[2], r->ir_rx.counter);
            return;
        }
        case CANDEV_RX_SONAR_PART: {  // one frame into fresh state: a part, kept for its scan
            const unsigned part = f->id - DYNAQPC_CAN_SONAR_RANGES_A_FRAME_ID;
            const unsigned first = part * 7u;
            const unsigned n = part < 2u ? 7u : RANGES_SONAR_COUNT - 14u;
            printf("OK SONAR_RANGES_%c", 'A' + part);
            for (unsigned i = first; i < first + n; i++) {
                printf(" Sonar%u=%.1f", i, bus.ranges.sonar_raw[i] * 2.0);
            }
            printf(" Counter=%u\n", bus.ranges.sonar_counter);
            return;
        }
        case CANDEV_RX_GPS: {
            const gps_pose_t *p = &bus.gps.pose;
            printf("OK GPS_POSE X=%d Y=%d Heading=%.2f Fix=%u Counter=%u\n", p->x_mm, p->y_mm,
                   p->heading_cdeg / 100.0, p->fix, bus.gps.rx.counter);
            return;
        }
        case CANDEV_RX_TOOL_CMD:
            printf("OK TOOL_CMD Command=%u Argument=%lu Counter=%u\n", cmd.command,
                   (unsigned long)cmd.argument, bus.tlm.tool_rx.counter);
            return;
        default:
            break;
        }
    }
    printf("ERR %d\n", rc);
}

/// Value of `key` among "K=V" tokens, or `def`.
static double arg(int argc, char **argv, const char *key, double def)
{
    size_t n = strlen(key);
    for (int i = 0; i < argc; i++) {
        if (strncmp(argv[i], key, n) == 0 && argv[i][n] == '=') {
            return strtod(argv[i] + n + 1, NULL);
        }
    }
    return def;
}

static void encode(const char *name, int argc, char **argv)
{
    hal_can_frame_t f;
    int rc = FW_ERR_INVAL;
    uint8_t counter = (uint8_t)arg(argc, argv, "Counter", 0);
    tlm_t tlm;
    tlm_init(&tlm);
    tlm.pose_counter = tlm.learn_counter = tlm.sched_counter = tlm.status_counter = tlm.value_counter = counter;
#define A(k) arg(argc, argv, k, 0)
    if (strcmp(name, "MOTOR_CMD") == 0) {
        motor_t m;
        motor_init(&m);
        m.tx_counter = counter;
        motor_cmd_t c = {(int16_t)A("SpeedLeft"), (int16_t)A("SpeedRight"), A("Enable") != 0};
        rc = motor_encode_cmd(&m, &c, &f);
    } else if (strcmp(name, "MOTOR_STATUS") == 0) {
        motor_status_t s = {(int16_t)A("SpeedLeft"), (int16_t)A("SpeedRight"), A("BumpFront") != 0,
                            A("BumpRear") != 0, A("Enabled") != 0,
                            (uint8_t)((A("FaultOverCurrent") != 0 ? MOTOR_FAULT_OVERCURRENT : 0u) |
                                      (A("FaultStall") != 0 ? MOTOR_FAULT_STALL : 0u) |
                                      (A("FaultUnderVoltage") != 0 ? MOTOR_FAULT_UNDERVOLTAGE : 0u) |
                                      (A("FaultCmdTimeout") != 0 ? MOTOR_FAULT_CMD_TIMEOUT : 0u))};
        rc = motor_encode_status(&counter, &s, &f);
    } else if (strcmp(name, "GYRO_RATE") == 0) {
        double r = A("YawRate") * 100.0;
        rc = gyro_encode_rate(&counter, (int16_t)(r < 0 ? r - 0.5 : r + 0.5), (int8_t)A("Temperature"),
                              (uint8_t)A("Status"), &f);
    } else if (strcmp(name, "IR_RANGES") == 0) {
        uint16_t mm[3] = {(uint16_t)A("RangeLeft"), (uint16_t)A("RangeFront"), (uint16_t)A("RangeRight")};
        bool valid[3] = {A("ValidLeft") != 0, A("ValidFront") != 0, A("ValidRight") != 0};
        rc = ranges_encode_ir(&counter, mm, valid, &f);
    } else if (strncmp(name, "SONAR_RANGES_", 13) == 0 && name[13] >= 'A' && name[13] <= 'C' && name[14] == 0) {
        uint16_t mm[RANGES_SONAR_COUNT];
        for (unsigned i = 0; i < RANGES_SONAR_COUNT; i++) {
            char key[16];
            snprintf(key, sizeof key, "Sonar%u", i);
            double cm = arg(argc, argv, key, 254.0);
            mm[i] = cm >= 254.0 ? RANGES_NO_ECHO : (uint16_t)(cm * 10.0 + 0.5);
        }
        hal_can_frame_t scan[RANGES_SONAR_PARTS];
        rc = ranges_encode_sonar(&counter, mm, scan);
        f = scan[name[13] - 'A'];
    } else if (strcmp(name, "GPS_POSE") == 0) {
        gps_pose_t p = {(int16_t)A("X"), (int16_t)A("Y"), (uint16_t)(A("Heading") * 100.0 + 0.5),
                        (uint8_t)A("Fix")};
        rc = gps_encode_pose(&counter, &p, &f);
    } else if (strcmp(name, "TOOL_CMD") == 0) {
        tlm_tool_cmd_t c = {(uint8_t)A("Command"), (uint32_t)A("Argument")};
        rc = tlm_encode_tool_cmd(&counter, &c, &f);
    } else if (strcmp(name, "TLM_VALUE") == 0) {
        tlm_value_t v = {(uint32_t)A("State"), (uint8_t)A("Action"), (float)A("Value"), (uint8_t)A("Aliasing")};
        tlm_encode_value(&tlm, &v, &f);
        rc = FW_OK;
    } else if (strcmp(name, "TOOL_ACK") == 0) {
        tlm_ack_t a = {(uint8_t)A("Command"), counter, (uint8_t)A("Result"), (uint8_t)A("Reason"),
                       (uint32_t)A("Sequence"), (uint32_t)A("Episodes")};
        tlm_encode_ack(&a, &f);
        rc = FW_OK;
    } else if (strcmp(name, "TLM_POSE") == 0) {
        tlm_pose_t p = {(int32_t)A("X"), (int32_t)A("Y"), (int32_t)(A("Heading") * 100.0 + 0.5),
                        (uint8_t)A("FixState")};
        tlm_encode_pose(&tlm, &p, &f);
        rc = FW_OK;
    } else if (strcmp(name, "TLM_LEARN") == 0) {
        tlm_learn_t l = {(uint32_t)A("State"), (uint8_t)A("Action"), (int32_t)A("Reward"),
                         (uint32_t)A("Episode"), (uint32_t)A("Step")};
        tlm_encode_learn(&tlm, &l, &f);
        rc = FW_OK;
    } else if (strcmp(name, "TLM_SCHED") == 0) {
        tlm_sched_t s = {(uint32_t)A("PlanUpdates"), (uint32_t)A("DeadlineMisses"),
                         (uint32_t)(A("IdlePercent") * 10.0 + 0.5), (uint32_t)A("QueueLength")};
        tlm_encode_sched(&tlm, &s, &f);
        rc = FW_OK;
    } else if (strcmp(name, "TLM_EPISODE") == 0) {
        tlm_episode_t e = {(uint32_t)A("Episode"), (uint32_t)A("Steps"), (int32_t)A("TotalReward"),
                           A("ReachedGoal") != 0, (uint32_t)A("Bumps"), A("Interrupted") != 0};
        tlm_encode_episode(&e, &f);
        rc = FW_OK;
    } else if (strcmp(name, "FW_STATUS") == 0) {
        static const char *const flags[8] = {"ErrMotorSilent", "ErrGyroSilent", "ErrRangeSilent",
                                             "ErrPoseLost", "ErrCanBus", "ErrUart", "ErrFlash",
                                             "ErrDeadlineMiss"};
        tlm_status_t s = {(uint8_t)A("Mode"), 0, (uint32_t)A("Uptime"), A("PoseTrusted") != 0,
                          (uint8_t)A("TrustReason"), (uint8_t)A("ResetCause"), (uint32_t)A("BootCount")};
        for (unsigned i = 0; i < 8u; i++) {
            s.errors |= (uint8_t)(A(flags[i]) != 0 ? 1u << i : 0u);
        }
        tlm_encode_status(&tlm, &s, &f);
        rc = FW_OK;
    }
#undef A
    if (rc != FW_OK) {
        printf("ERR %d\n", rc);
        return;
    }
    printf("OK %03X ", (unsigned)f.id);
    for (unsigned i = 0; i < f.dlc; i++) {
        printf("%02X", f.data[i]);
    }
    printf("\n");
}

int main(void)
{
    char line[1024];
    while (fgets(line, sizeof line, stdin) != NULL) {
        char *argv[64];
        int argc = 0;
        for (char *tok = strtok(line, " \t\r\n"); tok != NULL && argc < 64; tok = strtok(NULL, " \t\r\n")) {
            argv[argc++] = tok;
        }
        if (argc == 3 && strcmp(argv[0], "decode") == 0) {
            hal_can_frame_t f;
            if (parse_frame(argv[1], argv[2], &f) != 0) {
                printf("ERR bad-input\n");
            } else {
                decode(&f);
            }
        } else if (argc >= 2 && strcmp(argv[0], "encode") == 0) {
            encode(argv[1], argc - 2, argv + 2);
        } else {
            printf("ERR bad-input\n");
        }
        fflush(stdout);
    }
    return 0;
}
