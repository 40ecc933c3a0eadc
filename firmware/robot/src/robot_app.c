// SPDX-License-Identifier: MIT
// dynaqpc robot application: the firmware's wiring — interrupts to events, events to drivers,
// the control task, telemetry, idle planning, and the learned store.
#include "robot/robot_app.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "drivers/candev.h"
#include "drivers/cricket.h"
#include "dynaqpc_can.h"
#include "fw/fw_base.h"
#include "hal/hal_can.h"
#include "hal/hal_cpu.h"
#include "hal/hal_flash.h"
#include "hal/hal_time.h"
#include "hal/hal_uart.h"
#include "robot/boot_journal.h"
#include "robot/fix_gate.h"
#include "robot/pose_trust.h"

#define EV_CAN 1u   // a received frame, in u.can
#define EV_UART 2u  // Cricket bytes are waiting in the UART's ring buffer

#define CAN_BITRATE 500000u
#define CRICKET_BAUD 115200u
#define STATUS_PERIOD_US 1000000u
#define DEG_PER_RAD 57.2957795f
#define RAD_PER_DEG 0.0174532925f
// Beyond any sensor's reach: a range sensor that sees nothing.
#define RANGE_NOTHING_M 100.0f
// A wheel measured no faster than this stands (MOTOR_STATUS, mm/s). After a boot that cut an
// episode, this many MOTOR_STATUS in a row with both wheels standing (2 cycles, ~100 ms) say that
// the previous boot's last command no longer drives them.
#define STILL_MM_S 10
#define STILL_REPORTS 3u

// What the status task saw last, to raise a counting fault for the period it grew in.
typedef struct robot_health {
    uint32_t can_faults, uart_faults, uart_bytes, misses;
} robot_health_t;

typedef struct robot_app {
    robot_app_options_t opt;
    uint32_t gyro_gaps;        ///< the gyro's gaps at the last control period
    sched_t sched;
    candev_t dev;
    cricket_t cricket;
    cricket_beacon_t beacons[ROBOT_MAX_BEACONS];
    robot_ctrl_t ctrl;
    learned_store_t store;
    robot_health_t health;    // counters at the last status period
    float odom_m;             // the wheels' odometer (robot_sense_t.odom_m), from MOTOR_STATUS speeds
    float odom_speed;         // the mean wheel speed of the last MOTOR_STATUS, m/s
    uint64_t odom_us;         // when it came
    uint64_t last_fix_us;     // when the ranges of the last solvable Cricket fix were taken
    hal_can_frame_t last_ack; // the last TOOL_ACK, sent again for a repeated command
    agent_state_t prev_state; // the last TLM_LEARN's state: the next real step updates its Q row
    uint32_t tlm_planning_updates;  ///< the agent's planning updates at the last TLM_SCHED
    robot_app_stats_t stats;
    uint64_t boot_us;
    uint64_t period_start_idle_us;
    // Pose trust (robot/pose_trust.h): whether the heading may be used, and what watches it.
    pose_trust_t trust;
    uint64_t last_control_us;  ///< the last control period's start (0: none yet)
    uint64_t fix_after_us;     ///< fixes whose ranges are all older were taken before the operator's START
    uint64_t trusted_at_us;    ///< when the heading was last given (operator, leg)
    fix_gate_t gate;           ///< which fresh Cricket fixes are believed (robot/fix_gate.h)
    // Across reboots (robot/boot_journal.h).
    boot_journal_t journal;
    // The flags, together (the 192 KiB paper-sim image has no byte to spare for padding).
    bool store_ok;
    bool flash_fault;         // FW_STATUS Flash: the last save failed, or the restore refused a record
    bool bump_latch;          // a MOTOR_STATUS since the last control period reported a contact
    bool moved_last_period;   // the wheels were commanded to move in the last period
    uint8_t still_periods;    // control periods since the wheels were last commanded to move (saturating)
    bool odom_ok;             // a MOTOR_STATUS has come: the odometer counts
    uint8_t status_counter;
    bool have_ack;
    bool wiped_unsaved;       // RESET_LEARNING done and nothing saved since: flash's newest is the undo
    bool have_prev_state;
    bool start_pending;        ///< an episode is to start once the heading is trusted
    bool boot_report;          ///< report the episode a reboot cut (stats.boot_cut_*), at the first control period
    bool settle_pending;       ///< booted after a cut mid-episode: no heading until the wheels report still
    uint8_t still_reports;     ///< MOTOR_STATUS in a row with both wheels standing (saturating)
} robot_app_t;

static robot_app_t app_;

// ---- Interrupt context: copy and post -----------------------------------------------------------

static void on_can_isr_(const hal_can_frame_t *frame, void *ctx)
{
    (void)ctx;
    sched_event_t ev;
    ev.type = EV_CAN;
    ev.u.can = *frame;
    (void)sched_post(&app_.sched, &ev);  // a full queue counts the drop
}

// One EV_UART waits at a time: the handler drains every byte there is, and a post per byte would
// let one 70-byte Cricket line fill the event queue and crowd out CAN frames. A failed post (the
// queue is full) leaves the flag clear, so the next byte tries again: the port notifies on every
// byte while its ring holds unread ones, a full ring too (hal_uart_rx_fn). Should the line then
// fall silent, `uart_missed_` has the control task drain the ring itself, so no wake-up is lost.
static volatile bool uart_pending_;
static volatile bool uart_missed_;

static void on_uart_isr_(void *ctx)
{
    (void)ctx;
    if (uart_pending_) {
        return;
    }
    sched_event_t ev;
    ev.type = EV_UART;
    ev.u.word = 0;
    if (sched_post(&app_.sched, &ev) == FW_OK) {
        uart_pending_ = true;
    } else {
        uart_missed_ = true;
        app_.stats.uart_posts_failed++;
    }
}

// ---- Events: into the drivers -------------------------------------------------------------------

static void note_save_(int err)
{
    if (err == FW_OK) {
        boot_journal_follow(&app_.journal, &app_.store);  // the journal goes on after the new record
        app_.wiped_unsaved = false;
        app_.stats.saves++;
        app_.flash_fault = false;
    } else {
        app_.stats.save_errors++;
        app_.flash_fault = true;
    }
}

static void send_(const hal_can_frame_t *f)
{
    if (hal_can_send(f) != FW_OK) {
        app_.stats.frames_tx_dropped++;
    }
}

