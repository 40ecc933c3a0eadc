// SPDX-License-Identifier: MIT
// dynaqpc robot application: what one robot and its task look like to the firmware.
//
// One const robot_config_t per scenario. On the MCU it is compiled in (robot_config_paper_lab,
// robot_config_paper_sim); the simulator builds one from a scenario file. Everything the
// firmware needs to turn sensor readings into the agent's state and actions into wheel speeds
// is here, so the same code runs both scenarios.
#ifndef ROBOT_CONFIG_H
#define ROBOT_CONFIG_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/agent.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Range sensors on the robot (the IR board's 3, the sonar ring's 16).
#define ROBOT_MAX_RANGES 16u
/// Bits of the range-sensor code in the state.
#define ROBOT_MAX_CODE_BITS 4u
/// Cricket beacons the firmware knows the positions of.
#define ROBOT_MAX_BEACONS 8u
/// Most cells along one side of a grid fitted to the room (`encode auto`, robot_config_t.grid).
#define ROBOT_MAX_GRID_CELLS 32u

/// The actions, in the agent's numbering.
typedef enum robot_action {
    ROBOT_FORWARD = 0,
    ROBOT_BACKWARD = 1,
    ROBOT_TURN_LEFT = 2,   ///< counter-clockwise
    ROBOT_TURN_RIGHT = 3,
    ROBOT_N_ACTIONS = 4,
} robot_action_t;

/// Where the agent's discount and sweep threshold come from (robot_config_t.values).
typedef enum robot_values {
    /// From the room: robot_config_agent_params() sets gamma from the floor's size in cells and
    /// theta from the rewards' scale, so values reach the far end of any room (the default).
    ROBOT_VALUES_ROOM = 0,
    /// params.gamma and params.theta as given: the paper's 0.9 and 1e-3, a mode to ask for.
    ROBOT_VALUES_PAPER = 1,
} robot_values_t;

/// With ROBOT_VALUES_ROOM, gamma = 1 - 1 / H with H this many times the cells along the floor's
/// two sides: a state H steps from the goal keeps e^-1 of the goal's reward, and neighbours
/// that far still differ by about 0.37 (reward_goal / H + 1) in value, well above a slip's
/// noise (docs/agent.md, "Values that reach the far end").
#ifndef ROBOT_HORIZON_PER_SIDE_CELL
#define ROBOT_HORIZON_PER_SIDE_CELL 0.625f
#endif
/// With ROBOT_VALUES_ROOM, theta is the largest reward's magnitude over this (1e-3 for the
/// paper's +-100).
#define ROBOT_REWARD_PER_THETA 1e5f
/// With ROBOT_VALUES_ROOM, on a floor where a walk along its two sides ends farther from the goal
/// than the distance at which a path's value crosses zero (the sonar robot's floors, not the lab
/// robot's), a state never written starts at this share of the value of wandering for ever,
/// reward_step / (1 - gamma) (agent_params_t.q_prior; elsewhere 0, the paper's). Chosen on the
/// far-goal tuning rooms (docs/results/far-goal.md): 1 stops the robot
/// exploring (the lab robot's tuning rooms: 39 % of sets learned against 95 %), 0 leaves it
/// straying from long paths (the sonar robot's tuning serpentine: 0/2 sets; 0.5: 2/2).
#ifndef ROBOT_PRIOR_SHARE
#define ROBOT_PRIOR_SHARE 0.5f
#endif

/// 1: a robot narrower than its cells backs off after a step that bumped (robot_backs_off(),
/// robot_motion.h); 0: it stays where the bump left it. Measured with 0 in host builds only
/// (docs/results/lab-motion.md).
#ifndef ROBOT_BUMP_BACKOFF
#define ROBOT_BUMP_BACKOFF 1
#endif

/// 1: a robot that backs off after a bump also settles onto the grid of aligned stops at an
/// episode's start, before its first state is observed (robot_settle_motion(), robot_motion.h);
/// 0: it starts where it was put. Measured with 0 in host builds only (docs/results/lab-motion.md).
#ifndef ROBOT_START_SETTLE
#define ROBOT_START_SETTLE 1
#endif

