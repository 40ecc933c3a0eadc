// SPDX-License-Identifier: MIT
// dynaqpc robot application: the paper-sim-large image's entry point (its own object file, so
// an image links only the agent profile it uses). Its built-in scenario is paper-sim's robot on
// a 16 x 16 m floor of 64 x 64 equal cells (6 bits of x and of y), the goal at the floor's centre
// as paper-sim's is; the discount and the sweep threshold follow the floor (ROBOT_VALUES_ROOM).
#include "robot/agent_profiles.h"
#include "robot/robot_app.h"
#include "robot/robot_main.h"

void robot_config_paper_sim_large(robot_config_t *out)
{
    *out = robot_config_paper_sim;
    out->name = "paper-sim-large";
    out->arena_w = 16.0f;
    out->arena_h = 16.0f;
    out->goal_x = 8.0f;
    out->goal_y = 8.0f;
    out->bits_x = 6;
    out->bits_y = 6;
    out->grid[0].cells = 0;  // equal cells: paper-sim's grid is fitted to its own 8 x 8 m room
    out->grid[1].cells = 0;
}

void robot_main_paper_sim_large(void)
{
    static robot_config_t config;
    robot_config_paper_sim_large(&config);
    robot_app_run(&config, &agent_paper_sim_large, &agent_storage_paper_sim_large);
}