// Sends TOOL_ACK and keeps it: a repeated command frame (the same Counter) gets it again.
static void answer_(tlm_ack_t *ack)
{
    if (ack->result == TLM_ACK_REFUSED) {
        app_.stats.tool_refused++;
    }
    app_.stats.tool_answers++;
    tlm_encode_ack(ack, &app_.last_ack);
    app_.have_ack = true;
    send_(&app_.last_ack);
}

static void send_episode_(const robot_episode_report_t *ep)
{
    hal_can_frame_t f;
    const tlm_episode_t e = {ep->episode, ep->steps, (int32_t)lrintf(ep->reward), ep->reached_goal, ep->bumps,
                             ep->interrupted};
    tlm_encode_episode(&e, &f);
    send_(&f);
}

// An episode that ended before its first real step (cut by a lost heading, a START or a STOP)
// learned nothing: it is reported (TLM_EPISODE, 0 steps) but not counted, so its number goes back
// and the next episode takes it again, and it is not saved. Counted, empty episodes would add to a
// record's episodes with nothing learned, and after a RESET_LEARNING a silent gyro's START after
// START would pass the kept copy of the wiped learning and overwrite it (learned_store.h). Returns
// whether the episode learned.
static bool episode_learned_(void)
{
    if (app_.ctrl.last_episode.steps > 0u) {
        return true;
    }
    app_.stats.episodes_empty++;
    app_.ctrl.episode = app_.ctrl.episode > 0u ? app_.ctrl.episode - 1u : 0u;
    return false;
}

// A command ends the running episode (START_EPISODE, STOP): it is reported as interrupted, with
// the steps it had; its last step is not learned from.
static void interrupt_episode_(void)
{
    if (robot_ctrl_interrupt(&app_.ctrl, hal_time_us())) {
        app_.stats.episodes_interrupted++;
        send_episode_(&app_.ctrl.last_episode);
        (void)episode_learned_();
        (void)boot_journal_append(&app_.journal, app_.ctrl.episode, app_.ctrl.last_episode.steps, false);
        app_.ctrl.episode_done = false;  // reported here, not again by the control task
    }
}

static bool heading_absolute_(void)
{
    return app_.opt.cfg->pose_source != ROBOT_POSE_CRICKET;
}

// The range sensors' link (IR_RANGES, or the sonar scans); NULL for a robot without ranges.
static const can_link_rx_t *ranges_rx_(void)
{
    const robot_config_t *cfg = app_.opt.cfg;
    if (cfg->n_ranges == 0u) {
        return NULL;
    }
    return ranges_in_ir_frame(cfg->n_ranges) ? &app_.dev.ranges.ir_rx : &app_.dev.ranges.sonar_rx;
}

// Whether a device the robot drives on has fallen silent: heard, then not for the bus timeout; or
// not heard since boot for as long (a device's first frame may come a little after the boot).
static bool device_silent_(const can_link_rx_t *rx, uint64_t now)
{
    const uint64_t timeout = app_.opt.cfg->bus_timeout_us;
    return rx->seen ? can_link_rx_silent(rx, now, timeout) : now - app_.boot_us > timeout;
}

// Whether the robot lacks a device it needs to drive an episode: the motor controller, the range
// sensors, or the gyro that gives a Cricket robot its heading (silent or flagging a fault). An
// episode started now would only safe-stop, or lose its heading again at once.
static bool devices_missing_(uint64_t now)
{
    const can_link_rx_t *ranges = ranges_rx_();
    const gyro_t *g = &app_.dev.gyro;
    const bool gyro_needed = !heading_absolute_();
    return device_silent_(&app_.dev.motor.rx, now) || (ranges != NULL && device_silent_(ranges, now)) ||
           (gyro_needed && (device_silent_(&g->rx, now) || (g->rx.seen && g->status != GYRO_STATUS_OK)));
}

// Starts an episode and notes it in flash: a reboot before its end reports it as interrupted.
static void start_episode_(void)
{
    robot_ctrl_start_episode(&app_.ctrl);
    (void)boot_journal_append(&app_.journal, app_.ctrl.episode, 0u, true);
}

static uint8_t save_reason_(int err)
{
    return err == FW_ERR_NOSYS ? TLM_WHY_NO_STORE : err == FW_ERR_NOMEM ? TLM_WHY_NO_ROOM : TLM_WHY_FLASH_ERROR;
}

static void refuse_(tlm_ack_t *ack, uint8_t why)
{
    ack->result = TLM_ACK_REFUSED;
    ack->reason = why;
}

static void cmd_start_episode_(const tlm_tool_cmd_t *cmd, tlm_ack_t *ack)
{
    // The operator placed the robot; the argument is its heading in 0.01 deg when the pose
    // source has no heading of its own (a gyro only integrates), 0xFFFFFF to keep it.
    // A heading from the operator makes it trusted (the operator put the robot down: the
    // last fix's position is no reference for a jump). Without one an untrusted robot first
    // finds its heading (pose_trust.h), then starts.
    if (cmd->argument <= 35999u && app_.settle_pending) {
        // Booted after a cut mid-episode, and the wheels have not yet reported still: the motor
        // controller may still drive the previous boot's last command (it keeps one 500 ms and
        // refuses the new boot's first as a counter jump), so a heading read now may be stale by
        // the time it is taken. Nothing changes; send it again (BUSY), measured once it stands.
        refuse_(ack, TLM_WHY_BUSY);
        return;
    }
    if (devices_missing_(hal_time_us())) {
        // Nothing changes: FW_STATUS's Errors name the silent device; send it again once it is back.
        refuse_(ack, TLM_WHY_DEVICE_SILENT);
        return;
    }
    if (cmd->argument <= 35999u) {
        gyro_set_heading(&app_.dev.gyro, (float)cmd->argument * 0.01f);
        if (!heading_absolute_()) {
            pose_trust_grant(&app_.trust, POSE_TRUST_WHY_OPERATOR);
            app_.trusted_at_us = hal_time_us();
            fix_gate_forget(&app_.gate);
            app_.fix_after_us = hal_time_us();  // the next reference: a fix all taken from now on
        }
    }
    interrupt_episode_();
    if (app_.trust.trusted) {
        app_.start_pending = false;
        start_episode_();
    } else {
        app_.start_pending = true;
    }
}

