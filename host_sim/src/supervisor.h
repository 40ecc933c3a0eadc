// SPDX-License-Identifier: MIT
// dynaqpc-sim: what the operator of a learning run does on the bus, shared by the lock-step
// runner and `dynaqpc-sim devices --supervise`.
#ifndef DYNAQPC_SIM_SUPERVISOR_H
#define DYNAQPC_SIM_SUPERVISOR_H

#include <cstdint>
#include <string>

#include "hal/hal_can.h"
#include "robot/robot_config.h"
#include "world/world.h"

namespace dynaqpc {

/// The TOOL_CMD START_EPISODE the operator sends after putting the robot down at `start`. Its
/// argument is the start heading (0.01 deg) for a robot whose only heading sensor is a gyro
/// (Cricket pose source), 0xFFFFFFFF otherwise. Throws std::runtime_error if it cannot be encoded.
hal_can_frame_t start_episode_frame(const robot_config_t &cfg, const world::Pose &start,
                                    std::uint8_t *counter);

/// A generous bound on one episode's robot time: the step cap's steps, each as long as a step
/// across the grid's largest cell and a back-off as far with their corrections, and fix waits,
/// plus 10 s. An episode that outlasts it means the firmware stopped ending episodes.
std::uint64_t episode_limit_us(const robot_config_t &cfg);

/// How far the firmware's idea of where it is (its TLM_POSE) is from the simulated robot's true
/// pose, at each real step's observation (the TLM_LEARN that follows the period's TLM_POSE):
/// the robot then stands still waiting for its fix, so the comparison is fair on a real-time bus
/// as in lock-step. A heading that drifts puts the robot in other states and its aligned moves
/// off the grid; the closed loop's diagnosis (docs/results/emulated-board.md) reads it.
class PoseCheck {
public:
    /// A frame from the firmware; `truth` is the world's pose now.
    void on_frame(const hal_can_frame_t &f, const world::Pose &truth);
    void reset();
    std::uint32_t steps() const { return n_; }
    double heading_err_mean_deg() const { return n_ ? heading_sum_ / n_ : 0.0; }
    double heading_err_max_deg() const { return heading_max_; }
    double position_err_mean_m() const { return n_ ? position_sum_ / n_ : 0.0; }
    /// The grid of headings a step should start on (the scenario's turn, rad; 0: none). With
    /// it, steps() counts also the steps whose true heading is more than 10 degrees off it.
    void set_heading_grid(double turn_rad) { grid_rad_ = turn_rad; }
    std::uint32_t off_grid_steps() const { return off_grid_; }
    /// Steps learned from (TLM_LEARN Step >= 1) with the firmware's heading over 20 degrees off.
    std::uint32_t learned_over_20deg() const { return over20_; }
    /// The last TLM_LEARN seen: whether it was a step learned from (Step >= 1), and the heading
    /// error then, degrees (-1: none seen since reset).
    bool last_learned() const { return last_learned_; }
    double last_heading_err_deg() const { return last_err_deg_; }
    /// "head_err_mean_deg=.. head_err_max_deg=.. pos_err_mean_m=.. off_grid_10deg=K/N"
    std::string summary() const;

private:
    bool have_pose_ = false;
    double fw_x_ = 0.0, fw_y_ = 0.0, fw_heading_deg_ = 0.0;
    std::uint32_t n_ = 0;
    double heading_sum_ = 0.0, heading_max_ = 0.0, position_sum_ = 0.0;
    double grid_rad_ = 0.0;
    std::uint32_t off_grid_ = 0;
    std::uint32_t over20_ = 0;  // learned steps (TLM_LEARN Step >= 1) with the heading over 20 degrees off
    bool last_learned_ = false;
    double last_err_deg_ = -1.0;
};

}  // namespace dynaqpc

#endif  // DYNAQPC_SIM_SUPERVISOR_H
