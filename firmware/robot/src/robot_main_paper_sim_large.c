// SPDX-License-Identifier: MIT
// dynaqpc robot application: the paper-sim-large image's entry point (its own object file, so
// an image links only the agent profile it uses). Its built-in scenario is paper-sim's robot on
// a 16 x 16 m floor, 64 x 64 cells (6 bits of x and of y), the goal at the floor's centre as
// paper-sim's is; the discount and the sweep threshold follow the floor (ROBOT_VALUES_ROOM).
#include "robot/agent_profiles.h"
#include "robot/robot_app.h"
#include "robot/robot_main.h"

static robot_config_t config_;

void robot_main_paper_sim_large(void)
{
    config_ = robot_config_paper_sim;
    config_.name = "paper-sim-large";
    config_.arena_w = 16.0f;
    config_.arena_h = 16.0f;
    config_.goal_x = 8.0f;
    config_.goal_y = 8.0f;
    config_.bits_x = 6;
    config_.bits_y = 6;
    robot_app_run(&config_, &agent_paper_sim_large, &agent_storage_paper_sim_large);
}