// Authority (docs/can-protocol.md): the bus is trusted, a valid CRC-32 and a new counter make a
// command; but evaluate mode is a lock on what was learned, and wiping it takes a robot the
// operator has stopped first, so no single stray frame erases it mid-run.
static void cmd_save_learned_(tlm_ack_t *ack)
{
    if (app_.opt.evaluate) {
        refuse_(ack, TLM_WHY_EVALUATE_MODE);
    } else if ((app_.ctrl.mode == ROBOT_MODE_ACTING || app_.trust.phase == POSE_TRUST_LEG_DRIVE) &&
               app_.opt.cfg->wait_for_fix) {
        // A robot that stands still between actions saves while it stands, as at an episode's
        // end: erasing flash stalls the MCU for longer than the motor timeout. (One that never
        // stands mid-episode, the simulated robot, saves at once.)
        refuse_(ack, TLM_WHY_BUSY);
    } else {
        // The record counts the finished episodes: the running one's steps are in its tables but
        // the episode is not (a reboot reports it cut, numbered after them: open_journal_()).
        const bool running = app_.ctrl.mode != ROBOT_MODE_IDLE && app_.ctrl.episode > 0u;
        const uint32_t episodes = running ? app_.ctrl.episode - 1u : app_.ctrl.episode;
        const int err = app_.store_ok ? learned_store_save(&app_.store, app_.opt.agent, episodes) : FW_ERR_NOSYS;
        note_save_(err);
        if (err == FW_OK) {
            ack->sequence = app_.store.newest_sequence;
            ack->episodes = episodes;
        } else {
            ack->result = TLM_ACK_FAILED;
            ack->reason = save_reason_(err);
        }
    }
}

static void cmd_reset_learning_(const tlm_tool_cmd_t *cmd, tlm_ack_t *ack)
{
    if (app_.opt.evaluate) {
        refuse_(ack, TLM_WHY_EVALUATE_MODE);
    } else if (app_.ctrl.mode != ROBOT_MODE_IDLE || app_.start_pending) {
        refuse_(ack, TLM_WHY_NOT_IDLE);
    } else if ((app_.stats.saves > 0u || app_.stats.restore_result == FW_OK) &&
               cmd->argument != TLM_RESET_CONFIRM) {
        // Learning saved since boot, or restored at it: the operator must say so.
        refuse_(ack, TLM_WHY_CONFIRM);
    } else {
        // What is wiped is saved first (the robot stands: the time to write flash), so the
        // newest record is that learning and RESTORE_PREVIOUS undoes the wipe. The saves of
        // the new learning (episodes from 0 again) keep it (learned_store.h). A copy that
        // cannot be written leaves the learning as it was. A second wipe before any save keeps
        // the first one's copy as the newest record (the agent holds only the unsaved remains).
        const bool copy = app_.store_ok && !app_.wiped_unsaved;
        const int err = copy ? learned_store_save(&app_.store, app_.opt.agent, app_.ctrl.episode) : FW_OK;
        if (copy) {
            note_save_(err);
        }
        if (err != FW_OK) {
            ack->result = TLM_ACK_FAILED;
            ack->reason = save_reason_(err);
        } else {
            if (app_.store_ok) {
                ack->sequence = app_.store.newest_sequence;
            }
            agent_reset(app_.opt.agent, app_.opt.seed);
            app_.wiped_unsaved = app_.store_ok;
            app_.ctrl.episode = 0;
            app_.stats.resets++;
            ack->episodes = 0;
        }
    }
}

static void cmd_restore_previous_(tlm_ack_t *ack)
{
    if (app_.opt.evaluate) {
        refuse_(ack, TLM_WHY_EVALUATE_MODE);
    } else if (app_.ctrl.mode != ROBOT_MODE_IDLE || app_.start_pending) {
        refuse_(ack, TLM_WHY_NOT_IDLE);
    } else if (!app_.store_ok) {
        ack->result = TLM_ACK_FAILED;
        ack->reason = TLM_WHY_NO_STORE;
    } else {
        // After a wipe not saved over since, the newest record is the learning it wiped (saved
        // by RESET_LEARNING); otherwise the record before the newest, which after a wipe and
        // saves of the new learning is still the wiped learning (learned_store.h).
        uint32_t episodes = 0;
        int err;
        if (app_.wiped_unsaved) {
            err = learned_store_load(&app_.store, app_.opt.agent, &episodes);
            if (err == FW_OK) {
                (void)learned_store_slot_state(&app_.store, app_.opt.agent, (uint32_t)app_.store.restored_slot,
                                               &ack->sequence);
            }
        } else {
            err = learned_store_restore_previous(&app_.store, app_.opt.agent, &ack->sequence, &episodes);
        }
        if (err == FW_OK) {
            app_.wiped_unsaved = false;
            app_.ctrl.episode = episodes;
            ack->episodes = episodes;
            app_.stats.restores++;
            // Saved at once as the newest record, so a reboot boots what was restored (the
            // store keeps the other record: the one with more episodes, or the older).
            const int serr = learned_store_save(&app_.store, app_.opt.agent, episodes);
            note_save_(serr);
            if (serr != FW_OK) {
                ack->result = TLM_ACK_FAILED;
                ack->reason = save_reason_(serr);
            }
        } else if (err == FW_ERR_NOENT) {
            refuse_(ack, TLM_WHY_NO_PREVIOUS);
        } else {
            ack->result = TLM_ACK_FAILED;
            ack->reason = TLM_WHY_RECORD_DAMAGED;
        }
    }
}

static void handle_tool_cmd_(const tlm_tool_cmd_t *cmd, uint8_t counter)
{
    tlm_ack_t ack = {cmd->command, counter, TLM_ACK_DONE, TLM_WHY_NONE, 0u, app_.ctrl.episode};
    if (app_.store_ok) {
        uint32_t episodes;
        (void)learned_store_newest(&app_.store, &ack.sequence, &episodes);
    }
    switch (cmd->command) {
    case TLM_CMD_START_EPISODE:
        cmd_start_episode_(cmd, &ack);
        break;
    case TLM_CMD_STOP:
        interrupt_episode_();
        robot_ctrl_stop(&app_.ctrl);
        app_.start_pending = false;
        pose_trust_cancel(&app_.trust);
        break;
    case TLM_CMD_SAFE_STOP:
        robot_ctrl_safe_stop(&app_.ctrl);  // FW_STATUS shows SAFE_STOP until START or STOP
        app_.start_pending = false;
        pose_trust_cancel(&app_.trust);
        break;
    case TLM_CMD_SAVE_LEARNED:
        cmd_save_learned_(&ack);
        break;
    case TLM_CMD_RESET_LEARNING:
        cmd_reset_learning_(cmd, &ack);
        break;
    case TLM_CMD_RESTORE_PREVIOUS:
        cmd_restore_previous_(&ack);
        break;
    default:  // NOP
        break;
    }
    answer_(&ack);
}

