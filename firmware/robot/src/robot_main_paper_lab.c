// SPDX-License-Identifier: MIT
// dynaqpc robot application: the paper-lab image's entry point (its own object file, so an
// image links only the agent profile it uses).
#include "robot/agent_profiles.h"
#include "robot/robot_app.h"
#include "robot/robot_main.h"

void robot_main_paper_lab(void)
{
    robot_app_run(&robot_config_paper_lab, &agent_paper_lab, &agent_storage_paper_lab);
}
