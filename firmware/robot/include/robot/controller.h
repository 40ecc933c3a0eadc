// SPDX-License-Identifier: MIT
// dynaqpc robot application: the control loop's logic — episodes, real steps, rewards, safety.
//
// Pure logic, no I/O: each control period the application hands it what the sensors say and gets
// back the wheel speeds to command. One real step of the agent is: observe the state, pick an
// action, drive it for cfg->action_periods periods, (paper-lab) stop and wait for a fresh pose
// fix, observe the outcome and its reward, learn, and pick the next action. Everything between
// two observations — the step's motion, its heading held in closed loop, its end, the back-off
// after a bump, settling onto the grid before a first state — is robot_move.h's, called once a
// period; this file decides what is observed, learned and chosen.
#ifndef ROBOT_CONTROLLER_H
#define ROBOT_CONTROLLER_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/agent.h"
#include "robot/robot_config.h"
#include "robot/robot_geometry.h"
#include "robot/robot_motion.h"
#include "robot/robot_move.h"

/// With idle-time planning (config planning 0), the planning updates made when a step is
/// observed, before the next action is chosen; the idle time plans on after it. Each costs
/// ~23-25 µs on the MCU on average (3,886-4,171 instructions at 168 MHz) and at worst 51 µs
/// (8,556 instructions, measured): the control task runs at most ~3.3 ms longer, inside the
/// scheduler's 19.2 ms tolerance; measured on the emulated M4 over a learning run, the whole
/// task's worst run was 2.15 ms at 168 MHz (robot_app.h, docs/realtime.md).
#ifndef ROBOT_PLAN_BEFORE_ACT
#define ROBOT_PLAN_BEFORE_ACT 64u
#endif

#ifdef __cplusplus
extern "C" {
#endif

typedef enum robot_mode {
    ROBOT_MODE_IDLE = 0,       ///< stopped, waiting for the start of an episode
    ROBOT_MODE_ACTING = 1,     ///< driving the current action
    ROBOT_MODE_WAIT_FIX = 2,   ///< stopped after an action (or at the start), waiting for a pose fix
    ROBOT_MODE_SAFE_STOP = 3,  ///< stopped: the pose, the motor controller or the range sensors went
                               ///< silent (resumes when back), or
                               ///< the operator's safe stop (held until the next start or stop)
} robot_mode_t;

/// One finished episode.
typedef struct robot_episode_report {
    uint64_t start_us, end_us;
    uint32_t episode;       ///< counting from 1
    uint32_t steps;         ///< real steps
    float reward;           ///< total
    uint32_t bumps;
    bool reached_goal;
    bool interrupted;       ///< ended by robot_ctrl_interrupt(): neither the goal nor the step cap
} robot_episode_report_t;

/// The last real step, for telemetry.
typedef struct robot_step_report {
    agent_state_t state;    ///< the state observed
    uint8_t action;         ///< the action chosen there
    float reward;           ///< the reward that led into it
    uint32_t step;          ///< within the episode, from 1
} robot_step_report_t;

typedef struct robot_ctrl {
    const robot_config_t *cfg;
    agent_t *agent;
    // (Fields ordered so the struct has little padding: the 192 KiB paper-sim image has none to spare.)
    robot_mode_t mode;
    robot_mode_t resume_mode;  ///< the mode a safe stop interrupted: WAIT_FIX keeps the step
    uint8_t a;                 ///< the pending step's action (its state: s)
    /// false: replay the policy — greedy actions (ties at random), no updates, no planning.
    /// Default true.
    bool learning;
    agent_state_t s;           ///< the pending step's state (robot_move_pending())
    robot_move_t move;         ///< the step's life on the wheels (robot_move.h)
    uint32_t step, episode, bumps;
    float episode_reward;
    uint64_t episode_start_us;
    uint32_t safe_stops;       ///< times a safe stop was entered
    bool safe_stop_held;       ///< the operator's safe stop: no automatic resume
    bool step_done;            ///< a real step happened in the last period (see last_step)
    bool episode_done;         ///< an episode ended in the last period (see last_episode)
    robot_step_report_t last_step;
    robot_episode_report_t last_episode;
    /// The episode's last real steps, a ring of `recent_n` (state, action) pairs whose actions
    /// take 2 bits each of `recent_a`, and how often a loop was left: the agent's action
    /// overruled at a state's third visit within them (leave_loop_() in controller.c).
    uint64_t recent_a;
    agent_state_t recent_s[FW_CFG_LOOP_WINDOW];
    uint32_t loop_escapes;
    uint8_t recent_n, recent_head;
} robot_ctrl_t;

/// Prepares the controller, idle. The agent must be initialised for cfg's space.
void robot_ctrl_init(robot_ctrl_t *c, const robot_config_t *cfg, agent_t *agent);

/// Starts an episode at the next control period (the robot stands at its start pose). If an
/// episode is running it is abandoned without a final update. Context: thread.
void robot_ctrl_start_episode(robot_ctrl_t *c);

/// Ends any episode without learning from its last step and stops the wheels.
void robot_ctrl_stop(robot_ctrl_t *c);

/// Ends a running episode as interrupted (the heading became untrusted, or the operator's command
/// cut it): its pending step is not learned from, the wheels stop, and the report says interrupted
/// with the real steps it had (last_episode; episode_done until the next period). Returns whether
/// an episode was running. Context: thread.
bool robot_ctrl_interrupt(robot_ctrl_t *c, uint64_t now_us);

/// The operator's safe stop: the wheels stop and the mode is ROBOT_MODE_SAFE_STOP until the next
/// robot_ctrl_start_episode() or robot_ctrl_stop(), whatever the sensors say; the running
/// episode's last step is not learned from. Counted in safe_stops. Context: thread.
void robot_ctrl_safe_stop(robot_ctrl_t *c);

/// One control period: reads the sensors, advances the episode, returns the wheel speeds (the
/// move's: c->move.v_left, c->move.v_right; zero when idle).
void robot_ctrl_period(robot_ctrl_t *c, const robot_sense_t *sense, float *v_left, float *v_right);

/// One planning update in idle time, when cfg->planning is 0 ("as many as idle allows"). With a
/// fixed planning number the updates run right after each real step's learning, as in the
/// paper's Fig. 3, and this returns false. Returns false when there is nothing to plan on.
bool robot_ctrl_plan(robot_ctrl_t *c);

#ifdef __cplusplus
}
#endif

#endif // ROBOT_CONTROLLER_H