// A TOOL_CMD the driver refused: a repeat gets the last answer again; a whole frame whose Crc or
// Command is wrong gets REFUSED MALFORMED (Command and Counter as read); anything else, nothing.
static void answer_refused_frame_(const hal_can_frame_t *f, int err)
{
    if (f->id != DYNAQPC_CAN_TOOL_CMD_FRAME_ID || (f->flags & (HAL_CAN_FLAG_EXTENDED | HAL_CAN_FLAG_REMOTE)) != 0u) {
        return;
    }
    if (err == FW_ERR_NOENT) {
        if (app_.have_ack) {
            send_(&app_.last_ack);
        }
    } else if (f->dlc == DYNAQPC_CAN_TOOL_CMD_LENGTH) {
        struct dynaqpc_can_tool_cmd_t m;
        (void)dynaqpc_can_tool_cmd_unpack(&m, f->data, f->dlc);
        const tlm_ack_t ack = {m.command, m.counter, TLM_ACK_REFUSED, TLM_WHY_MALFORMED, 0u, app_.ctrl.episode};
        hal_can_frame_t out;
        app_.stats.tool_malformed++;
        tlm_encode_ack(&ack, &out);  // not kept: a repeat of the last good command gets its answer
        send_(&out);
    }
}

// The odometer: the mean of the two wheels' measured speeds, integrated between MOTOR_STATUS
// frames (trapezoid; a gap over 200 ms, a silent controller, is not bridged).
#define ODOM_MAX_GAP_US 200000u

static void odometer_(uint64_t now)
{
    const motor_status_t *st = &app_.dev.motor.status;
    const float v = 0.0005f * (float)((int32_t)st->speed_left_mm_s + (int32_t)st->speed_right_mm_s);
    if (app_.odom_ok && now > app_.odom_us && now - app_.odom_us <= ODOM_MAX_GAP_US) {
        const float ds = 0.5f * (v + app_.odom_speed) * ((float)(now - app_.odom_us) * 1e-6f);
        app_.odom_m += ds;
        if (app_.opt.cfg->pose_source == ROBOT_POSE_CRICKET) {  // only Cricket fixes are gated
            // Along the heading the motions use: the gyro's, with what the fixes said of it.
            const float heading =
                robot_move_heading(&app_.ctrl.move, gyro_heading_deg(&app_.dev.gyro) * RAD_PER_DEG);
            fix_gate_travel(&app_.gate, ds, heading, app_.trust.trusted);
        }
    }
    app_.odom_speed = v;
    app_.odom_us = now;
    app_.odom_ok = true;
}

// Whether the wheels stand, by MOTOR_STATUS: after a boot that cut an episode, the heading is
// taken (START's, a leg's fixes) only once they have reported still STILL_REPORTS times in a row.
static void wheels_still_(void)
{
    const motor_status_t *st = &app_.dev.motor.status;
    const bool still = st->speed_left_mm_s <= STILL_MM_S && st->speed_left_mm_s >= -STILL_MM_S &&
                       st->speed_right_mm_s <= STILL_MM_S && st->speed_right_mm_s >= -STILL_MM_S;
    app_.still_reports = !still ? 0u : app_.still_reports < 255u ? (uint8_t)(app_.still_reports + 1u) : 255u;
    if (app_.still_reports >= STILL_REPORTS) {
        app_.settle_pending = false;
    }
}

static void on_can_event_(const sched_event_t *ev, void *ctx)
{
    (void)ctx;
    tlm_tool_cmd_t cmd;
    const int r = candev_rx(&app_.dev, &ev->u.can, hal_time_us(), &cmd);
    if (r < 0) {
        app_.stats.frames_bad += r == FW_ERR_INVAL ? 1u : 0u;
        answer_refused_frame_(&ev->u.can, r);
        return;
    }
    app_.stats.frames_rx++;
    if (r == CANDEV_RX_MOTOR) {
        odometer_(hal_time_us());
        wheels_still_();
    }
    if (r == CANDEV_RX_MOTOR && (app_.dev.motor.status.bump_front || app_.dev.motor.status.bump_rear)) {
        app_.bump_latch = true;
    } else if (r == CANDEV_RX_TOOL_CMD) {
        handle_tool_cmd_(&cmd, app_.dev.tlm.tool_rx.counter);
    }
}

static void drain_uart_(void)
{
    uint8_t buf[64];
    size_t n;
    uart_pending_ = false;  // before draining: a byte arriving from here on posts again
    uart_missed_ = false;
    while ((n = hal_uart_read(buf, sizeof buf)) > 0u) {
        (void)cricket_feed(&app_.cricket, buf, n, hal_time_us());
    }
}

static void on_uart_event_(const sched_event_t *ev, void *ctx)
{
    (void)ev;
    (void)ctx;
    drain_uart_();
}

// ---- The control task ---------------------------------------------------------------------------

/// Whether a fresh Cricket fix is believed (robot/fix_gate.h); a confirmed jump loses the heading.
static bool believe_fix_(const cricket_fix_t *fix, uint64_t now)
{
    const robot_config_t *cfg = app_.opt.cfg;
    const fix_gate_in_t g = {now, fix->x_mm * 0.001f, fix->y_mm * 0.001f, cfg->arena_w, cfg->arena_h};
    const fix_gate_verdict_t v = fix_gate_check(&app_.gate, &g);
    if (v == FIX_GATE_MOVED) {
        pose_trust_lose(&app_.trust, POSE_TRUST_WHY_FIX_JUMP);
    }
    return v != FIX_GATE_REFUSE;
}

