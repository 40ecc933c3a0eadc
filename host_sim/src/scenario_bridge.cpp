// SPDX-License-Identifier: MIT
// dynaqpc-sim: from a scenario file to the world's description and the firmware's configuration.
#include "scenario_bridge.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "drivers/cricket.h"
#include "drivers/gyro.h"
#include "drivers/trilat.h"
#include "options.h"
#include "world/scenario.h"
#include "fw/fw_util.h"

namespace dynaqpc {

namespace {

// A length in mm as "10 m" or "0.30 m".
std::string fmt_m(float mm)
{
    char text[32];
    std::snprintf(text, sizeof text, mm >= 1000.0f && std::fmod(mm, 1000.0f) == 0.0f ? "%.0f m" : "%.2f m",
                  static_cast<double>(mm) / 1000.0);
    return text;
}

// The firmware's limits (robot_config.h) are narrower than the world's: say which one is hit.
void check_firmware_limits(const world::Scenario &sc, const std::string &path)
{
    auto fail = [&](const std::string &what) { throw UsageError(path + ": " + what); };
    if (sc.code_bits.size() > ROBOT_MAX_CODE_BITS) {
        fail("the firmware takes at most " + std::to_string(ROBOT_MAX_CODE_BITS) + " code bits");
    }
    if (sc.ranger.rays.size() > ROBOT_MAX_RANGES) {
        fail("the firmware takes at most " + std::to_string(ROBOT_MAX_RANGES) + " range sensors");
    }
    if (sc.cricket.beacons.size() > ROBOT_MAX_BEACONS) {
        fail("the firmware knows at most " + std::to_string(ROBOT_MAX_BEACONS) + " Cricket beacons");
    }
    if (!sc.gps.enabled && sc.cricket.beacons.size() < 3) {
        fail("no pose source: a gps line, or at least 3 Cricket beacons");
    }
}

// What the firmware's trilateration makes of the beacons from one point of the floor.
struct BeaconView {
    std::size_t in_range = 0;  // beacons within the listener's max_range_mm
    float spread_mm = 0.0f;    // their RMS distance off the line that fits them best
    bool fix = false;          // trilat_geometry_ok(): a fix is possible
};

BeaconView beacon_view(const world::Scenario &sc, const cricket_config &cc, double x, double y)
{
    const float listener_z_mm = static_cast<float>(sc.cricket.listener_height) * 1000.0f;
    trilat_anchor_t in_range[ROBOT_MAX_BEACONS];
    BeaconView v;
    for (const world::Beacon &bc : sc.cricket.beacons) {
        // As the firmware holds them: robot_config_t's float metres, times 1000.
        const trilat_anchor_t a = {static_cast<float>(bc.x) * 1000.0f, static_cast<float>(bc.y) * 1000.0f,
                                   static_cast<float>(bc.z) * 1000.0f, 0.0f};
        const float dx = a.x - static_cast<float>(x * 1000.0), dy = a.y - static_cast<float>(y * 1000.0);
        const float dz = a.z - listener_z_mm;
        if (std::sqrt(dx * dx + dy * dy + dz * dz) <= cc.max_range_mm) in_range[v.in_range++] = a;
    }
    v.fix = trilat_geometry_ok(in_range, v.in_range, cc.min_spread_mm, &v.spread_mm);
    return v;
}

// Where on the floor the firmware can fix the robot's position from the Cricket beacons, by its
// own rule: the ranges it takes (cricket.c: up to max_range_mm from the listener) must come from
// 3 beacons or more whose x, y spread at least min_spread_mm across their narrowest direction
// (trilat_geometry_ok(), the test trilat_solve() refuses a fix by). A layout that fails it, such
// as beacons along a corridor's middle, gives no fix there: a robot started there waits for one
// and never takes a step. Checked at the centres of a 5 cm grid over the whole arena.
void check_beacon_fix(const world::Scenario &sc, const std::string &path)
{
    if (sc.gps.enabled || sc.cricket.beacons.size() < 3 || sc.cricket.beacons.size() > ROBOT_MAX_BEACONS) {
        return;
    }
    cricket_config cc;
    cricket_default_config(&cc);
    constexpr double kGrid = 0.05;
    const long nx = std::max(1L, std::lround(std::ceil(sc.arena_w / kGrid)));
    const long ny = std::max(1L, std::lround(std::ceil(sc.arena_h / kGrid)));
    long bad = 0;
    double x0 = 0, x1 = 0, y0 = 0, y1 = 0, at_x = 0, at_y = 0;
    BeaconView first;  // at the first point without a fix
    for (long j = 0; j < ny; j++) {
        for (long i = 0; i < nx; i++) {
            const double x = std::min((i + 0.5) * kGrid, sc.arena_w), y = std::min((j + 0.5) * kGrid, sc.arena_h);
            const BeaconView v = beacon_view(sc, cc, x, y);
            if (v.fix) continue;
            if (bad++ == 0) {
                x0 = x1 = at_x = x;
                y0 = y1 = at_y = y;
                first = v;
            }
            x0 = std::min(x0, x);
            x1 = std::max(x1, x);
            y0 = std::min(y0, y);
            y1 = std::max(y1, y);
        }
    }
    if (bad == 0) return;
    char text[240];
    std::string msg = path + ": the Cricket beacons give the firmware no position fix ";
    if (bad == nx * ny) {
        msg += "anywhere on the floor: ";
    } else {
        const double share = std::max(1.0, std::floor(100.0 * static_cast<double>(bad) / static_cast<double>(nx * ny)));
        std::snprintf(text, sizeof text, "on %.0f %% of the floor (within x %.2f-%.2f m, y %.2f-%.2f m): at (%.2f, %.2f) ",
                      share, x0 - kGrid / 2, x1 + kGrid / 2, y0 - kGrid / 2, y1 + kGrid / 2, at_x, at_y);
        msg += text;
    }
    const std::string range = fmt_m(cc.max_range_mm);
    if (first.in_range < 3) {
        std::snprintf(text, sizeof text, "only %zu beacon(s) lie within the listener's %s", first.in_range,
                      range.c_str());
    } else {
        std::snprintf(text, sizeof text, "the %zu beacons within the listener's %s lie along a line (%.2f m RMS off it)",
                      first.in_range, range.c_str(), static_cast<double>(first.spread_mm) / 1000.0);
    }
    msg += text;
    msg += ", and its trilateration needs 3 or more within " + range + " spread at least " + fmt_m(cc.min_spread_mm) +
           " RMS off any line: ";
    msg += first.in_range < 3 ? "place 3 beacons or more within " + range + " of every point, not in a line"
                              : std::string("place the beacons not in a line, e.g. one over each corner region");
    throw UsageError(msg + " (docs/scenarios.md, \"beacon\")");
}

}  // namespace

std::string beacon_rate_warning(const world::Scenario &sc)
{
    if (sc.gps.enabled || sc.cricket.beacons.empty()) return "";
    cricket_config cc;
    cricket_default_config(&cc);
    const double age_s = static_cast<double>(cc.max_age_us) * 1e-6;
    const double mean_s = 0.5 * (sc.cricket.min_interval + sc.cricket.max_interval);  // s
    // Each beacon's chance of a range no older than age_s, over the beacons: the fresh ranges a
    // fix can take at a time, on average (every beacon counted, in range or not).
    const double fresh = static_cast<double>(sc.cricket.beacons.size()) * std::min(1.0, age_s / mean_s);
    if (fresh >= 3.0) return "";
    char text[512];
    std::snprintf(text, sizeof text,
                  "the beacons transmit every %.3g s on average, and the firmware takes a fix from 3 ranges at "
                  "most %.3g s old: about %.2g of the %zu beacons' ranges are that fresh at a time, so fixes come "
                  "seldom or never and the robot waits for one before each step; give min_interval_ms and "
                  "max_interval_ms that average under %.3g s (the Cricket's default: 668-1332 ms)",
                  mean_s, age_s, fresh, sc.cricket.beacons.size(),
                  age_s * static_cast<double>(sc.cricket.beacons.size()) / 3.0);
    return text;
}

namespace {

// "1:5e:3c:3c:a:0:0:b1" (the listener's ID field) as the Cricket driver reads it.
std::uint64_t beacon_id(const std::string &text, const std::string &path)
{
    std::uint64_t id = 0;
    if (cricket_parse_id(text.data(), text.size(), &id) != 0) {
        throw UsageError(path + ": beacon id '" + text + "' is not 8 hex bytes separated by ':'");
    }
    return id;
}

// The arena, the goal and the state encoding (cells fitted to the room: world/grid_fit.h).
void set_geometry(robot_config_t &r, const world::Scenario &sc)
{
    r.arena_w = static_cast<float>(sc.arena_w);
    r.arena_h = static_cast<float>(sc.arena_h);
    r.goal_x = static_cast<float>(sc.goal.cx);
    r.goal_y = static_cast<float>(sc.goal.cy);
    r.goal_r = static_cast<float>(sc.goal.radius);
    r.goal_cells = sc.goal.cells ? 1u : 0u;
    r.bits_x = static_cast<uint8_t>(sc.encoding.x_bits);
    r.bits_y = static_cast<uint8_t>(sc.encoding.y_bits);
    r.bits_heading = static_cast<uint8_t>(sc.encoding.heading_bits);
    r.bits_code = static_cast<uint8_t>(sc.code_bits.size());
    if (sc.encoding.fitted) {  // the cells fitted to the room (world/grid_fit.h)
        const std::vector<double> *edges[2] = {&sc.encoding.x_edges, &sc.encoding.y_edges};
        for (int axis = 0; axis < 2; axis++) {
            robot_grid_axis_t &g = r.grid[axis];
            g.cells = static_cast<uint8_t>(edges[axis]->size() - 1);
            for (std::size_t k = 0; k < edges[axis]->size(); k++) g.edge[k] = static_cast<float>((*edges[axis])[k]);
        }
    }
    for (std::size_t k = 0; k < sc.code_bits.size(); k++) {
        for (int ray : sc.code_bits[k].rays) {
            r.rays_of_bit[k] |= 1u << ray;
        }
        r.code_threshold_m[k] = static_cast<float>(sc.code_bits[k].threshold);
    }
}

// The ranger, the actions and the control timing.
void set_actions(robot_config_t &r, const world::Scenario &sc)
{
    r.n_ranges = static_cast<uint8_t>(sc.ranger.rays.size());
    r.step_m = static_cast<float>(sc.actions.step);
    r.turn_rad = static_cast<float>(sc.actions.turn);
    r.aligned_actions = static_cast<uint8_t>(sc.actions.aligned == 0 ? ROBOT_ACTIONS_FIXED
                                             : sc.actions.centred   ? ROBOT_ACTIONS_CENTRED
                                                                    : ROBOT_ACTIONS_ALIGNED);
    r.step_past_m = static_cast<float>(sc.actions.past);
    r.track_m = static_cast<float>(sc.robot.track);
    r.period_us = static_cast<uint32_t>(std::lround(sc.timing.control_period * 1e6));
    // An action takes as many whole periods as the wheels need at their top speed, and a turn as
    // many as keep it within 80 % of the gyro's measuring range (a saturated gyro loses heading).
    const double wheel_travel = std::max(sc.actions.step, sc.actions.turn * sc.robot.track / 2.0);
    const double max_turn_rate = 0.8 * GYRO_RANGE_DEG_S * FW_PI / 180.0;
    const double periods = std::ceil(std::max(wheel_travel / sc.robot.max_speed, sc.actions.turn / max_turn_rate) /
                                         sc.timing.control_period -
                                     1e-9);
    r.action_periods = static_cast<uint8_t>(std::clamp(periods, 1.0, 255.0));
}

// Rewards and the learning lines.
void set_learning(robot_config_t &r, const world::Scenario &sc)
{
    r.reward_goal = static_cast<float>(sc.rewards.goal);
    r.reward_bump = static_cast<float>(sc.rewards.bump);
    r.reward_step = static_cast<float>(sc.rewards.step);
    r.params.alpha = r.params.plan_alpha = static_cast<float>(sc.learning.alpha);
    if (sc.learning.gamma == world::Learning::kGammaFromRoom) {
        r.values = ROBOT_VALUES_ROOM;  // gamma and theta from the room: robot_config_agent_params()
    } else {
        r.values = ROBOT_VALUES_PAPER;
        r.params.gamma = static_cast<float>(sc.learning.gamma);
    }
    r.params.epsilon = static_cast<float>(sc.learning.epsilon);
    r.params.explore = explore_mode_of(sc.learning.explore, "learning explore");
    r.params.kappa = static_cast<float>(sc.learning.kappa);
    r.params.model = agent_model_of(sc.learning.model);
    for (std::size_t k = 0; k < sc.learning.model_tiles.size() && k < FW_CFG_MAX_COMPONENTS; k++) {
        r.params.model_tile_shift[k] = static_cast<std::uint8_t>(sc.learning.model_tiles[k]);
    }
    r.planning = static_cast<uint32_t>(sc.learning.planning);
    r.step_cap = static_cast<uint32_t>(sc.learning.step_cap);
}

// GPS or the Cricket beacons.
void set_pose_source(robot_config_t &r, const world::Scenario &sc, const std::string &path)
{
    if (sc.gps.enabled) {
        r.pose_source = ROBOT_POSE_GPS;
        r.wait_for_fix = 0;
        r.pose_timeout_us = 1000000u;
    } else {
        r.pose_source = ROBOT_POSE_CRICKET;
        r.wait_for_fix = 1;  // the paper's lab robot waited, still, for a stable fix
        r.pose_timeout_us = 5000000u;
    }
    r.n_beacons = static_cast<uint8_t>(sc.cricket.beacons.size());
    for (std::size_t i = 0; i < sc.cricket.beacons.size(); i++) {
        const world::Beacon &bc = sc.cricket.beacons[i];
        r.beacons[i].id = beacon_id(bc.id, path);
        r.beacons[i].x = static_cast<float>(bc.x);
        r.beacons[i].y = static_cast<float>(bc.y);
        r.beacons[i].z = static_cast<float>(bc.z);
    }
    r.listener_z = static_cast<float>(sc.cricket.listener_height);
    // Why tell the firmware: under ceiling beacons a range's error is the horizontal one several
    // times over, and a room 10 degrees C from the 343 m/s the driver assumes put the fixes
    // 0.12 m off (docs/scenarios.md, `cricket`).
    r.speed_of_sound = sc.gps.enabled ? 0.0f : static_cast<float>(sc.cricket.speed_of_sound);
}

}  // namespace

ScenarioBundle load_scenario(const std::string &arg)
{
    auto sc = std::make_shared<world::Scenario>();
    std::string error;
    if (!world::load_scenario(arg, sc.get(), &error)) {
        throw UsageError(error);
    }
    ScenarioBundle b;
    b.path = sc->path;
    b.name = sc->name;
    check_firmware_limits(*sc, b.path.empty() ? arg : b.path);
    check_beacon_fix(*sc, b.path.empty() ? arg : b.path);

    robot_config_t &r = b.robot;
    robot_config_defaults(&r);  // what the scenario does not say
    set_geometry(r, *sc);
    set_actions(r, *sc);
    set_learning(r, *sc);
    b.sets = static_cast<uint32_t>(sc->learning.sets);
    b.episodes = static_cast<uint32_t>(sc->learning.episodes);
    set_pose_source(r, *sc, b.path);
    b.world = sc;
    r.name = b.world->name.c_str();
    r.params = robot_config_agent_params(&r);  // what the firmware will use, for all to read
    if (robot_config_check(&r) != 0) {
        throw UsageError((b.path.empty() ? arg : b.path) +
                         ": the firmware cannot run this scenario (state encoding, sensors or actions out of range)");
    }
    return b;
}

ScenarioBundle load_changed_scenario(const ScenarioBundle &base, const std::string &arg)
{
    ScenarioBundle b;
    try {
        b = load_scenario(arg);
    } catch (const UsageError &e) {
        throw UsageError(std::string("--changed: ") + e.what());
    }
    const std::string problem = world::layout_change_problem(*base.world, *b.world);
    if (!problem.empty()) {
        throw UsageError("--changed: " + (b.path.empty() ? arg : b.path) + " is not a change of " +
                         (base.path.empty() ? base.name : base.path) + ": " + problem);
    }
    if (base.world->encoding.fitted) {
        // The firmware is not told of the change and keeps the grid it was fitted to; so do the
        // world's goal cells.
        auto same_grid = std::make_shared<world::Scenario>(*b.world);
        same_grid->encoding = base.world->encoding;
        b.world = same_grid;
        b.robot.grid[0] = base.robot.grid[0];
        b.robot.grid[1] = base.robot.grid[1];
    }
    return b;
}

void declare_change_options(Options &o, const std::string &change_at_help, std::uint32_t *change_at,
                            std::uint32_t max, std::string *changed)
{
    o.add_uint("--change-at", "K", change_at_help, change_at, 1, max);
    o.add_string("--changed", "FILE",
                 "with --change-at: the changed room, a scenario file whose obstacles alone differ from "
                 "--scenario's (docs/scenarios.md, \"Rooms that change\")",
                 changed);
}

ScenarioBundle load_change_options(const Options &o, const ScenarioBundle &base, const std::string &changed,
                                   std::uint32_t change_at, std::uint32_t last, const char *unit)
{
    if (o.seen("--change-at") != o.seen("--changed")) {
        throw UsageError(o.seen("--change-at") ? "--change-at: needs --changed FILE (the changed room)"
                                               : std::string("--changed: needs --change-at K (the first ") + unit +
                                                     " in it)");
    }
    ScenarioBundle b;
    if (o.seen("--changed")) {
        b = load_changed_scenario(base, changed);
        if (change_at > last) {
            throw UsageError("--change-at: " + std::string(unit) + " " + std::to_string(change_at) +
                             " is past the last (" + std::to_string(last) + ")");
        }
    }
    return b;
}

agent_kind_t agent_kind_of(const std::string &name)
{
    agent_kind_t kind;
    if (agent_kind_from_name(name.c_str(), &kind) != FW_OK) {
        throw UsageError("unknown agent '" + name + "' (" + agent_kind_list() + ")");
    }
    return kind;
}

std::vector<std::string> explore_mode_names()
{
    return {"egreedy", "plan-bonus", "act-bonus"};  // agent_explore_t order
}

uint8_t explore_mode_of(const std::string &name, const std::string &what)
{
    const std::vector<std::string> names = explore_mode_names();
    for (std::size_t i = 0; i < names.size(); i++) {
        if (name == names[i]) return static_cast<uint8_t>(i);
    }
    throw UsageError(what + ": '" + name + "' is not egreedy, plan-bonus or act-bonus");
}

uint8_t ablate_mask(const std::string &list)
{
    static const struct {
        const char *name;
        uint8_t bit;
    } parts[] = {{"generalise", AGENT_ABLATE_GENERALISE},
                 {"majority", AGENT_ABLATE_MAJORITY},
                 {"new-states", AGENT_ABLATE_NEW_STATES},
                 {"expected", AGENT_ABLATE_EXPECTED},
                 {"stay", AGENT_ABLATE_STAY},
                 {"alias", AGENT_ABLATE_ALIAS}};
    uint8_t mask = 0;
    std::stringstream in(list);
    std::string word;
    while (std::getline(in, word, ',')) {
        if (word == "none" || (word.empty() && list.empty())) continue;
        bool known = false;
        for (const auto &p : parts) {
            if (word == p.name) {
                mask = static_cast<uint8_t>(mask | p.bit);
                known = true;
            }
        }
        if (!known) {
            throw UsageError("--ablate: unknown part '" + word + "' (generalise, majority, new-states, expected, stay, alias)");
        }
    }
    return mask;
}

std::vector<std::string> agent_kind_names()
{
    std::vector<std::string> names;
    for (uint32_t k = 0; k < AGENT_KINDS; k++) {
        names.push_back(agent_kind_name(static_cast<agent_kind_t>(k)));
    }
    return names;
}

std::string agent_kind_list()
{
    std::string list;
    for (const auto &n : agent_kind_names()) {
        list += (list.empty() ? "" : ", ") + n;
    }
    return list;
}

std::uint8_t agent_model_of(const std::string &name)
{
    std::uint8_t model = 0;
    if (agent_model_from_name(name.c_str(), &model) != FW_OK) {
        throw UsageError("unknown model '" + name + "' (relocatable, paper)");
    }
    return model;
}

void apply_overrides(const Options &o, const ConfigOverrides &v, robot_config_t *cfg)
{
    if (v.model != nullptr && o.seen("--model")) cfg->params.model = agent_model_of(*v.model);
    if (v.model_tiles != nullptr && o.seen("--model-tiles")) {
        std::vector<int> tiles;
        std::string problem;
        if (!world::parse_model_tiles(*v.model_tiles, &tiles, &problem)) {
            throw UsageError("--model-tiles: '" + *v.model_tiles + "': " + problem);
        }
        for (std::size_t k = 0; k < tiles.size(); k++) {
            cfg->params.model_tile_shift[k] = static_cast<std::uint8_t>(tiles[k]);
        }
    }
    if (v.agent != nullptr) cfg->agent = agent_kind_of(*v.agent);
    if (v.planning != nullptr && o.seen("--planning")) cfg->planning = *v.planning;
    if (v.step_cap != nullptr && o.seen("--step-cap")) cfg->step_cap = *v.step_cap;
    if (v.epsilon != nullptr && o.seen("--epsilon")) cfg->params.epsilon = static_cast<float>(*v.epsilon);
    if (v.explore != nullptr && o.seen("--explore")) cfg->params.explore = explore_mode_of(*v.explore, "--explore");
    if (v.kappa != nullptr && o.seen("--kappa")) cfg->params.kappa = static_cast<float>(*v.kappa);
    if (v.alpha != nullptr && o.seen("--alpha")) {
        cfg->params.alpha = cfg->params.plan_alpha = static_cast<float>(*v.alpha);
    }
    if (v.gamma != nullptr && o.seen("--gamma")) {
        if (*v.gamma == "auto") {
            cfg->values = ROBOT_VALUES_ROOM;
        } else {
            char *end = nullptr;
            const double g = std::strtod(v.gamma->c_str(), &end);
            if (v.gamma->empty() || *end != '\0' || !(g >= 0.0 && g <= 1.0)) {
                throw UsageError("--gamma: '" + *v.gamma + "' is neither a discount in [0, 1] nor auto");
            }
            cfg->values = ROBOT_VALUES_PAPER;
            cfg->params.gamma = static_cast<float>(g);
        }
    }
}

std::string arena_json(const world::Scenario &sc)
{
    std::ostringstream o;
    o.precision(6);
    o << "{\"name\":\"" << sc.name << "\",\"width\":" << sc.arena_w << ",\"height\":" << sc.arena_h
      << ",\"obstacles\":[";
    for (std::size_t i = 0; i < sc.obstacles.size(); i++) {
        const world::Obstacle &ob = sc.obstacles[i];
        o << (i ? "," : "");
        if (ob.shape == world::Obstacle::Shape::Box) {
            o << "{\"kind\":\"box\",\"cx\":" << ob.cx << ",\"cy\":" << ob.cy << ",\"w\":" << ob.w
              << ",\"h\":" << ob.h << ",\"angle_deg\":" << ob.angle * 180.0 / FW_PI << "}";
        } else {
            o << "{\"kind\":\"circle\",\"cx\":" << ob.cx << ",\"cy\":" << ob.cy << ",\"r\":" << ob.radius
              << "}";
        }
    }
    o << "],\"goal\":{\"cx\":" << sc.goal.cx << ",\"cy\":" << sc.goal.cy << ",\"r\":" << sc.goal.radius;
    if (sc.goal.cells) {  // the goal is these cells; the circle only chose them
        o << ",\"cells\":[";
        const std::vector<world::CellBox> cells = world::goal_cells(sc);
        for (std::size_t i = 0; i < cells.size(); i++) {
            const world::CellBox &c = cells[i];
            o << (i ? "," : "") << "[" << c.x0 << "," << c.y0 << "," << c.x1 << "," << c.y1 << "]";
        }
        o << "]";
    }
    o << "},\"beacons\":[";
    for (std::size_t i = 0; i < sc.cricket.beacons.size(); i++) {
        const world::Beacon &bc = sc.cricket.beacons[i];
        o << (i ? "," : "") << "{\"id\":\"" << bc.id << "\",\"x\":" << bc.x << ",\"y\":" << bc.y
          << ",\"z\":" << bc.z << "}";
    }
    o << "]}\n";
    return o.str();
}

}  // namespace dynaqpc