/// 1: a robot whose heading comes from its gyro (the lab robot) closes its motions on the gyro and
/// its wheels' odometer (robot_run_t, robot_motion.h); 0: every motion is open loop, its wheel
/// speeds set once at its start. Measured with 0 in host builds only (docs/results/realistic-robot.md).
#ifndef ROBOT_CLOSED_LOOP
#define ROBOT_CLOSED_LOOP 1
#endif

/// How actions move (robot_config_t.aligned_actions).
typedef enum robot_actions_kind {
    ROBOT_ACTIONS_FIXED = 0,    ///< fixed steps and turns (the paper's)
    ROBOT_ACTIONS_ALIGNED = 1,  ///< aligned to the grid; a step stops step_past_m past the edge it crosses
    ROBOT_ACTIONS_CENTRED = 2,  ///< aligned to the grid; a step stops at the centre of the cell it enters
} robot_actions_kind_t;

/// Where the pose comes from.
typedef enum robot_pose_source {
    ROBOT_POSE_GPS = 0,      ///< paper-sim: a pose frame on the bus every cycle
    ROBOT_POSE_CRICKET = 1,  ///< paper-lab: x, y trilaterated from Cricket ranges; heading from the gyro
} robot_pose_source_t;

/// The state grid along one axis when it is fitted to the room (`encode auto`: docs/agent.md,
/// "A grid that fits the room"): cell k spans [edge[k], edge[k + 1]), edge[0] = 0 and
/// edge[cells] = the arena's side. Cells narrower than step_past_m lie inside an obstacle (a thin
/// partition): an aligned step crosses them and never stops in one.
typedef struct robot_grid_axis {
    uint8_t cells;  ///< 0: the axis is cut into 2^bits equal cells instead
    float edge[ROBOT_MAX_GRID_CELLS + 1u];
} robot_grid_axis_t;

typedef struct robot_beacon {
    uint64_t id;     ///< the beacon's 8-byte ID as the listener prints it, first byte most significant
    float x, y, z;   ///< metres, arena frame
} robot_beacon_t;