static uint8_t sense_(robot_sense_t *in, uint64_t now)
{
    const robot_config_t *cfg = app_.opt.cfg;
    memset(in, 0, sizeof *in);
    in->now_us = now;
    in->bus_ok = !can_link_rx_silent(&app_.dev.motor.rx, now, cfg->bus_timeout_us);
    in->bump = app_.bump_latch;
    app_.bump_latch = false;
    in->odom_m = app_.odom_m;
    in->odom_ok = app_.odom_ok;
    uint8_t fix_state = TLM_FIX_LOST;
    if (cfg->pose_source == ROBOT_POSE_GPS) {
        const gps_t *g = &app_.dev.gps;
        const bool fresh = !can_link_rx_silent(&g->rx, now, cfg->pose_timeout_us);
        if (fresh && g->pose.fix != GPS_FIX_NONE) {
            in->pose_ok = true;
            in->pose.x = (float)g->pose.x_mm * 0.001f;
            in->pose.y = (float)g->pose.y_mm * 0.001f;
            in->pose.heading = (float)g->pose.heading_cdeg * 0.01f * RAD_PER_DEG;
            in->pose_time_us = g->rx.last_ok_us;
            fix_state = TLM_FIX_FRESH;
        }
    } else {
        if (app_.moved_last_period) {
            cricket_note_motion(&app_.cricket, now);
        }
        cricket_fix_t fix;
        cricket_fix_state_t st = cricket_get_fix(&app_.cricket, now, &fix);
        if (st == CRICKET_FIX_FRESH && fix.oldest_us > app_.fix_after_us && !believe_fix_(&fix, now)) {
            st = CRICKET_FIX_LOST;  // refused (robot/fix_gate.h): no pose this period
        }
        fix_state = (uint8_t)st;
        // While the robot drives, ranges from before and after the motion disagree and no fix
        // solves (LOST); that is expected, so the pose counts as lost only when no fix has
        // solved for the controller's pose timeout.
        if (st != CRICKET_FIX_LOST) {
            in->pose.x = fix.x_mm * 0.001f;
            in->pose.y = fix.y_mm * 0.001f;
            app_.last_fix_us = fix.oldest_us;
        }
        in->pose_time_us = app_.last_fix_us;
        in->pose_ok = st == CRICKET_FIX_FRESH;
        in->pose.heading = gyro_heading_deg(&app_.dev.gyro) * RAD_PER_DEG;
    }
    in->n_ranges = cfg->n_ranges;
    const can_link_rx_t *ranges = ranges_rx_();
    in->ranges_silent = ranges != NULL && device_silent_(ranges, now);
    const ranges_t *rg = &app_.dev.ranges;
    for (uint32_t i = 0; i < cfg->n_ranges && i < ROBOT_MAX_RANGES; i++) {
        if (ranges_in_ir_frame(cfg->n_ranges)) {
            in->range_m[i] = rg->ir_valid[i] ? (float)rg->ir_mm[i] * 0.001f : RANGE_NOTHING_M;
        } else {
            in->range_m[i] = rg->sonar_mm[i] == RANGES_NO_ECHO ? RANGE_NOTHING_M
                                                               : (float)rg->sonar_mm[i] * 0.001f;
        }
    }
    return fix_state;
}

static int16_t mm_s_(float v)
{
    float mm = v * 1000.0f;
    if (mm > (float)MOTOR_CMD_SPEED_MAX) {
        mm = (float)MOTOR_CMD_SPEED_MAX;
    } else if (mm < -(float)MOTOR_CMD_SPEED_MAX) {
        mm = -(float)MOTOR_CMD_SPEED_MAX;
    }
    return (int16_t)lrintf(mm);
}

static void telemetry_(const robot_sense_t *in, uint8_t fix_state)
{
    hal_can_frame_t f;
    // The heading the motions use (the gyro's with what the fixes said of it), not the raw gyro's.
    const float heading = robot_move_heading(&app_.ctrl.move, in->pose.heading);
    const tlm_pose_t pose = {(int32_t)lrintf(in->pose.x * 1000.0f), (int32_t)lrintf(in->pose.y * 1000.0f),
                             (int32_t)lrintf(heading * DEG_PER_RAD * 100.0f), fix_state};
    tlm_encode_pose(&app_.dev.tlm, &pose, &f);
    send_(&f);
    if (app_.ctrl.step_done) {
        const robot_step_report_t *st = &app_.ctrl.last_step;
        const tlm_learn_t learn = {st->state, st->action, (int32_t)lrintf(st->reward), app_.ctrl.episode, st->step};
        tlm_encode_learn(&app_.dev.tlm, &learn, &f);
        send_(&f);
        // The value map as it changes: the state this real step's update changed (the previous
        // step's), its greedy action and V. A start state (step 0) changed nothing.
        if (st->step >= 1u && app_.have_prev_state && app_.ctrl.learning) {
            const uint8_t g = agent_greedy(app_.opt.agent, app_.prev_state);
            const uint32_t aliasing = agent_aliasing(app_.opt.agent, app_.prev_state);
            const tlm_value_t tv = {app_.prev_state, g, agent_q(app_.opt.agent, app_.prev_state, g),
                                    (uint8_t)(aliasing < 255u ? aliasing : 255u)};
            tlm_encode_value(&app_.dev.tlm, &tv, &f);
            send_(&f);
        }
        app_.prev_state = st->state;
        app_.have_prev_state = true;
    }
    sched_stats_t ss;
    sched_get_stats(&app_.sched, &ss);
    uint32_t misses = 0;
    for (uint32_t i = 0; i < ss.task_count; i++) {
        misses += ss.task[i].misses;
    }
    const uint64_t idle = ss.idle_us - app_.period_start_idle_us;
    app_.period_start_idle_us = ss.idle_us;
    const uint32_t period = app_.opt.cfg->period_us;
    // PlanUpdates: every planning update since the last TLM_SCHED, the control task's (N after
    // a step, or the first ROBOT_PLAN_BEFORE_ACT with idle-time planning) and the idle loop's.
    // Dyna-QPC's queue is often empty before the idle loop runs (its share is in sched's
    // idle_steps), so counting the idle loop's alone would read 0 while the robot plans.
    const uint32_t planned = app_.opt.agent->stats.planning_updates;
    // (A reset of the agent by the operator restarts its count from 0.)
    const uint32_t plan_updates = planned >= app_.tlm_planning_updates ? planned - app_.tlm_planning_updates : planned;
    app_.tlm_planning_updates = planned;
    const tlm_sched_t sch = {plan_updates, misses,
                             (uint32_t)(idle >= period ? 1000u : idle * 1000u / period),
                             agent_backlog(app_.opt.agent)};
    tlm_encode_sched(&app_.dev.tlm, &sch, &f);
    send_(&f);
    if (app_.ctrl.episode_done) {
        send_episode_(&app_.ctrl.last_episode);
    }
}

// The fastest the robot can turn on the wheel speeds it was given lately (motor.h,
// MOTOR_PEAK_CMDS): both wheels at the peak, opposite ways, 2 v / track, by half as much again,
// plus GYRO_LIMIT_SLACK_DEG_S (the bias, noise, a push); 0 (none) before the motor driver has
// seen enough commands, or beyond the sensor's range. A gyro sample beyond it is refused and
// bridged (gyro_set_rate_limit).
#define GYRO_LIMIT_SLACK_DEG_S 30.0f
static uint16_t gyro_limit_(int32_t peak_mm_s)
{
    if (peak_mm_s < 0) {
        return 0u;
    }
    const float turn = 2.0f * (float)peak_mm_s * 1e-3f / app_.opt.cfg->track_m * DEG_PER_RAD;
    const float limit = 1.5f * turn + GYRO_LIMIT_SLACK_DEG_S;
    return limit < (float)GYRO_RANGE_DEG_S ? (uint16_t)(limit * 100.0f) : 0u;
}

