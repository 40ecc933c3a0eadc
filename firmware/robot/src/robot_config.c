// SPDX-License-Identifier: MIT
// dynaqpc robot application: the configuration every scenario starts from.
#include "robot/robot_config.h"
#include "robot/robot_geometry.h"

void robot_config_defaults(robot_config_t *cfg)
{
    agent_params_t params = agent_default_params();
    params.theta = 1e-3f;  // docs/agent.md: the priority below which a pair is not queued
    *cfg = (robot_config_t){
        .name = "",
        .period_us = 192000u,
        .action_periods = 1,
        .reward_goal = 100.0f,
        .reward_bump = -100.0f,
        .reward_step = -1.0f,
        .agent = AGENT_DYNA_QPC,
        .params = params,
        .values = ROBOT_VALUES_ROOM,
        .pose_source = ROBOT_POSE_GPS,
        .pose_timeout_us = 1000000u,
        .bus_timeout_us = 500000u,
    };
}

static float magnitude_(float x)
{
    return x < 0.0f ? -x : x;
}

// Whether a walk of side_cells steps (along the floor's two sides) ends beyond n0, the distance
// from the goal at which a path's value R gamma^n - |r| (1 - gamma^n) / (1 - gamma) crosses zero
// (R the goal's reward, r a step's). n0 = ln(|r| / ((1 - gamma) R + |r|)) / ln(gamma); compared
// as gamma^side_cells < |r| / ((1 - gamma) R + |r|) to stay clear of logarithms of 0.
static bool robot_goal_beyond_zero_crossing_(const robot_config_t *cfg, float gamma,
                                             uint32_t side_cells)
{
    const float step = -cfg->reward_step;
    const float goal = cfg->reward_goal;
    if (step <= 0.0f || goal <= 0.0f || gamma >= 1.0f) {
        return false;  // steps cost nothing, or no goal reward: known values never fall below 0
    }
    float walk = 1.0f;  // gamma^side_cells, by squaring
    float base = gamma;
    for (uint32_t n = side_cells; n > 0u; n >>= 1) {
        if (n & 1u) {
            walk *= base;
        }
        base *= base;
    }
    return walk < step / ((1.0f - gamma) * goal + step);
}

agent_params_t robot_config_agent_params(const robot_config_t *cfg)
{
    agent_params_t p = cfg->params;
    // A step that earns the ordinary reward and leaves the state as it was did not leave its cell
    // (a fixed step shorter than the cell): Dyna-QPC's model counts it beside the move (model.h).
    p.stays = 1u;
    p.step_reward = cfg->reward_step;
    if (cfg->values == ROBOT_VALUES_ROOM) {
        // The paper's gamma 0.9 halves a reward's weight every 6.6 steps: 60 steps from the goal
        // a state differs from its neighbour by about 0.02, below the noise of one bump, and the
        // robot does not learn where the goal is far. The horizon grows with the floor instead;
        // the longest shortest path of a room is a few times its sides in cells (a serpentine
        // more, an open floor less), and the e^-1 at H steps still leaves a usable gradient
        // beyond.
        const uint32_t side_cells = robot_grid_cells(cfg, ROBOT_AXIS_X) + robot_grid_cells(cfg, ROBOT_AXIS_Y);
        p.gamma = 1.0f - 1.0f / (ROBOT_HORIZON_PER_SIDE_CELL * (float)side_cells);
        float scale = magnitude_(cfg->reward_goal);
        scale = magnitude_(cfg->reward_bump) > scale ? magnitude_(cfg->reward_bump) : scale;
        scale = magnitude_(cfg->reward_step) > scale ? magnitude_(cfg->reward_step) : scale;
        p.theta = scale / ROBOT_REWARD_PER_THETA;
        // A state the robot never met is worth less than nothing where every step costs and the
        // goal can be far: with a prior of 0 every known state more than n0 steps from the goal
        // (where its value crosses zero) looks worse than any state the robot does not know, and
        // in a long room the robot that has found the goal keeps leaving its path for states it
        // has not met (docs/agent.md, "What an unknown state is worth"). Where a walk along the
        // floor's two sides is longer than n0, unknown states start at a share of the value of
        // wandering for ever, reward_step / (1 - gamma): below every state near the goal, above
        // the far ones nothing has reached yet. Where it is not (the lab robot's floors, whose
        // n0 is 23-30 steps), the paper's optimistic 0 stays, and with it the exploration it
        // drives.
        if (robot_goal_beyond_zero_crossing_(cfg, p.gamma, side_cells)) {
            p.q_prior = ROBOT_PRIOR_SHARE * cfg->reward_step / (1.0f - p.gamma);
        }
    }
    return p;
}
