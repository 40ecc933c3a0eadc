// SPDX-License-Identifier: MIT
// dynaqpc-sim agents: the learning algorithms the firmware registers (agent/algorithms.h), with
// their labels, models, planning costs and counters, as a table or as JSON for the tools
// (tools/dynaqpc_tools/agents.py). Nothing here names an algorithm: adding one to the registry
// adds it here.
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "agent_pick.h"
#include "commands.h"
#include "options.h"
#include "robot/robot_geometry.h"
#include "scenario_bridge.h"

namespace dynaqpc {

namespace {

struct ModelInfo {
    std::string name;
    std::vector<std::string> counters;
};

struct AlgorithmInfo {
    agent_kind_t kind = AGENT_Q_LEARNING;
    agent_info_t info{};
    std::vector<std::string> counters;  // with the default model
    std::vector<ModelInfo> models;      // the models it runs operations of its own with
};

// The counters an agent of `kind` with `model` lists, asked of one initialised on paper-lab's
// profile (epsilon-greedy: the bonus modes add tried_pairs and tried_forgotten).
std::vector<std::string> counter_names(const robot_config_t &robot, agent_kind_t kind, std::uint8_t model)
{
    robot_config_t cfg = robot;
    cfg.agent = kind;
    cfg.params.model = model;
    cfg.params.explore = AGENT_EXPLORE_EGREEDY;
    agent_space_t sp;
    robot_config_space(&cfg, &sp);
    agent_t *ag = nullptr;
    const agent_storage_t *storage = nullptr;
    pick_agent_profile(cfg, &ag, &storage);
    const agent_config_t ac = {kind, &sp, cfg.params, storage, 1u};
    std::vector<std::string> names;
    if (agent_init(ag, &ac) != FW_OK) return names;
    agent_counter_t c[AGENT_MAX_COUNTERS];
    const std::uint32_t n = agent_counters(ag, c);
    for (std::uint32_t i = 0; i < n; i++) names.emplace_back(c[i].name);
    return names;
}

std::vector<AlgorithmInfo> registry()
{
    const robot_config_t robot = load_scenario("paper-lab").robot;
    std::vector<AlgorithmInfo> out;
    for (std::uint32_t k = 0; k < AGENT_KINDS; k++) {
        AlgorithmInfo a;
        a.kind = static_cast<agent_kind_t>(k);
        (void)agent_kind_info(a.kind, &a.info);
        a.counters = counter_names(robot, a.kind, AGENT_MODEL_RELOCATABLE);
        for (std::uint32_t m = 0; m < AGENT_MODELS; m++) {
            if (agent_kind_has_model(a.kind, static_cast<std::uint8_t>(m))) {
                a.models.push_back({agent_model_name(static_cast<std::uint8_t>(m)),
                                    counter_names(robot, a.kind, static_cast<std::uint8_t>(m))});
            }
        }
        out.push_back(a);
    }
    return out;
}

std::string json_list(const std::vector<std::string> &v)
{
    std::string s = "[";
    for (std::size_t i = 0; i < v.size(); i++) s += (i ? ",\"" : "\"") + v[i] + "\"";
    return s + "]";
}

std::string json_of(const std::vector<AlgorithmInfo> &algs)
{
    std::ostringstream o;
    o << "{\"format\":\"dynaqpc-agents 1\",\"agents\":[";
    for (std::size_t i = 0; i < algs.size(); i++) {
        const AlgorithmInfo &a = algs[i];
        o << (i ? ",\n" : "\n") << "{\"name\":\"" << a.info.name << "\",\"number\":" << static_cast<unsigned>(a.kind)
          << ",\"label\":\"" << a.info.label << "\",\"plan_cycles\":" << a.info.plan_cycles
          << ",\"counters\":" << json_list(a.counters) << ",\"models\":[";
        for (std::size_t m = 0; m < a.models.size(); m++) {
            o << (m ? "," : "") << "{\"name\":\"" << a.models[m].name << "\",\"counters\":" << json_list(a.models[m].counters)
              << "}";
        }
        o << "]}";
    }
    o << "]}\n";
    return o.str();
}

}  // namespace

int cmd_agents(const std::string &program, const std::vector<std::string> &args)
{
    bool json = false;
    Options o("agents", "the learning algorithms the firmware registers (agent/algorithms.h)");
    o.add_flag("--json", "as JSON, for the tools (format \"dynaqpc-agents 1\", docs/tools.md)", &json);
    if (o.parse_or_usage(args, program)) {
        return kExitOk;
    }
    const std::vector<AlgorithmInfo> algs = registry();
    if (json) {
        std::fputs(json_of(algs).c_str(), stdout);
        return kExitOk;
    }
    std::printf("%-16s %-6s %-20s %-11s %s\n", "name", "number", "label", "plan_cycles", "models");
    for (const AlgorithmInfo &a : algs) {
        std::string models;
        for (const ModelInfo &m : a.models) models += (models.empty() ? "" : ",") + m.name;
        std::printf("%-16s %-6u %-20s %-11u %s\n", a.info.name, static_cast<unsigned>(a.kind), a.info.label,
                    a.info.plan_cycles, models.empty() ? "-" : models.c_str());
    }
    return kExitOk;
}

}  // namespace dynaqpc