// What makes a gyro-integrated heading untrusted (pose_trust.h): a gap in the gyro's samples (or
// its silence, or a sample it flags), a control task that stalled (the samples that bunched up
// behind it are integrated over the wrong times). A move seen by the fixes: believe_fix_().
static void watch_trust_(uint64_t now)
{
    const robot_config_t *cfg = app_.opt.cfg;
    if (heading_absolute_()) {
        return;
    }
    const gyro_t *g = &app_.dev.gyro;
    if (app_.last_control_us != 0u && now - app_.last_control_us > (uint64_t)cfg->period_us + POSE_TRUST_STALL_US) {
        pose_trust_lose(&app_.trust, POSE_TRUST_WHY_STALL);
    }
    app_.last_control_us = now;
    // (Not heard yet: silent once the bus timeout has passed since the heading was given.)
    const bool silent = g->rx.seen ? can_link_rx_silent(&g->rx, now, cfg->bus_timeout_us)
                                   : now - app_.trusted_at_us > cfg->bus_timeout_us;
    // A gap in the samples of a robot that stood still (wheels off for two periods, both ends'
    // rates near zero) cost nothing; while the wheels drive, a whole turn can hide in it.
    const bool gap = g->gaps != app_.gyro_gaps && (g->gap_bound_deg > POSE_TRUST_GAP_DEG || app_.still_periods < 2u);
    if (gap || (g->rx.seen && g->status != GYRO_STATUS_OK) || silent) {
        pose_trust_lose(&app_.trust, POSE_TRUST_WHY_GYRO_GAP);
    }
    app_.gyro_gaps = g->gaps;
}

// While an episode waits for the heading: the straight leg that finds it (pose_trust.h).
static void find_heading_(const robot_sense_t *in, float *vl, float *vr)
{
    if (!in->bus_ok || in->ranges_silent) {
        // No motor controller, or no ranges to see a wall ahead: stand, and start the leg again.
        pose_trust_cancel(&app_.trust);
        return;
    }
    gyro_t *g = &app_.dev.gyro;
    const pose_trust_in_t ti = {in->now_us, in->pose_ok, in->pose.x, in->pose.y, in->pose_time_us,
                                gyro_heading_deg(g), in->n_ranges > 0u ? in->range_m[0] : RANGE_NOTHING_M,
                                in->bump};
    float correction = 0.0f;
    if (pose_trust_leg_period(&app_.trust, app_.opt.cfg, &ti, vl, vr, &correction)) {
        gyro_set_heading(g, gyro_heading_deg(g) + correction);
        app_.trusted_at_us = in->now_us;
        app_.start_pending = false;
        start_episode_();
    }
}

static void control_task_(void *ctx)
{
    (void)ctx;
    if (uart_missed_) {
        drain_uart_();  // a wake-up the full event queue lost
    }
    const uint64_t now = hal_time_us();
    robot_sense_t in;
    const uint8_t fix_state = sense_(&in, now);
    watch_trust_(now);
    float vl = 0.0f, vr = 0.0f;
    if (!app_.trust.trusted && app_.ctrl.mode != ROBOT_MODE_IDLE) {
        // The heading is lost: the episode ends here, before its pending step is observed, and
        // the next starts once the heading is found again.
        (void)robot_ctrl_interrupt(&app_.ctrl, now);
        app_.stats.episodes_interrupted++;
        app_.start_pending = app_.start_pending || app_.opt.auto_start;
    } else {
        robot_ctrl_period(&app_.ctrl, &in, &vl, &vr);
        if (app_.ctrl.step_done && app_.ctrl.last_step.step >= 1u && !app_.ctrl.episode_done) {
            (void)boot_journal_append(&app_.journal, app_.ctrl.episode, app_.ctrl.last_step.step, true);
        }
        if (app_.start_pending && app_.ctrl.mode == ROBOT_MODE_IDLE && !app_.settle_pending) {
            find_heading_(&in, &vl, &vr);  // (it stands until the wheels report still after a cut)
        }
    }
    if (app_.boot_report) {
        app_.boot_report = false;  // the episode the last reboot cut, with the steps it had
        const robot_episode_report_t cut = {.episode = app_.stats.boot_cut_episode,
                                            .steps = app_.stats.boot_cut_steps,
                                            .interrupted = true};
        send_episode_(&cut);
    }
    const bool moving = vl != 0.0f || vr != 0.0f;
    app_.moved_last_period = moving;
    app_.still_periods = moving ? 0u : app_.still_periods < 255u ? (uint8_t)(app_.still_periods + 1u) : 255u;
    gyro_set_stationary(&app_.dev.gyro, !moving && in.bus_ok);
    const motor_cmd_t cmd = {mm_s_(vl), mm_s_(vr), true};
    hal_can_frame_t f;
    if (motor_encode_cmd(&app_.dev.motor, &cmd, &f) == FW_OK) {
        send_(&f);
    }
    gyro_set_rate_limit(&app_.dev.gyro, gyro_limit_(motor_cmd_peak_mm_s(&app_.dev.motor)));
    telemetry_(&in, fix_state);
    if (app_.ctrl.episode_done && episode_learned_()) {
        app_.stats.episodes++;
        // The robot stands still at an episode's end: the time to erase and program flash.
        if (app_.opt.persist && app_.store_ok && !app_.opt.evaluate) {
            note_save_(learned_store_save(&app_.store, app_.opt.agent, app_.ctrl.episode));
        }
    }
    if (app_.ctrl.episode_done) {
        (void)boot_journal_append(&app_.journal, app_.ctrl.episode, app_.ctrl.last_episode.steps, false);
        if (app_.opt.auto_start && app_.trust.trusted) {
            start_episode_();
        } else if (app_.opt.auto_start) {
            app_.start_pending = true;
        }
    }
    hal_cpu_watchdog_kick();
}

