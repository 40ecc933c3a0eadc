// SPDX-License-Identifier: MIT
// dynaqpc robot application: the paper-sim image's entry point (its own object file, so an
// image links only the agent profile it uses).
#include "robot/agent_profiles.h"
#include "robot/robot_app.h"
#include "robot/robot_main.h"

void robot_main_paper_sim(void)
{
    robot_app_run(&robot_config_paper_sim, &agent_paper_sim, &agent_storage_paper_sim);
}
