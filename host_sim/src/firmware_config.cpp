// SPDX-License-Identifier: MIT
// dynaqpc-sim: a robot_config_t as C source (see firmware_config.h).
//
// Why generated: the MCU images have no file system, so their scenarios are compiled in; the
// simulator reads host_sim/scenarios/*.scn. Writing the C from the same scenario_bridge the
// simulator uses leaves one source for both, and a field added to robot_config_t is added here
// once (the emitter below lists each field, and the tests compare its whole output).
#include "firmware_config.h"

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "scenario_bridge.h"

namespace dynaqpc {

namespace {

// The shortest text that strtof reads back to exactly f, as a C float literal: fixed notation
// for the magnitudes a scenario has, %g beyond them.
std::string float_c(float f)
{
    char buf[64];
    const double d = static_cast<double>(f);
    const bool fixed = f == 0.0f || (std::fabs(d) >= 1e-4 && std::fabs(d) < 1e9);
    for (int precision = fixed ? 0 : 1; precision <= (fixed ? 12 : 9); precision++) {
        std::snprintf(buf, sizeof buf, fixed ? "%.*f" : "%.*g", precision, d);
        if (std::strtof(buf, nullptr) == f) break;
    }
    std::string s = buf;
    if (s.find_first_of(".en") == std::string::npos) s += ".0";
    return s + "f";
}

std::string u32_c(std::uint32_t v)
{
    return std::to_string(v) + "u";
}

std::string hex_c(std::uint64_t v, int digits)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "0x%0*" PRIX64 "u", digits, v);
    return buf;
}

const char *agent_c(agent_kind_t k)
{
#define AGENT_C_NAME_(kind, number, name, label, id, d) \
    if (k == kind) return #kind;
    AGENT_ALGORITHMS(AGENT_C_NAME_)
#undef AGENT_C_NAME_
    return "?";
}

template <typename T, typename F>
std::string list_c(const T *values, unsigned n, F each)
{
    std::string s = "{";
    for (unsigned i = 0; i < n; i++) s += (i ? ", " : "") + each(values[i]);
    return s + "}";
}

}  // namespace