// The FW_STATUS error flags (docs/realtime.md "Faults"): each is raised while its condition
// holds and cleared when it passes. Silences are measured against the bus timeout; the counting
// faults (CAN, UART, deadline) are raised for the status period in which their counters grew.
static uint8_t health_(uint64_t now)
{
    const robot_config_t *cfg = app_.opt.cfg;
    robot_health_t *h = &app_.health;
    uint8_t errors = 0;
    errors |= can_link_rx_silent(&app_.dev.motor.rx, now, cfg->bus_timeout_us) ? TLM_ERR_MOTOR_SILENT : 0u;
    if (cfg->pose_source == ROBOT_POSE_CRICKET) {  // the gyro gives the heading
        errors |= can_link_rx_silent(&app_.dev.gyro.rx, now, cfg->bus_timeout_us) ? TLM_ERR_GYRO_SILENT : 0u;
    }
    const can_link_rx_t *ranges = ranges_rx_();
    if (ranges != NULL) {
        errors |= can_link_rx_silent(ranges, now, cfg->bus_timeout_us) ? TLM_ERR_RANGE_SILENT : 0u;
    }
    // No usable pose for the pose timeout: the controller safe-stops on the same rule.
    const bool pose_lost =
        cfg->pose_source == ROBOT_POSE_GPS
            ? (can_link_rx_silent(&app_.dev.gps.rx, now, cfg->pose_timeout_us) ||
               app_.dev.gps.pose.fix == GPS_FIX_NONE)
            : now - app_.last_fix_us > cfg->pose_timeout_us;
    errors |= pose_lost ? TLM_ERR_POSE_LOST : 0u;
    hal_can_stats_t cs;
    hal_can_get_stats(&cs);
    sched_stats_t ss;
    sched_get_stats(&app_.sched, &ss);
    const uint32_t can_faults = cs.tx_dropped + cs.rx_overruns + cs.bus_errors + ss.events_dropped;
    errors |= can_faults != h->can_faults ? TLM_ERR_CAN_BUS : 0u;
    h->can_faults = can_faults;
    if (cfg->pose_source == ROBOT_POSE_CRICKET) {
        hal_uart_stats_t us;
        hal_uart_get_stats(&us);
        // Bytes lost or garbled, or a line that has fallen silent for a whole status period.
        const uint32_t uart_faults = us.rx_overruns + us.rx_errors;
        errors |= uart_faults != h->uart_faults || us.rx_bytes == h->uart_bytes ? TLM_ERR_UART : 0u;
        h->uart_faults = uart_faults;
        h->uart_bytes = us.rx_bytes;
    }
    // The last save failed, or the boot's restore refused a record, until a save succeeds.
    errors |= app_.flash_fault ? TLM_ERR_FLASH : 0u;
    uint32_t misses = 0;
    for (uint32_t i = 0; i < ss.task_count; i++) {
        misses += ss.task[i].misses;
    }
    errors |= misses != h->misses ? TLM_ERR_DEADLINE_MISS : 0u;
    h->misses = misses;
    return errors;
}

static void status_task_(void *ctx)
{
    (void)ctx;
    const uint64_t now = hal_time_us();
    const uint8_t errors = health_(now);
    app_.stats.status_errors = errors;
    // An episode waiting for the heading (start_pending) runs: the robot drives its leg.
    const uint8_t mode = app_.ctrl.mode == ROBOT_MODE_IDLE && !app_.start_pending ? TLM_MODE_IDLE
                         : app_.ctrl.mode == ROBOT_MODE_SAFE_STOP                 ? TLM_MODE_SAFE_STOP
                                                                                  : TLM_MODE_RUNNING;
    const tlm_status_t st = {mode,
                             errors,
                             (uint32_t)((now - app_.boot_us) / 1000000u),
                             app_.trust.trusted,
                             app_.trust.reason,
                             (uint8_t)hal_cpu_reset_cause(),
                             app_.journal.boot};
    hal_can_frame_t f;
    tlm_encode_status(&app_.dev.tlm, &st, &f);
    send_(&f);
}

static bool idle_(void *ctx)
{
    (void)ctx;
    return robot_ctrl_plan(&app_.ctrl);
}

// ---- Boot ---------------------------------------------------------------------------------------

// The learning saved in flash, if the build keeps it and its record fits the store's slots.
static void restore_learning_(const robot_app_options_t *opt)
{
    app_.stats.restore_result = FW_ERR_NOENT;
    if (opt->persist) {
        app_.store_ok = learned_store_init(&app_.store) == FW_OK &&
                        learned_store_record_size(opt->agent) <= app_.store.slot_size;
        if (app_.store_ok) {
            app_.stats.restore_result =
                learned_store_load(&app_.store, opt->agent, &app_.stats.restored_episodes);
            // Refused or damaged records, a fallback to an older one: reported, not silent.
            app_.stats.records_refused = app_.store.refused_records + app_.store.corrupt_records;
            // Another layout's record (another scenario, agent or build) is not this firmware's to
            // restore, and its saves go over it (learned_store.h): counted, and reported too.
            app_.stats.records_foreign = app_.store.foreign_records;
            app_.stats.restore_fell_back = app_.store.fell_back;
            app_.flash_fault = app_.stats.restore_result == FW_ERR_CORRUPT || app_.store.fell_back;
        }
    }
}

// What the robot did when it last stopped (the boot journal): an episode still running was cut by
// this boot, and the numbering goes on after it.
static void open_journal_(void)
{
    if (!app_.store_ok) {
        return;
    }
    boot_journal_entry_t last;
    uint32_t sequence, saved = 0u;
    if (boot_journal_open(&app_.journal, &app_.store, &last)) {
        // An entry from before the newest record's save (that record's journal lost its first
        // entry to a cut or damage) naming a running episode the record counts: the episode
        // ended and was saved before the cut (a save counts only finished episodes: at an
        // episode's end, or SAVE_LEARNED's). Not cut by this boot.
        if (last.running && last.before_newest && learned_store_newest(&app_.store, &sequence, &saved) &&
            last.episode <= saved) {
            last.running = false;
        }
        if (last.running) {
            app_.boot_report = true;
            // The previous boot's last command may still drive the wheels: no heading till they stand.
            app_.settle_pending = !heading_absolute_();
            app_.stats.episodes_interrupted++;
            app_.stats.boot_cut_episode = last.episode;
            app_.stats.boot_cut_steps = last.steps;
        }
        // Numbers go on after the cut episode's (the record holds only the finished ones); one cut
        // before its first real step learned nothing and is not counted (episode_learned_()).
        const uint32_t counted = last.running && last.steps == 0u && last.episode > 0u ? last.episode - 1u
                                                                                      : last.episode;
        app_.ctrl.episode = counted > app_.ctrl.episode ? counted : app_.ctrl.episode;
    }
    if (app_.opt.evaluate) {
        // Evaluate mode is a lock on the flash: it reads what the last boot journaled and writes
        // nothing, not even the journal (every append after this is refused: FW_ERR_NOSYS).
        app_.journal.ok = false;
        return;
    }
    (void)boot_journal_append(&app_.journal, app_.ctrl.episode, 0u, false);
}

