// SPDX-License-Identifier: MIT
// dynaqpc robot application: the shipped scenarios, compiled in for the MCU images.
//
// GENERATED from host_sim/scenarios/*.scn by `dynaqpc-sim firmware-config --out <this file>`
// (host_sim/src/firmware_config.cpp): edit the .scn files, then regenerate. The test
// sim.firmware_config.up_to_date fails when this file differs from what they give.
#include "robot/robot_config.h"

const robot_config_t robot_config_paper_sim = {
    .name = "paper-sim",
    .arena_w = 8.0f, .arena_h = 8.0f,
    .goal_x = 4.0f, .goal_y = 4.0f, .goal_r = 0.5f, .goal_cells = 0,
    .bits_x = 5, .bits_y = 5, .bits_heading = 4, .bits_code = 4,
    .grid = {{.cells = 18, .edge = {0.0f, 0.575f, 1.15f, 1.45f, 1.925f, 2.4f, 2.6f, 3.0f, 3.4f, 4.0f, 4.6f, 5.0f, 5.4f, 5.6f, 6.08f, 6.56f, 7.04f, 7.52f, 8.0f}},
             {.cells = 18, .edge = {0.0f, 0.48f, 0.96f, 1.44f, 1.92f, 2.4f, 2.6f, 3.3f, 3.4f, 4.0f, 4.6f, 4.7f, 5.4f, 5.6f, 6.08f, 6.56f, 7.04f, 7.52f, 8.0f}}},
    .rays_of_bit = {0xC003u, 0x003Cu, 0x3C00u, 0x03C0u},
    .code_threshold_m = {1.0f, 1.0f, 1.0f, 1.0f},
    .n_ranges = 16,
    .tile_shift = {0, 0, 0, 0},
    .step_m = 0.25f, .turn_rad = 1.5707964f, .track_m = 0.4f,
    .action_periods = 2, .aligned_actions = 1, .step_past_m = 0.05f,
    .wait_for_fix = 0, .period_us = 192000u,
    .reward_goal = 100.0f, .reward_bump = -100.0f, .reward_step = -1.0f,
    .agent = AGENT_DYNA_QPC,
    .params = {.alpha = 0.9f, .plan_alpha = 0.9f, .gamma = 0.95555556f, .epsilon = 0.01f,
               .theta = 0.001f, .model_rate = 0.999f, .tilings = 16, .min_count = 1,
               .model = AGENT_MODEL_RELOCATABLE, .model_tile_shift = {0, 0, 0, 1},
               .explore = 0, .kappa = 0.0f},
    .values = ROBOT_VALUES_ROOM,
    .planning = 0u, .step_cap = 5000u,
    .pose_source = ROBOT_POSE_GPS,
    .n_beacons = 0,
    .listener_z = 0.1f,
    .pose_timeout_us = 1000000u, .bus_timeout_us = 500000u,
};

const robot_config_t robot_config_paper_lab = {
    .name = "paper-lab",
    .arena_w = 4.3f, .arena_h = 3.2f,
    .goal_x = 3.75f, .goal_y = 2.55f, .goal_r = 0.3f, .goal_cells = 1,
    .bits_x = 3, .bits_y = 3, .bits_heading = 4, .bits_code = 3,
    .rays_of_bit = {0x0001u, 0x0002u, 0x0004u, 0x0000u},
    .code_threshold_m = {0.3f, 0.3f, 0.3f, 0.0f},
    .n_ranges = 3,
    .tile_shift = {0, 0, 0, 0},
    .step_m = 0.25f, .turn_rad = 1.5707964f, .track_m = 0.18f,
    .action_periods = 2, .aligned_actions = 1, .step_past_m = 0.16f,
    .wait_for_fix = 1, .period_us = 192000u,
    .reward_goal = 100.0f, .reward_bump = -100.0f, .reward_step = -1.0f,
    .agent = AGENT_DYNA_QPC,
    .params = {.alpha = 0.9f, .plan_alpha = 0.9f, .gamma = 0.9f, .epsilon = 0.1f,
               .theta = 0.001f, .model_rate = 0.999f, .tilings = 16, .min_count = 1,
               .model = AGENT_MODEL_RELOCATABLE, .model_tile_shift = {0, 0, 0, 1},
               .explore = 0, .kappa = 0.0f},
    .values = ROBOT_VALUES_ROOM,
    .planning = 0u, .step_cap = 200u,
    .pose_source = ROBOT_POSE_CRICKET,
    .n_beacons = 5,
    .beacons = {{0x015E3C3C0A0000B1u, 0.5f, 0.5f, 2.5f},
                {0x015E3C3C0A0000B2u, 3.8f, 0.5f, 2.5f},
                {0x015E3C3C0A0000B3u, 0.5f, 2.7f, 2.5f},
                {0x015E3C3C0A0000B4u, 3.8f, 2.7f, 2.5f},
                {0x015E3C3C0A0000B5u, 2.15f, 1.6f, 2.5f}},
    .listener_z = 0.15f,
    .speed_of_sound = 343.0f,
    .pose_timeout_us = 5000000u, .bus_timeout_us = 500000u,
};
