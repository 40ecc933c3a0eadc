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

}  // namespace dynaqpc
