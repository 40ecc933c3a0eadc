// SPDX-License-Identifier: MIT
// dynaqpc drivers: the firmware's own frames — telemetry (TLM_POSE, TLM_SCHED every control
// period; TLM_LEARN and TLM_VALUE with each real step; TLM_EPISODE at each episode end), the FW_STATUS heartbeat (1 s), the
// operator's TOOL_CMD (received) and its answer, TOOL_ACK.
//
// Encoders saturate every value to its signal's range as docs/dynaqpc.dbc documents (telemetry
// must never refuse to report), keep one rolling counter per periodic frame, and never fail.
// Decoders (tlm_decode_*) exist for host tools and tests written in C.
// Context: one thread; nothing blocks.
#ifndef DRIVERS_TELEMETRY_H
#define DRIVERS_TELEMETRY_H

#include <stdbool.h>
#include <stdint.h>

#include "drivers/can_link.h"
#include "hal/hal_can.h"

#ifdef __cplusplus
extern "C" {
#endif

/// TLM_POSE FixState; the same values as cricket_fix_state (drivers/cricket.h).
enum tlm_fix_state { TLM_FIX_FRESH = 0, TLM_FIX_STALE = 1, TLM_FIX_MOVING = 2, TLM_FIX_LOST = 3 };

/// FW_STATUS Mode.
enum tlm_mode { TLM_MODE_BOOT = 0, TLM_MODE_IDLE = 1, TLM_MODE_RUNNING = 2, TLM_MODE_SAFE_STOP = 3,
                TLM_MODE_FAULT = 4 };

/// FW_STATUS TrustReason: the values of pose_trust_reason_t (robot/pose_trust.h).
enum tlm_trust_reason { TLM_TRUST_BOOT = 0, TLM_TRUST_GYRO_GAP = 1, TLM_TRUST_FIX_JUMP = 2, TLM_TRUST_STALL = 3,
                        TLM_TRUST_OPERATOR = 4, TLM_TRUST_LEG = 5, TLM_TRUST_ABSOLUTE = 6 };

/// FW_STATUS error flags (tlm_status_t.errors).
#define TLM_ERR_MOTOR_SILENT 0x01u
#define TLM_ERR_GYRO_SILENT 0x02u
#define TLM_ERR_RANGE_SILENT 0x04u
#define TLM_ERR_POSE_LOST 0x08u
#define TLM_ERR_CAN_BUS 0x10u
#define TLM_ERR_UART 0x20u
#define TLM_ERR_FLASH 0x40u
#define TLM_ERR_DEADLINE_MISS 0x80u

/// TOOL_CMD Command.
enum tlm_tool_command { TLM_CMD_NOP = 0, TLM_CMD_START_EPISODE = 1, TLM_CMD_STOP = 2,
                        TLM_CMD_SAFE_STOP = 3, TLM_CMD_SAVE_LEARNED = 4, TLM_CMD_RESET_LEARNING = 5,
                        TLM_CMD_RESTORE_PREVIOUS = 6 };

/// RESET_LEARNING's Argument that confirms wiping learning saved since boot or restored at boot.
#define TLM_RESET_CONFIRM 1u

/// TOOL_ACK Result.
enum tlm_ack_result { TLM_ACK_DONE = 0, TLM_ACK_REFUSED = 1, TLM_ACK_FAILED = 2 };

/// TOOL_ACK Reason (docs/can-protocol.md "Answers").
enum tlm_ack_reason {
    TLM_WHY_NONE = 0,
    TLM_WHY_EVALUATE_MODE = 1,   ///< refused: evaluate mode locks what was learned
    TLM_WHY_NOT_IDLE = 2,        ///< refused: needs a stopped robot (send STOP first)
    TLM_WHY_BUSY = 3,            ///< refused: the wheels are driving (an action; after a cut, maybe the last boot's command); try again
    TLM_WHY_CONFIRM = 4,         ///< refused: learning was saved since boot or restored at boot; Argument 1 confirms
    TLM_WHY_NO_STORE = 5,        ///< failed: no flash store (persistence off or no region)
    TLM_WHY_FLASH_ERROR = 6,     ///< failed: erasing or programming the flash failed
    TLM_WHY_NO_ROOM = 7,         ///< failed: the record does not fit a slot
    TLM_WHY_NO_PREVIOUS = 8,     ///< refused: no previous record of this agent's layout
    TLM_WHY_MALFORMED = 9,       ///< refused: bad Crc or unknown Command
    TLM_WHY_RECORD_DAMAGED = 10, ///< failed: the record to restore failed its checks
    TLM_WHY_DEVICE_SILENT = 11,  ///< refused: a device the robot drives on is silent (FW_STATUS Errors says which); try again
};

typedef struct tlm_pose {
    int32_t x_mm, y_mm;     ///< saturated to int16
    int32_t heading_cdeg;   ///< any value; wrapped into 0..35999
    uint8_t fix_state;      ///< enum tlm_fix_state (values > 3 are sent as LOST)
} tlm_pose_t;

typedef struct tlm_learn {
    uint32_t state;         ///< saturated to 24 bits
    uint8_t action;         ///< saturated to 15
    int32_t reward;         ///< saturated to -128..127
    uint32_t episode;       ///< sent modulo 2048
    uint32_t step;          ///< saturated to 8191
} tlm_learn_t;

typedef struct tlm_value {
    uint32_t state;         ///< saturated to 24 bits
    uint8_t action;         ///< the greedy action, saturated to 15
    float value;            ///< V; sent in 0.1 steps, saturated to -3276.8..3276.7 (NaN as 0)
    uint8_t aliasing;       ///< the state's cell's aliasing count (agent_aliasing())
} tlm_value_t;

typedef struct tlm_sched {
    uint32_t plan_updates;     ///< planning updates since the last TLM_SCHED, saturated to 65535
    uint32_t deadline_misses;  ///< since boot, sent modulo 65536
    uint32_t idle_permille;    ///< idle share of the last period, 0..1000 (sent in 0.5 % steps)
    uint32_t queue_length;     ///< saturated to 65535
} tlm_sched_t;

typedef struct tlm_episode {
    uint32_t episode;       ///< sent modulo 65536
    uint32_t steps;         ///< saturated to 32767
    int32_t total_reward;   ///< saturated to -524288..524287
    bool reached_goal;
    uint32_t bumps;         ///< saturated to 2047
    bool interrupted;       ///< cut before the goal or the step cap (its last step not learned)
} tlm_episode_t;

typedef struct tlm_status {
    uint8_t mode;           ///< enum tlm_mode
    uint8_t errors;         ///< TLM_ERR_* bits
    uint32_t uptime_s;
    bool pose_trusted;      ///< the firmware trusts its heading (robot/pose_trust.h)
    uint8_t trust_reason;   ///< enum tlm_trust_reason (saturated to ABSOLUTE)
    uint8_t reset_cause;    ///< hal_reset_cause_t (saturated to OTHER)
    uint32_t boot_count;    ///< sent modulo 256
} tlm_status_t;

typedef struct tlm_tool_cmd {
    uint8_t command;        ///< enum tlm_tool_command
    uint32_t argument;      ///< 24 bits on the bus: larger values are sent as 0xFFFFFF ("none")
} tlm_tool_cmd_t;

/// TOOL_ACK: the answer to one TOOL_CMD.
typedef struct tlm_ack {
    uint8_t command;        ///< enum tlm_tool_command (as read, for MALFORMED)
    uint8_t counter;        ///< the command's Counter
    uint8_t result;         ///< enum tlm_ack_result
    uint8_t reason;         ///< enum tlm_ack_reason
    uint32_t sequence;      ///< record sequence number, saturated to 24 bits
    uint32_t episodes;      ///< saturated to 65535
} tlm_ack_t;

/// The firmware's transmit counters and the TOOL_CMD receive state.
typedef struct tlm {
    uint8_t pose_counter, learn_counter, sched_counter, status_counter, value_counter;
    can_link_rx_t tool_rx;  ///< TOOL_CMD bookkeeping
} tlm_t;

void tlm_init(tlm_t *tlm);

void tlm_encode_pose(tlm_t *tlm, const tlm_pose_t *pose, hal_can_frame_t *out);
void tlm_encode_learn(tlm_t *tlm, const tlm_learn_t *learn, hal_can_frame_t *out);
void tlm_encode_sched(tlm_t *tlm, const tlm_sched_t *sched, hal_can_frame_t *out);
void tlm_encode_value(tlm_t *tlm, const tlm_value_t *value, hal_can_frame_t *out);
void tlm_encode_episode(const tlm_episode_t *episode, hal_can_frame_t *out);
void tlm_encode_status(tlm_t *tlm, const tlm_status_t *status, hal_can_frame_t *out);

/// Decodes TOOL_CMD. Returns FW_OK (a new command in *out), FW_ERR_NOENT (the same counter as
/// the last accepted command: a repeat, ignore it), or FW_ERR_INVAL (malformed, CRC mismatch or
/// unknown command; counted in tool_rx.malformed).
int tlm_rx_tool_cmd(tlm_t *tlm, const hal_can_frame_t *frame, uint64_t now_us, tlm_tool_cmd_t *out);

/// Builds TOOL_ACK (saturating Sequence and Episodes).
void tlm_encode_ack(const tlm_ack_t *ack, hal_can_frame_t *out);

/// Tool side: builds TOOL_CMD with counter `*counter` (advanced) and its CRC. FW_OK or
/// FW_ERR_INVAL (unknown command).
int tlm_encode_tool_cmd(uint8_t *counter, const tlm_tool_cmd_t *cmd, hal_can_frame_t *out);

/// Tool side decoders of the firmware's frames: FW_OK or FW_ERR_INVAL (malformed).
int tlm_decode_pose(const hal_can_frame_t *frame, tlm_pose_t *out);
int tlm_decode_learn(const hal_can_frame_t *frame, tlm_learn_t *out);
int tlm_decode_sched(const hal_can_frame_t *frame, tlm_sched_t *out);
int tlm_decode_episode(const hal_can_frame_t *frame, tlm_episode_t *out);
int tlm_decode_status(const hal_can_frame_t *frame, tlm_status_t *out);
int tlm_decode_ack(const hal_can_frame_t *frame, tlm_ack_t *out);
int tlm_decode_value(const hal_can_frame_t *frame, tlm_value_t *out);

#ifdef __cplusplus
}
#endif

#endif // DRIVERS_TELEMETRY_H
