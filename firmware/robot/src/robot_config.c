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
        .pose_source = ROBOT_POSE_GPS,
        .pose_timeout_us = 1000000u,
        .bus_timeout_us = 500000u,
    };
}
