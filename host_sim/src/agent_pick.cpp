// SPDX-License-Identifier: MIT
#include "agent_pick.h"

#include <stdexcept>

#include "robot/robot_geometry.h"

namespace dynaqpc {

namespace {

enum class Profile { Lab, Sim, SimLarge };

// The profile a floor's state bits call for; profile_of() moves a floor the paper-lab
// profile's tables cannot hold up to paper-sim's.
Profile profile_by_bits(const robot_config_t &cfg)
{
    const unsigned bits = cfg.bits_x + cfg.bits_y + cfg.bits_heading + cfg.bits_code;
    if (bits <= 13u) return Profile::Lab;
    if (bits <= 18u) return Profile::Sim;
    return Profile::SimLarge;
}

// The MCU's bytes of one entry of the tables the floor sizes (model.h): a percept mask per
// place, an arrival per position, a class per situation and action.
constexpr std::uint32_t kPlaceBytes = sizeof(std::uint16_t);
constexpr std::uint32_t kPositionBytes = sizeof(std::int16_t);
constexpr std::uint32_t kClassBytes = sizeof(model_class_t);
// agent_t and the storage on the MCU: the host's overlay is 80 bytes larger (agent_profiles.h).
constexpr std::uint32_t kAgentBytes = 3544u;

std::uint32_t masked_bits(const agent_space_t &sp, std::uint32_t mask)
{
    std::uint32_t bits = 0;
    for (std::uint32_t k = 0; k < sp.n_components; k++) {
        if ((mask >> k) & 1u) bits += sp.bits[k];
    }
    return bits;
}

}  // namespace

#define PROFILE_BYTES_(P, mem_t) \
    static_cast<std::uint32_t>(sizeof(mem_t) - sizeof(((mem_t *)nullptr)->alg) + P(ALGORITHM_BYTES) + kAgentBytes)

// What each profile's image holds: its bytes and the floor-sized tables' entries.
struct ProfileTables {
    const char *name;
    std::uint32_t bytes, places, positions, classes;
};

ProfileTables tables_of(Profile p)
{
    switch (p) {
    case Profile::Lab:
        return {"paper-lab", PROFILE_BYTES_(AGENT_PROFILE_PAPER_LAB, agent_memory_paper_lab_t), FW_CFG_LAB_PLACES,
                FW_CFG_LAB_POSITIONS, FW_CFG_LAB_CLASSES};
    case Profile::Sim:
        return {"paper-sim", PROFILE_BYTES_(AGENT_PROFILE_PAPER_SIM, agent_memory_paper_sim_t), FW_CFG_SIM_PLACES,
                FW_CFG_SIM_POSITIONS, FW_CFG_SIM_CLASSES};
    case Profile::SimLarge:
        break;
    }
    return {"paper-sim-large",
            PROFILE_BYTES_(AGENT_PROFILE_PAPER_SIM_LARGE, agent_memory_paper_sim_large_t) +
                static_cast<std::uint32_t>(sizeof(agent_memory_paper_sim_large_apart_t)),
            FW_CFG_SIM_LARGE_PLACES, FW_CFG_SIM_LARGE_POSITIONS, FW_CFG_SIM_LARGE_CLASSES};
}

static ProfileNeed need_in(const robot_config_t &cfg, Profile p)
{
    const ProfileTables t = tables_of(p);
    const std::uint32_t places = t.places, positions = t.positions, classes = t.classes;
    ProfileNeed n{t.name, t.bytes, 0, {}};
    n.need_bytes = n.bytes;
    const unsigned state_bits = cfg.bits_x + cfg.bits_y + cfg.bits_heading + cfg.bits_code;
    if (p == Profile::SimLarge && !qstore_keys16_exact(FW_CFG_SIM_LARGE_Q_STATES, state_bits)) {
        // Its 16-bit Q keys hold states of up to 20 bits (qstore.h); beyond, keys of 32 bits.
        n.short_of = "state bits " + std::to_string(state_bits) + " > 20 (16-bit Q keys)";
        n.need_bytes += FW_CFG_SIM_LARGE_Q_STATES * static_cast<std::uint32_t>(sizeof(std::uint16_t));
    }
    // Only Dyna-QPC's relocatable model sizes tables by the floor (model_init()'s rule).
    if (cfg.agent != AGENT_DYNA_QPC || cfg.params.model != AGENT_MODEL_RELOCATABLE) return n;
    agent_space_t sp{};
    robot_config_space(&cfg, &sp);
    const std::uint32_t all = (1u << sp.n_components) - 1u;
    auto short_of = [&n](const char *what, std::uint64_t need, std::uint32_t have, std::uint32_t entry) {
        if (need <= have) return;
        if (!n.short_of.empty()) n.short_of += ", ";
        n.short_of += std::string(what) + " " + std::to_string(need) + " > " + std::to_string(have);
        n.need_bytes += static_cast<std::uint32_t>((need - have) * entry);
    };
    if (sp.absolute_mask != 0u) {
        const std::uint32_t every = masked_bits(sp, all & ~static_cast<std::uint32_t>(sp.absolute_mask));
        const std::uint32_t bits = every <= 24u && places >= (1u << every) ? every : every - sp.turn_step_bits;
        short_of("places", std::uint64_t{1} << bits, places, kPlaceBytes);
    }
    if (sp.context_mask != 0u) {
        const std::uint32_t context = masked_bits(sp, sp.context_mask);
        const std::uint32_t position =
            masked_bits(sp, all & ~static_cast<std::uint32_t>(sp.absolute_mask | sp.context_mask));
        short_of("situations x actions", (std::uint64_t{1} << context) * sp.n_actions, classes, kClassBytes);
        short_of("positions", std::uint64_t{1} << position, positions, kPositionBytes);
    }
    return n;
}

// A floor of few state bits whose model the 64 KiB image cannot hold (a fitted grid of more than
// 8 x 8 cells: paper-lab-motion's 9 x 7 on 8 headings) runs on the 192 KiB image.
static Profile profile_of(const robot_config_t &cfg)
{
    const Profile p = profile_by_bits(cfg);
    if (p == Profile::Lab && !need_in(cfg, Profile::Lab).short_of.empty()) return Profile::Sim;
    return p;
}

ProfileNeed profile_need(const robot_config_t &cfg)
{
    return need_in(cfg, profile_of(cfg));
}

void pick_agent_profile(const robot_config_t &cfg, agent_t **agent, const agent_storage_t **storage)
{
    const ProfileNeed need = profile_need(cfg);
    if (!need.short_of.empty()) {
        throw std::runtime_error(std::string(cfg.name != nullptr ? cfg.name : "the scenario") +
                                 " does not fit the " + need.profile + " agent profile (" +
                                 std::to_string(need.bytes) + " bytes of RAM): " + need.short_of +
                                 "; it needs " + std::to_string(need.need_bytes) + " bytes");
    }
    switch (profile_of(cfg)) {
    case Profile::Lab:
        *agent = &agent_paper_lab;
        *storage = &agent_storage_paper_lab;
        break;
    case Profile::Sim:
        *agent = &agent_paper_sim;
        *storage = &agent_storage_paper_sim;
        break;
    case Profile::SimLarge:
        *agent = &agent_paper_sim_large;
        *storage = &agent_storage_paper_sim_large;
        break;
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
