// SPDX-License-Identifier: MIT
// dynaqpc robot application: the firmware that runs the robot, on the MCU and on the host port.
//
// It owns the scheduler and wires everything together:
//   - CAN frames (motor controller, gyro, range board, GPS, tool commands) and Cricket serial
//     bytes arrive by interrupt and are posted into the scheduler's event queue;
//   - the control task, every cfg->period_us: sense -> observe -> act -> command, then telemetry;
//     a run that starts more than sched_tolerance_us(period) (FW_CFG_SCHED_TOLERANCE_PERMILLE,
//     10 %) after its release is a deadline miss (so is the 1 s status task's, by the same rule);
//   - idle time: the agent's planning updates (cfg->planning == 0) until the next deadline nears;
//   - at each episode's end, what was learned is saved to flash; at boot it is restored.
// One instance per program (the firmware is a singleton, as on the MCU).
#ifndef ROBOT_APP_H
#define ROBOT_APP_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/agent.h"
#include "drivers/cricket.h"
#include "robot/fix_gate.h"
#include "robot/controller.h"
#include "robot/learned_store.h"
#include "robot/robot_config.h"
#include "sched/sched.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Worst-case time of one planning update on the MCU, for fitting idle work before a deadline.
/// Measured (docs/realtime.md "On an emulated Cortex-M4"): the worst single Dyna-QPC
/// update is 8,556 Cortex-M4 instructions (`ctest --preset cortex-m4 -V -R single_update`: QEMU
/// TCG plugin, one update per agent_plan() call, 9,076 calls of a learning run), 51 us at 168 MHz
/// and one cycle per instruction: 100 us leaves 1.95x (it holds up to 1.96 cycles per
/// instruction). The control task that observes a step also makes up to ROBOT_PLAN_BEFORE_ACT
/// updates before acting: its worst run over a paper-lab learning run on the emulated board
/// (QEMU netduinoplus2, -icount shift=3, 227 real steps, no save) is 2,893 us at 125 M
/// instructions/s = 361,600 instructions = 2.15 ms at 168 MHz; the bound 64 x 8,556 + the rest of
/// the task is ~3.4 ms. The task's tolerance is 19.2 ms and its period 192 ms: margins 8.9x
/// (measured) and 5.6x (bound) on the tolerance.
#ifndef ROBOT_PLAN_BUDGET_US
#define ROBOT_PLAN_BUDGET_US 100u
#endif
/// Watchdog timeout: a few control periods.
#ifndef ROBOT_WATCHDOG_MS
#define ROBOT_WATCHDOG_MS 1000u
#endif

typedef struct robot_app_options {
    const robot_config_t *cfg;
    agent_t *agent;                  ///< a profile's agent (agent_profiles.h) big enough for cfg
    const agent_storage_t *storage;  ///< that profile's storage
    uint32_t seed;
    bool evaluate;          ///< replay greedily, no learning, no saving
    bool persist;           ///< restore at boot, save at episode ends (needs a flash region)
    bool auto_start;        ///< start an episode at boot and after each end (no operator)
    uint8_t gyro_period_ms; ///< GYRO_RATE's period: integrate the gyro over the samples' clock
                            ///< (gyro_set_sample_period); 0 keeps the build's FW_CFG_GYRO_PERIOD_US
    uint32_t plan_cycles;   ///< CPU cycles of one planning update (scheduler accounting; 0 none)
    uint32_t plan_budget_us;///< worst-case time of one planning update (idle fitting)
} robot_app_options_t;

/// Counters the application exports (and sends in telemetry).
typedef struct robot_app_stats {
    uint32_t frames_rx, frames_bad, frames_tx_dropped;
    uint32_t episodes, saves, save_errors;
    uint32_t episodes_empty;     ///< episodes ended before their first real step: not counted, not saved
    uint32_t uart_posts_failed;  ///< Cricket wake-ups the full event queue refused (retried)
    uint32_t tool_refused;       ///< TOOL_CMDs answered REFUSED (can-protocol.md "Answers")
    uint32_t tool_answers;       ///< TOOL_ACKs sent (a repeat's resent answer not counted)
    uint32_t tool_malformed;     ///< TOOL_CMDs answered MALFORMED (bad Crc or Command)
    uint32_t resets, restores;   ///< RESET_LEARNING and RESTORE_PREVIOUS done
    int32_t restore_result;  ///< learned_store_load() at boot: FW_OK, FW_ERR_NOENT, ...
    uint32_t restored_episodes;
    uint32_t records_refused;   ///< records the boot's restore found damaged or refused
    bool restore_fell_back;     ///< the boot restored an older record past a damaged one
    uint8_t status_errors;      ///< the TLM_ERR_* flags of the last FW_STATUS
    uint8_t records_foreign;    ///< whole records of another layout (scenario, agent, build) at boot
    uint32_t safe_stops;        ///< safe stops entered (the controller's count)
    uint32_t episodes_interrupted;  ///< episodes cut: the heading lost, or a START or STOP mid-episode
    uint32_t trust_losses;      ///< times the heading stopped being trusted (robot/pose_trust.h)
    uint16_t trust_losses_by[4];///< of them, by pose_trust_reason_t (GYRO_GAP, FIX_JUMP, STALL)
    uint16_t trust_legs;        ///< straight legs that found the heading
    uint16_t trust_legs_failed; ///< straight legs cut short (a bump) or without room
    uint32_t boot_count;        ///< this boot's number (robot/boot_journal.h; 1: none in flash before)
    uint32_t boot_cut_episode;  ///< the episode the last reboot cut (0: none), and its steps
    uint32_t boot_cut_steps;
} robot_app_stats_t;

/// Initialises the HAL's time, CAN and UART, the agent (restoring what was learned when
/// opt->persist), the drivers and the scheduler's tasks. Returns FW_OK or a negative fw_err_t
/// (a bad configuration, a HAL failure). Context: thread, at boot.
int robot_app_init(const robot_app_options_t *opt);

/// One pass of the main loop (sched_step). The MCU's main: for (;;) robot_app_step();
void robot_app_step(void);

/// The MCU's firmware: robot_app_init() with persistence on, the watchdog started, then the main
/// loop for ever. If initialisation fails nothing is safe to do: it sleeps for ever (the motor
/// controller stops on its own without commands). Never returns.
void robot_app_run(const robot_config_t *cfg, agent_t *agent, const agent_storage_t *storage);

sched_t *robot_app_sched(void);
const robot_ctrl_t *robot_app_ctrl(void);
/// The gate of the Cricket fixes (robot/fix_gate.h): its counters of refused fixes.
const fix_gate_t *robot_app_fix_gate(void);
void robot_app_get_stats(robot_app_stats_t *out);
/// The Cricket listener's line and fix counters (zero when the pose is from the GPS).
void robot_app_get_cricket_stats(cricket_stats_t *out);

#ifdef __cplusplus
}
#endif

#endif // ROBOT_APP_H