typedef struct robot_config {
    const char *name;  ///< "paper-sim", "paper-lab", or the scenario file's name

    // The arena and the goal (metres, arena frame: origin at a corner, x along the width).
    float arena_w, arena_h;
    float goal_x, goal_y, goal_r;
    /// 0: the goal is reached when the pose is inside the circle. 1: when the pose is in a cell
    /// of the state grid whose centre is inside the circle, so that reaching the goal is a
    /// function of the state the agent sees (docs/scenarios.md, "The goal as cells").
    uint8_t goal_cells;

    // State encoding: x, y, heading and the range code, in this many bits each (component 0 is x).
    uint8_t bits_x, bits_y, bits_heading, bits_code;
    /// x (grid[0]) and y (grid[1]) cells fitted to the room; cells 0: 2^bits equal cells. A
    /// fitted axis has at most 2^bits cells (bits_x, bits_y still size the state).
    robot_grid_axis_t grid[2];
    /// Code bit k is set when any range in rays_of_bit[k] (a bit mask of sensors) reads below
    /// code_threshold_m[k]: an obstacle is near on that side.
    uint32_t rays_of_bit[ROBOT_MAX_CODE_BITS];
    float code_threshold_m[ROBOT_MAX_CODE_BITS];
    uint8_t n_ranges;
    /// CMAC tile width of x, y, heading, code as a power of two (0: exact). Wider tiles let the
    /// models generalise a step's effect to neighbouring cells at the cost of more cells.
    uint8_t tile_shift[4];

    // Actions: one real step drives the wheels for action_periods control periods.
    float step_m;          ///< forward / backward distance of one step
    float turn_rad;        ///< turn of one step
    float track_m;         ///< wheel separation
    uint8_t action_periods;
    /// Actions aligned to the state grid (0: fixed steps and turns). A turn ends on a multiple of
    /// turn_rad, so the heading after it is the same every time; a step drives just past the edge
    /// of the current cell, so it always leads to a neighbouring cell. With cells larger than a
    /// step (paper-lab: 54 x 40 cm cells, 25 cm steps) fixed steps land in the same cell or the
    /// next one depending on where in the cell the robot stood, a difference the state cannot
    /// show; aligned actions make the outcome of (state, action) nearly deterministic, which is
    /// what a table and its model can learn from in a few thousand steps (docs/scenarios.md).
    ///
    /// A robot_actions_kind_t. With ROBOT_ACTIONS_CENTRED a step stops at the centre of the cell
    /// it enters, so each cell has one stop per axis instead of two, as far from both of its
    /// edges as the cell allows (docs/scenarios.md, "Where a step stops").
    uint8_t aligned_actions;
    /// Aligned steps end this far past the edge of the cell they leave (m, less than the smaller
    /// side of a cell). Where in the next cell the robot stops decides what its rangers see of
    /// the cell after it; choose it so a wall one cell ahead reads the same every time
    /// (docs/scenarios.md, "Where a step stops"). Centred steps stop at the centre instead; for
    /// both, a fitted cell narrower than this lies inside an obstacle and is stepped over.
    float step_past_m;
    /// After the action, wait with the wheels stopped for a fresh pose fix before observing
    /// (the paper's lab robot waited for a stable Cricket fix). 0: observe at once.
    uint8_t wait_for_fix;
    uint32_t period_us;    ///< control period, 192,000 in the paper

    // Rewards.
    float reward_goal, reward_bump, reward_step;

    // Learning.
    agent_kind_t agent;
    /// The agent's settings; with values ROBOT_VALUES_ROOM its gamma and theta are replaced by
    /// what the room gives (robot_config_agent_params()).
    agent_params_t params;
    uint8_t values;  ///< robot_values_t
    /// Planning updates per real step; 0 = as many as the idle time allows (the firmware default).
    uint32_t planning;
    uint32_t step_cap;     ///< real steps after which an episode ends without the goal

    // Pose source and its sensors.
    robot_pose_source_t pose_source;
    uint8_t n_beacons;
    robot_beacon_t beacons[ROBOT_MAX_BEACONS];
    float listener_z;      ///< height of the robot's Cricket listener
    /// m/s at which the Cricket's time of flight (DR) becomes a range: the room's speed of sound,
    /// 331.3 + 0.606 per degree C; 0: the driver's 343 (20 degrees C). A Cricket robot only.
    float speed_of_sound;

    // Safety: stop the wheels when the pose or the bus has been silent this long.
    uint32_t pose_timeout_us;
    uint32_t bus_timeout_us;
} robot_config_t;

/// The paper's two scenarios, as shipped in host_sim/scenarios/ (docs/scenarios.md).
extern const robot_config_t robot_config_paper_sim;
extern const robot_config_t robot_config_paper_lab;

/// Fills `cfg` with what every scenario shares unless it says otherwise: the paper's 192 ms
/// control period, rewards +100 goal, -100 bump, -1 step, Dyna-QPC with agent_default_params()
/// and theta 1e-3, a GPS pose that times out after 1 s, the bus after 500 ms. The arena, the
/// goal, the state encoding, the sensors and the actions stay zero: robot_config_check()
/// refuses the result until a scenario fills them in.
void robot_config_defaults(robot_config_t *cfg);

/// The agent's learning settings for `cfg`: its params, with gamma and theta from the room when
/// cfg->values is ROBOT_VALUES_ROOM (ROBOT_HORIZON_PER_SIDE_CELL, ROBOT_REWARD_PER_THETA).
agent_params_t robot_config_agent_params(const robot_config_t *cfg);

/// Checks a configuration's ranges and relations. Returns FW_OK or FW_ERR_INVAL.
int robot_config_check(const robot_config_t *cfg);


#ifdef __cplusplus
}
#endif

#endif // ROBOT_CONFIG_H
