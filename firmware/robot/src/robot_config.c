// SPDX-License-Identifier: MIT
// dynaqpc robot application: the configuration every scenario starts from.
#include "robot/robot_config.h"

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
        const float side_cells = (float)((1u << cfg->bits_x) + (1u << cfg->bits_y));
        p.gamma = 1.0f - 1.0f / (ROBOT_HORIZON_PER_SIDE_CELL * side_cells);
        float scale = magnitude_(cfg->reward_goal);
        scale = magnitude_(cfg->reward_bump) > scale ? magnitude_(cfg->reward_bump) : scale;
        scale = magnitude_(cfg->reward_step) > scale ? magnitude_(cfg->reward_step) : scale;
        p.theta = scale / ROBOT_REWARD_PER_THETA;
    }
    return p;
}
