// SPDX-License-Identifier: MIT
// dynaqpc-sim: the operator's frames and bounds.
#include "supervisor.h"

#include <cmath>
#include <stdexcept>

#include "drivers/telemetry.h"
#include "fw/fw_util.h"

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

std::uint64_t episode_limit_us(const robot_config_t &cfg)
{
    return static_cast<std::uint64_t>(cfg.step_cap + 2) * (cfg.action_periods + (cfg.wait_for_fix ? 60u : 1u)) *
               cfg.period_us + 10000000u;
}

}  // namespace dynaqpc