static int init_cricket_(const robot_config_t *cfg)
{
    if (cfg->pose_source != ROBOT_POSE_CRICKET) {
        return FW_OK;
    }
    struct cricket_config cc;
    cricket_default_config(&cc);
    for (uint32_t i = 0; i < cfg->n_beacons; i++) {
        app_.beacons[i] = (cricket_beacon_t){cfg->beacons[i].id, cfg->beacons[i].x * 1000.0f,
                                             cfg->beacons[i].y * 1000.0f, cfg->beacons[i].z * 1000.0f};
    }
    cc.beacons = app_.beacons;
    cc.n_beacons = cfg->n_beacons;
    cc.listener_z_mm = cfg->listener_z * 1000.0f;
    if (cfg->speed_of_sound > 0.0f) {
        cc.speed_of_sound_m_s = cfg->speed_of_sound;  // else the driver's 343 m/s
    }
    return cricket_init(&app_.cricket, &cc);
}

// The control and status tasks and the CAN and UART events on the scheduler.
static int init_sched_(const robot_app_options_t *opt, const robot_config_t *cfg)
{
    const sched_config_t sc = {idle_, NULL, opt->plan_budget_us, 0u, opt->plan_cycles};
    int err = sched_init(&app_.sched, &sc);
    if (err) {
        return err;
    }
    // A run more than FW_CFG_SCHED_TOLERANCE_PERMILLE of its period late is a deadline miss.
    const sched_task_config_t control = {"control", control_task_, NULL, cfg->period_us, 0u,
                                         sched_tolerance_us(cfg->period_us), 0u};
    const sched_task_config_t status = {"status", status_task_, NULL, STATUS_PERIOD_US, 1000u,
                                        sched_tolerance_us(STATUS_PERIOD_US), 0u};
    if (sched_add_task(&app_.sched, &control) < 0 || sched_add_task(&app_.sched, &status) < 0) {
        return FW_ERR_NOMEM;
    }
    // Event types below FW_CFG_SCHED_EVENT_TYPES on a live scheduler: only a programming error fails.
    FW_UNUSED const int on_can = sched_on_event(&app_.sched, EV_CAN, on_can_event_, NULL);
    FW_UNUSED const int on_uart = sched_on_event(&app_.sched, EV_UART, on_uart_event_, NULL);
    FW_ASSERT(on_can == FW_OK && on_uart == FW_OK);
    return FW_OK;
}

int robot_app_init(const robot_app_options_t *opt)
{
    if (opt == NULL || opt->agent == NULL || opt->storage == NULL || robot_config_check(opt->cfg) != FW_OK) {
        return FW_ERR_INVAL;
    }
    memset(&app_, 0, sizeof app_);
    uart_pending_ = false;
    uart_missed_ = false;
    app_.opt = *opt;
    const robot_config_t *cfg = opt->cfg;
    int err = hal_time_init();
    if (err) {
        return err;
    }
    app_.boot_us = hal_time_us();

    static agent_space_t space;
    robot_config_space(cfg, &space);
    const agent_config_t ac = {cfg->agent, &space, robot_config_agent_params(cfg), opt->storage,
                               opt->seed};
    err = agent_init(opt->agent, &ac);
    if (err) {
        return err;
    }
    restore_learning_(opt);
    robot_ctrl_init(&app_.ctrl, cfg, opt->agent);
    pose_trust_init(&app_.trust, cfg->pose_source != ROBOT_POSE_CRICKET);
    fix_gate_init(&app_.gate);
    app_.tlm_planning_updates = opt->agent->stats.planning_updates;
    app_.ctrl.learning = !opt->evaluate;
    app_.ctrl.episode = app_.stats.restore_result == FW_OK ? app_.stats.restored_episodes : 0u;
    open_journal_();
    app_.stats.boot_count = app_.journal.boot;

    candev_init(&app_.dev);
    if (opt->gyro_period_ms != 0u) {
        gyro_set_sample_period(&app_.dev.gyro, (uint16_t)(opt->gyro_period_ms * 1000u));
    }
    err = init_cricket_(cfg);
    if (err) {
        return err;
    }
    err = init_sched_(opt, cfg);
    if (err) {
        return err;
    }
    err = hal_can_init(CAN_BITRATE, candev_rx_ids, CANDEV_RX_ID_COUNT, on_can_isr_, NULL);
    if (err) {
        return err;
    }
    if (cfg->pose_source == ROBOT_POSE_CRICKET) {
        err = hal_uart_init(CRICKET_BAUD, on_uart_isr_, NULL);
        if (err) {
            return err;
        }
    }
    if (opt->auto_start) {
        // Untrusted at boot (a gyro-integrated heading starts at 0): the robot first finds it.
        if (app_.trust.trusted) {
            start_episode_();
        } else {
            app_.start_pending = true;
        }
    }
    return FW_OK;
}

void robot_app_step(void)
{
    sched_step(&app_.sched);
}

void robot_app_run(const robot_config_t *cfg, agent_t *agent, const agent_storage_t *storage)
{
    robot_app_options_t opt = {0};
    opt.cfg = cfg;
    opt.agent = agent;
    opt.storage = storage;
    opt.seed = 1;
    opt.persist = true;
    opt.plan_budget_us = ROBOT_PLAN_BUDGET_US;
    if (robot_app_init(&opt) != FW_OK) {
        for (;;) {
            hal_cpu_wait_until(UINT64_MAX);
        }
    }
    // A port without a watchdog says FW_ERR_NOSYS; a timeout it refuses is a programming error.
    FW_UNUSED const int watchdog = hal_cpu_watchdog_start(ROBOT_WATCHDOG_MS);
    FW_ASSERT(watchdog == FW_OK || watchdog == FW_ERR_NOSYS);
    for (;;) {
        robot_app_step();
    }
}

sched_t *robot_app_sched(void)
{
    return &app_.sched;
}

const robot_ctrl_t *robot_app_ctrl(void)
{
    return &app_.ctrl;
}

const fix_gate_t *robot_app_fix_gate(void)
{
    return &app_.gate;
}

void robot_app_get_stats(robot_app_stats_t *out)
{
    *out = app_.stats;
    out->safe_stops = app_.ctrl.safe_stops;
    out->trust_losses = app_.trust.losses;
    for (uint32_t i = 0; i < 4u; i++) {
        out->trust_losses_by[i] = app_.trust.losses_by[i];
    }
    out->trust_legs = app_.trust.legs;
    out->trust_legs_failed = app_.trust.legs_failed;
}

void robot_app_get_cricket_stats(cricket_stats_t *out)
{
    *out = app_.cricket.stats;
}
