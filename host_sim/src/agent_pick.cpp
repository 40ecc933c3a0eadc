// SPDX-License-Identifier: MIT
#include "agent_pick.h"

namespace dynaqpc {

void pick_agent_profile(const robot_config_t &cfg, agent_t **agent, const agent_storage_t **storage)
{
    const unsigned bits = cfg.bits_x + cfg.bits_y + cfg.bits_heading + cfg.bits_code;
    if (bits <= 13u) {
        *agent = &agent_paper_lab;
        *storage = &agent_storage_paper_lab;
    } else {
        *agent = &agent_paper_sim;
        *storage = &agent_storage_paper_sim;
    }
}

robot_app_options_t host_app_options(const robot_config_t &cfg, std::uint32_t seed)
{
    robot_app_options_t ao{};
    agent_t *agent = nullptr;
    const agent_storage_t *storage = nullptr;
    pick_agent_profile(cfg, &agent, &storage);
    ao.cfg = &cfg;
    ao.agent = agent;
    ao.storage = storage;
    ao.seed = seed;
    ao.persist = true;
    return ao;
}

}  // namespace dynaqpc
