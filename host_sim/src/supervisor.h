// SPDX-License-Identifier: MIT
// dynaqpc-sim: what the operator of a learning run does on the bus, shared by the lock-step
// runner and `dynaqpc-sim devices --supervise`.
#ifndef DYNAQPC_SIM_SUPERVISOR_H
#define DYNAQPC_SIM_SUPERVISOR_H

#include <cstdint>

#include "hal/hal_can.h"
#include "robot/robot_config.h"
#include "world/world.h"

namespace dynaqpc {

/// The TOOL_CMD START_EPISODE the operator sends after putting the robot down at `start`. Its
/// argument is the start heading (0.01 deg) for a robot whose only heading sensor is a gyro
/// (Cricket pose source), 0xFFFFFFFF otherwise. Throws std::runtime_error if it cannot be encoded.
hal_can_frame_t start_episode_frame(const robot_config_t &cfg, const world::Pose &start,
                                    std::uint8_t *counter);

/// A generous bound on one episode's robot time: the step cap's actions and fix waits, plus 10 s.
/// An episode that outlasts it means the firmware stopped ending episodes.
std::uint64_t episode_limit_us(const robot_config_t &cfg);

}  // namespace dynaqpc

#endif  // DYNAQPC_SIM_SUPERVISOR_H
