// SPDX-License-Identifier: MIT
// dynaqpc robot application: the paper's two scenarios, compiled in for the MCU images.
// They must match host_sim/scenarios/*.scn (a test compares them); docs/scenarios.md says why
// each value is what it is.
#include "robot/robot_config.h"

#include "fw/fw_util.h"

const robot_config_t robot_config_paper_sim = {
    .name = "paper-sim",
    .arena_w = 8.0f, .arena_h = 8.0f,
    .goal_x = 4.0f, .goal_y = 4.0f, .goal_r = 0.5f,
    .bits_x = 5, .bits_y = 5, .bits_heading = 4, .bits_code = 4,
    // 16 sonars, sonar i at 11.25 + 22.5 i degrees: front, left, right, back sectors of four
    // (the paper's 100 cm threshold).
    .rays_of_bit = {0xC003u, 0x003Cu, 0x3C00u, 0x03C0u},
    .code_threshold_m = {1.0f, 1.0f, 1.0f, 1.0f},
    .n_ranges = 16,
    .tile_shift = {0, 0, 0, 0},
    .step_m = 0.25f, .turn_rad = FW_PI_F / 2.0f, .track_m = 0.40f,
    // Two periods: a 90 degree turn in one would exceed 80 % of the gyro's 300 deg/s.
    .action_periods = 2, .aligned_actions = 1, .wait_for_fix = 0, .period_us = 192000u,
    .step_past_m = 0.05f,  // a fifth of the 25 cm cell
    .reward_goal = 100.0f, .reward_bump = -100.0f, .reward_step = -1.0f,
    .agent = AGENT_DYNA_QPC,
    .params = {0.9f, 0.9f, 0.9f, 0.01f, 1e-3f, 0.999f, 16, 1},
    .planning = 5,
    .step_cap = 5000,
    .pose_source = ROBOT_POSE_GPS,
    .n_beacons = 0,
    .pose_timeout_us = 1000000u,
    .bus_timeout_us = 500000u,
};

const robot_config_t robot_config_paper_lab = {
    .name = "paper-lab",
    .arena_w = 4.3f, .arena_h = 3.2f,
    .goal_x = 3.75f, .goal_y = 2.55f, .goal_r = 0.3f, .goal_cells = 1,
    .bits_x = 3, .bits_y = 3, .bits_heading = 4, .bits_code = 3,
    // IR 0 front, 1 front-left, 2 front-right: one bit each, obstacle within 30 cm.
    .rays_of_bit = {0x1u, 0x2u, 0x4u, 0u},
    .code_threshold_m = {0.30f, 0.30f, 0.30f, 0.0f},
    .n_ranges = 3,
    .tile_shift = {0, 0, 0, 0},
    .step_m = 0.25f, .turn_rad = FW_PI_F / 2.0f, .track_m = 0.18f,
    // Two periods: a 90 degree turn in one would exceed 80 % of the gyro's 300 deg/s.
    .action_periods = 2, .aligned_actions = 1, .wait_for_fix = 1, .period_us = 192000u,
    // 16 cm into a 54 x 40 cm cell: the front IR then reads a wall at the next cell edge ahead at
    // 25 cm (x) or 12 cm (y), well inside its 30 cm bit (docs/scenarios.md).
    .step_past_m = 0.16f,
    .reward_goal = 100.0f, .reward_bump = -100.0f, .reward_step = -1.0f,
    .agent = AGENT_DYNA_QPC,
    .params = {0.9f, 0.9f, 0.9f, 0.1f, 1e-3f, 0.999f, 16, 1},
    .planning = 5,
    .step_cap = 200,
    .pose_source = ROBOT_POSE_CRICKET,
    .n_beacons = 5,
    .beacons = {{0x015E3C3C0A0000B1u, 0.5f, 0.5f, 2.5f}, {0x015E3C3C0A0000B2u, 3.8f, 0.5f, 2.5f},
                {0x015E3C3C0A0000B3u, 0.5f, 2.7f, 2.5f}, {0x015E3C3C0A0000B4u, 3.8f, 2.7f, 2.5f},
                {0x015E3C3C0A0000B5u, 2.15f, 1.6f, 2.5f}},
    .listener_z = 0.15f,
    .pose_timeout_us = 5000000u,
    .bus_timeout_us = 500000u,
};