std::string robot_config_c(const robot_config_t &c, const std::string &var)
{
    auto f = [](float v) { return float_c(v); };
    auto u = [](std::uint32_t v) { return u32_c(v); };
    std::ostringstream o;
    o << "const robot_config_t " << var << " = {\n";
    o << "    .name = \"" << (c.name ? c.name : "") << "\",\n";
    o << "    .arena_w = " << f(c.arena_w) << ", .arena_h = " << f(c.arena_h) << ",\n";
    o << "    .goal_x = " << f(c.goal_x) << ", .goal_y = " << f(c.goal_y) << ", .goal_r = " << f(c.goal_r)
      << ", .goal_cells = " << unsigned(c.goal_cells) << ",\n";
    o << "    .bits_x = " << unsigned(c.bits_x) << ", .bits_y = " << unsigned(c.bits_y)
      << ", .bits_heading = " << unsigned(c.bits_heading) << ", .bits_code = " << unsigned(c.bits_code) << ",\n";
    if (c.grid[0].cells != 0u || c.grid[1].cells != 0u) {  // encode auto: the fitted cells' edges
        o << "    .grid = {";
        for (unsigned axis = 0; axis < 2; axis++) {
            const robot_grid_axis_t &g = c.grid[axis];
            o << (axis ? ",\n             " : "") << "{.cells = " << unsigned(g.cells) << ", .edge = "
              << list_c(g.edge, g.cells + 1u, f) << "}";
        }
        o << "},\n";
    }
    o << "    .rays_of_bit = " << list_c(c.rays_of_bit, ROBOT_MAX_CODE_BITS, [](std::uint32_t v) { return hex_c(v, 4); })
      << ",\n";
    o << "    .code_threshold_m = " << list_c(c.code_threshold_m, ROBOT_MAX_CODE_BITS, f) << ",\n";
    o << "    .n_ranges = " << unsigned(c.n_ranges) << ",\n";
    o << "    .tile_shift = " << list_c(c.tile_shift, 4, [](std::uint8_t v) { return std::to_string(v); }) << ",\n";
    o << "    .step_m = " << f(c.step_m) << ", .turn_rad = " << f(c.turn_rad) << ", .track_m = " << f(c.track_m)
      << ",\n";
    o << "    .action_periods = " << unsigned(c.action_periods) << ", .aligned_actions = " << unsigned(c.aligned_actions)
      << ", .step_past_m = " << f(c.step_past_m) << ",\n";
    o << "    .wait_for_fix = " << unsigned(c.wait_for_fix) << ", .period_us = " << u(c.period_us) << ",\n";
    o << "    .reward_goal = " << f(c.reward_goal) << ", .reward_bump = " << f(c.reward_bump)
      << ", .reward_step = " << f(c.reward_step) << ",\n";
    o << "    .agent = " << agent_c(c.agent) << ",\n";
    const agent_params_t &p = c.params;
    o << "    .params = {.alpha = " << f(p.alpha) << ", .plan_alpha = " << f(p.plan_alpha) << ", .gamma = " << f(p.gamma)
      << ", .epsilon = " << f(p.epsilon) << ",\n"
      << "               .theta = " << f(p.theta) << ", .model_rate = " << f(p.model_rate)
      << ", .tilings = " << unsigned(p.tilings) << ", .min_count = " << unsigned(p.min_count) << ",\n"
      << "               .model = " << (p.model == AGENT_MODEL_PAPER ? "AGENT_MODEL_PAPER" : "AGENT_MODEL_RELOCATABLE")
      << ", .model_tile_shift = "
      << list_c(p.model_tile_shift, 4, [](std::uint8_t v) { return std::to_string(v); }) << ",\n"
      << "               .explore = " << unsigned(p.explore) << ", .kappa = " << f(p.kappa) << "},\n";
    o << "    .values = " << (c.values == ROBOT_VALUES_ROOM ? "ROBOT_VALUES_ROOM" : "ROBOT_VALUES_PAPER") << ",\n";
    o << "    .planning = " << u(c.planning) << ", .step_cap = " << u(c.step_cap) << ",\n";
    o << "    .pose_source = " << (c.pose_source == ROBOT_POSE_GPS ? "ROBOT_POSE_GPS" : "ROBOT_POSE_CRICKET") << ",\n";
    o << "    .n_beacons = " << unsigned(c.n_beacons) << ",\n";
    // Every beacon up to the last one with anything in it (C zeroes the rest, and so must we).
    unsigned n_listed = 0;
    for (unsigned i = 0; i < ROBOT_MAX_BEACONS; i++) {
        const robot_beacon_t &b = c.beacons[i];
        if (i < c.n_beacons || b.id != 0u || b.x != 0.0f || b.y != 0.0f || b.z != 0.0f) n_listed = i + 1;
    }
    if (n_listed > 0) o << "    .beacons = {";
    for (unsigned i = 0; i < n_listed; i++) {
        const robot_beacon_t &b = c.beacons[i];
        o << (i ? ",\n                " : "") << "{" << hex_c(b.id, 16) << ", " << f(b.x) << ", " << f(b.y) << ", "
          << f(b.z) << "}";
    }
    if (n_listed > 0) o << "},\n";
    o << "    .listener_z = " << f(c.listener_z) << ",\n";
    if (c.speed_of_sound != 0.0f) o << "    .speed_of_sound = " << f(c.speed_of_sound) << ",\n";
    o << "    .pose_timeout_us = " << u(c.pose_timeout_us) << ", .bus_timeout_us = " << u(c.bus_timeout_us) << ",\n";
    o << "};\n";
    return o.str();
}

std::string robot_scenarios_c(const std::vector<std::string> &names)
{
    std::ostringstream o;
    o << "// SPDX-License-Identifier: MIT\n"
         "// dynaqpc robot application: the shipped scenarios, compiled in for the MCU images.\n"
         "//\n"
         "// GENERATED from host_sim/scenarios/*.scn by `dynaqpc-sim firmware-config --out <this file>`\n"
         "// (host_sim/src/firmware_config.cpp): edit the .scn files, then regenerate. The test\n"
         "// sim.firmware_config.up_to_date fails when this file differs from what they give.\n"
         "#include \"robot/robot_config.h\"\n";
    for (const std::string &name : names) {
        const ScenarioBundle b = load_scenario(name);
        std::string var = "robot_config_" + name;
        for (char &ch : var) {
            if (ch == '-') ch = '_';
        }
        o << "\n" << robot_config_c(b.robot, var);
    }
    return o.str();
}

}  // namespace dynaqpc
