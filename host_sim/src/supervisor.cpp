// SPDX-License-Identifier: MIT
// dynaqpc-sim: the operator's frames and bounds.
#include "supervisor.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "drivers/telemetry.h"
#include "dynaqpc_can.h"
#include "fw/fw_util.h"
#include "robot/robot_geometry.h"
#include "robot/robot_motion.h"

namespace dynaqpc {

hal_can_frame_t start_episode_frame(const robot_config_t &cfg, const world::Pose &start,
                                    std::uint8_t *counter)
{
    double h = std::fmod(start.heading * 18000.0 / FW_PI, 36000.0);
    if (h < 0) h += 36000.0;
    tlm_tool_cmd_t cmd{};
    cmd.command = TLM_CMD_START_EPISODE;
    cmd.argument = cfg.pose_source == ROBOT_POSE_CRICKET ? static_cast<std::uint32_t>(h) % 36000u : 0xFFFFFFFFu;
    hal_can_frame_t f;
    if (tlm_encode_tool_cmd(counter, &cmd, &f) != 0) {
        throw std::runtime_error("cannot encode TOOL_CMD");
    }
    return f;
}

// A real step's periods: its motion, which takes action_periods per step_m driven, and an aligned
// step drives across up to a whole cell and past its edge (a fitted sonar cell is 0.6 m, 2.4
// steps); a step that bumps backs off, as far again; each motion's closed-loop corrections; and
// the observation (a fix's wait). The fixed action_periods alone were outlasted by a frozen
// robot bumping its way to the step cap in paper-sim-blocked: `run` stopped with an error.
std::uint64_t episode_limit_us(const robot_config_t &cfg)
{
    float longest = cfg.step_m;
    for (std::uint32_t axis = 0; axis < 2u; axis++) {
        for (std::uint32_t k = 0; k < robot_grid_cells(&cfg, axis); k++) {
            float lo = 0.0f, side = 0.0f;
            robot_grid_span(&cfg, axis, k, &lo, &side);
            longest = std::max(longest, side + cfg.step_past_m);
        }
    }
    const std::uint64_t motion = static_cast<std::uint64_t>(std::ceil(longest / cfg.step_m)) * cfg.action_periods;
    const std::uint64_t per_step = 2u * (motion + ROBOT_RUN_MAX_CORRECTIONS) + (cfg.wait_for_fix ? 60u : 1u);
    return static_cast<std::uint64_t>(cfg.step_cap + 2) * per_step * cfg.period_us + 10000000u;
}

void PoseCheck::on_frame(const hal_can_frame_t &f, const world::Pose &truth)
{
    if (f.id == DYNAQPC_CAN_TLM_POSE_FRAME_ID) {
        tlm_pose_t p;
        if (tlm_decode_pose(&f, &p) == 0) {
            fw_x_ = p.x_mm * 1e-3;
            fw_y_ = p.y_mm * 1e-3;
            fw_heading_deg_ = p.heading_cdeg * 0.01;
            have_pose_ = true;
        }
    } else if (f.id == DYNAQPC_CAN_TLM_LEARN_FRAME_ID && have_pose_) {
        constexpr double kDegPerRad = 57.29577951308232;
        double e = std::fmod(fw_heading_deg_ - truth.heading * kDegPerRad, 360.0);
        if (e > 180.0) e -= 360.0;
        if (e < -180.0) e += 360.0;
        e = std::fabs(e);
        tlm_learn_t l;
        const bool decoded = tlm_decode_learn(&f, &l) == 0;
        if (std::getenv("DYNAQPC_POSE_TRACE") != nullptr) {
            std::printf("posecheck fw=%.3f,%.3f,%.1f world=%.3f,%.3f,%.1f step=%u\n", fw_x_, fw_y_, fw_heading_deg_,
                        truth.x, truth.y, truth.heading * kDegPerRad, decoded ? (unsigned)l.step : 0u);
        }
        heading_sum_ += e;
        heading_max_ = std::max(heading_max_, e);
        last_learned_ = decoded && l.step >= 1u;  // a step learned from
        last_err_deg_ = e;
        if (e > 20.0 && last_learned_) over20_++;
        position_sum_ += std::hypot(fw_x_ - truth.x, fw_y_ - truth.y);
        if (grid_rad_ > 0.0) {
            // How far the true heading is from the nearest heading of the turn grid.
            const double k = std::round(truth.heading / grid_rad_);
            if (std::fabs(truth.heading - k * grid_rad_) * kDegPerRad > 10.0) off_grid_++;
        }
        n_++;
    }
}

void PoseCheck::reset()
{
    const double grid = grid_rad_;
    *this = PoseCheck{};
    grid_rad_ = grid;
}

std::string PoseCheck::summary() const
{
    char buf[192];
    std::snprintf(buf, sizeof buf, "head_err_mean_deg=%.1f head_err_max_deg=%.1f pos_err_mean_m=%.3f",
                  heading_err_mean_deg(), heading_err_max_deg(), position_err_mean_m());
    char grid[48];
    if (grid_rad_ > 0.0) {
        std::snprintf(grid, sizeof grid, " off_grid_10deg=%u/%u", off_grid_, n_);
    } else {
        std::snprintf(grid, sizeof grid, " off_grid_10deg=none");  // no heading grid to be off
    }
    return std::string(buf) + grid;
}

}  // namespace dynaqpc
