// SPDX-License-Identifier: MIT
// dynaqpc robot application: the entry point of a firmware image.
#ifndef ROBOT_MAIN_H
#define ROBOT_MAIN_H

#include "robot/robot_config.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Boots the firmware with the paper-lab (or paper-sim) scenario built in and its agent profile,
/// restores what was learned from flash, waits for the operator's TOOL_CMD to start episodes,
/// and runs the main loop for ever. Each is in its own object file, so an image links only the
/// profile it uses.
void robot_main_paper_lab(void);
void robot_main_paper_sim(void);
/// paper-sim's robot on a 16 x 16 m floor with the paper-sim-large profile (the STM32F427's
/// 256 KiB image).
void robot_main_paper_sim_large(void);
/// That image's scenario, built from paper-sim's (robot_scenarios.c) into `out`.
void robot_config_paper_sim_large(robot_config_t *out);

/// What an image's main() calls: the profile the image is built for (DYNAQPC_PROFILE_PAPER_LAB
/// DYNAQPC_PROFILE_PAPER_SIM or DYNAQPC_PROFILE_PAPER_SIM_LARGE defined on main.c). `scenario_config` is reserved (NULL).
static inline void robot_main(const void *scenario_config)
{
    (void)scenario_config;
#if defined(DYNAQPC_PROFILE_PAPER_SIM_LARGE)
    robot_main_paper_sim_large();
#elif defined(DYNAQPC_PROFILE_PAPER_SIM)
    robot_main_paper_sim();
#else
    robot_main_paper_lab();
#endif
}

#ifdef __cplusplus
}
#endif

#endif // ROBOT_MAIN_H
