// SPDX-License-Identifier: MIT
// dynaqpc robot application: the paper-lab image's entry point.
#include "agent/agent_profiles.h"
#include "hal/hal_cpu.h"
#include "robot/robot_app.h"
#include "robot/robot_main.h"

void robot_main_paper_lab(void)
{
    robot_app_options_t opt = {0};
    opt.cfg = &robot_config_paper_lab;
    opt.agent = &agent_paper_lab;
    opt.storage = &agent_storage_paper_lab;
    opt.seed = 1;
    opt.persist = true;
    opt.plan_budget_us = ROBOT_PLAN_BUDGET_US;
    if (robot_app_init(&opt) != 0) {
        for (;;) {  // nothing safe to do: the motor controller stops on its own without commands
            hal_cpu_wait_until(UINT64_MAX);
        }
    }
    (void)hal_cpu_watchdog_start(ROBOT_WATCHDOG_MS);
    for (;;) {
        robot_app_step();
    }
}
