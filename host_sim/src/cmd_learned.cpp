// SPDX-License-Identifier: MIT
// dynaqpc-sim learned: what a flash image holds, decoded by the firmware itself, as JSON.
//
// The firmware boots on the image exactly as `run` does (learned_store_load: CRCs, layout, the
// agent's own checks), and what it restored is then read through the agent's own functions: its
// walk (agent_walk: the tables' fill and, per state, its Q row, whether it was visited or is
// modelled, the model's training counts, each module describing its own), Q values
// (agent_q, agent_value) and the greedy action (agent_greedy). No offset of the
// store's layout is written down twice: dynaqpc-learned (tools/dynaqpc_tools/learned.py) only
// draws this JSON. The format is documented in docs/tools.md ("dynaqpc-learned").
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "commands.h"
#include "hal/hal_flash.h"
#include "lockstep.h"
#include "options.h"
#include "robot/learned_store.h"
#include "robot/robot_app.h"
#include "robot/robot_geometry.h"
#include "scenario_bridge.h"
#include "world/scenario.h"

namespace dynaqpc {

namespace {

const char *kind_name(agent_kind_t k)
{
    const char *name = agent_kind_name(k);
    return name != nullptr ? name : "?";
}

const char *slot_state_name(learned_slot_state_t s)
{
    switch (s) {
    case LEARNED_SLOT_EMPTY: return "empty";
    case LEARNED_SLOT_DAMAGED: return "damaged";
    case LEARNED_SLOT_FOREIGN: return "foreign";
    case LEARNED_SLOT_REFUSED: return "refused";
    default: return "good";
    }
}

// A float as JSON (finite by the store's own checks; guard anyway).
std::string num(double v)
{
    if (!std::isfinite(v)) return "null";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

// What agent_walk() hands over, gathered per state (facts about one state add up).
struct Knowledge {
    std::uint32_t n_states, na;
    std::vector<agent_table_fill_t> fill;
    std::vector<std::uint8_t> row, visited, modelled;
    std::vector<std::uint32_t> n;
    Knowledge(std::uint32_t states, std::uint32_t actions)
        : n_states(states), na(actions), row(states, 0), visited(states, 0), modelled(states, 0),
          n(static_cast<std::size_t>(states) * actions, 0)
    {
    }
    static int take(void *data, const agent_fact_t *fact)
    {
        Knowledge &k = *static_cast<Knowledge *>(data);
        if (fact->kind == AGENT_FACT_TABLE) {
            k.fill.push_back(fact->u.table);
        } else if (fact->kind == AGENT_FACT_STATE && fact->u.state.state < k.n_states) {
            const agent_state_facts_t &f = fact->u.state;
            k.row[f.state] |= f.row ? 1 : 0;
            k.visited[f.state] |= f.visited ? 1 : 0;
            k.modelled[f.state] |= f.modelled ? 1 : 0;
            for (std::uint32_t a = 0; a < k.na; a++) {
                std::uint32_t &v = k.n[static_cast<std::size_t>(f.state) * k.na + a];
                v = std::max(v, f.n[a]);
            }
        }
        return 0;
    }
};

struct SlotInfo {
    learned_slot_state_t state = LEARNED_SLOT_EMPTY;
    std::uint32_t sequence = 0;
    std::uint32_t episodes = 0;
};

// What each slot of the flash holds for this agent's layout (the store's own classification).
std::vector<SlotInfo> slots_of(const agent_t *ag)
{
    std::vector<SlotInfo> out;
    learned_store_t st;
    if (learned_store_init(&st) != FW_OK) return out;
    for (std::uint32_t slot = 0; slot < 2u; slot++) {
        SlotInfo si;
        si.state = learned_store_slot_state(&st, ag, slot, &si.sequence);
        if (si.state == LEARNED_SLOT_GOOD || si.state == LEARNED_SLOT_FOREIGN || si.state == LEARNED_SLOT_REFUSED) {
            const auto *h = static_cast<const learned_header_t *>(hal_flash_map(slot * st.slot_size, sizeof(learned_header_t)));
            if (h != nullptr) si.episodes = h->episodes;
        }
        out.push_back(si);
    }
    return out;
}

// Where an aligned step stops (robot_actions_kind_t, `actions ... stop`): "past" the edge it
// crosses, the "centre" of the cell it enters, or "none" with fixed steps.
const char *stop_name(const robot_config_t &cfg)
{
    switch (cfg.aligned_actions) {
    case ROBOT_ACTIONS_ALIGNED: return "past";
    case ROBOT_ACTIONS_CENTRED: return "centre";
    default: return "none";
    }
}

// What the firmware learns the room's values with (robot_config_agent_params(), gamma auto
// resolved; a train --gamma override is not in an image): the discount, the sweep's threshold,
// what a state never met is worth (docs/agent.md, 11. and 13.), the rewards, and the value of
// wandering for ever (every step's reward, never the goal), where a region the model closes off
// settles (dynaqpc-learned's closed regions).
std::string values_json(const robot_config_t &cfg)
{
    const agent_params_t &p = cfg.params;
    std::ostringstream o;
    o << "{\"gamma\":" << num(p.gamma) << ",\"theta\":" << num(p.theta) << ",\"prior\":" << num(p.q_prior)
      << ",\"reward_goal\":" << num(cfg.reward_goal) << ",\"reward_bump\":" << num(cfg.reward_bump)
      << ",\"reward_step\":" << num(cfg.reward_step) << ",\"wander\":"
      << (p.gamma < 1.0f ? num(cfg.reward_step / (1.0f - p.gamma)) : std::string("null")) << "}";
    return o.str();
}

// The side of every cell along `axis` when they are all the same (the equal grid's), else null (a
// grid fitted to the room: its edges give each cell).
std::string common_side(const robot_config_t &cfg, std::uint32_t axis)
{
    float lo, first;
    robot_grid_span(&cfg, axis, 0, &lo, &first);
    for (std::uint32_t k = 1; k < robot_grid_cells(&cfg, axis); k++) {
        float side;
        robot_grid_span(&cfg, axis, k, &lo, &side);
        if (std::fabs(side - first) > 1e-6f * first) return "null";
    }
    return num(first);
}

// The state grid: cells, their edges (a grid fitted to the room has cells of different sizes) and
// the goal's cells.
void write_grid(std::ostringstream &o, const robot_config_t &cfg)
{
    const std::uint32_t nx = robot_grid_cells(&cfg, ROBOT_AXIS_X), ny = robot_grid_cells(&cfg, ROBOT_AXIS_Y);
    o << "\"grid\":{\"cells_x\":" << nx << ",\"cells_y\":" << ny
      << ",\"headings\":" << (1u << cfg.bits_heading) << ",\"codes\":" << (1u << cfg.bits_code)
      << ",\"cell_w\":" << common_side(cfg, ROBOT_AXIS_X) << ",\"cell_h\":" << common_side(cfg, ROBOT_AXIS_Y);
    // The edges of every cell, from 0 to the arena's side.
    for (std::uint32_t axis = 0; axis < 2u; axis++) {
        o << (axis == 0 ? ",\"x_edges\":[" : "],\"y_edges\":[");
        const std::uint32_t n = axis == 0 ? nx : ny;
        for (std::uint32_t k = 0; k < n; k++) {
            float lo, side;
            robot_grid_span(&cfg, axis, k, &lo, &side);
            o << num(lo) << ",";
            if (k + 1 == n) o << num(lo + side);
        }
    }
    o << "],\"goal_cells\":[";
    bool first = true;
    for (std::uint32_t y = 0; y < ny; y++) {
        for (std::uint32_t x = 0; x < nx; x++) {
            robot_pose_t p{};
            float lo, side;
            robot_grid_span(&cfg, ROBOT_AXIS_X, x, &lo, &side);
            p.x = lo + 0.5f * side;
            robot_grid_span(&cfg, ROBOT_AXIS_Y, y, &lo, &side);
            p.y = lo + 0.5f * side;
            if (robot_in_goal(&cfg, &p)) {
                o << (first ? "" : ",") << "[" << x << "," << y << "]";
                first = false;
            }
        }
    }
    o << "]";
}

void write_states(std::ostringstream &o, const agent_space_t &sp, agent_t *ag, const Knowledge &k)
{
    const std::uint32_t n_states = 1u << space_state_bits(&sp);
    const std::uint32_t na = sp.n_actions;
    // Per state: whether it has a Q row, was visited (perceived on a real step), is modelled (the
    // model predicts an action there, tried or generalised); its Q values and real experience.
    o << "\"states_columns\":[\"s\",\"x\",\"y\",\"heading\",\"code\",\"row\",\"visited\",\"modelled\",\"greedy\",\"v\",\"q\",\"n\"],\n"
      << "\"states\":[";
    bool first = true;
    for (std::uint32_t s = 0; s < n_states; s++) {
        const bool row = k.row[s] != 0, vis = k.visited[s] != 0, modelled = k.modelled[s] != 0;
        if (!row && !vis && !modelled) continue;
        float q[FW_CFG_MAX_ACTIONS];
        for (std::uint32_t a = 0; a < na; a++) q[a] = agent_q(ag, s, static_cast<std::uint8_t>(a));
        const std::uint32_t *n = &k.n[static_cast<std::size_t>(s) * na];
        std::uint32_t comp[FW_CFG_MAX_COMPONENTS];
        space_unpack(&sp, s, comp);
        o << (first ? "\n" : ",\n") << "[" << s << "," << comp[0] << "," << comp[1] << "," << comp[2] << "," << comp[3] << ","
          << (row ? 1 : 0) << "," << (vis ? 1 : 0) << "," << (modelled ? 1 : 0) << "," << unsigned(agent_greedy(ag, s)) << ","
          << num(agent_value(ag, s)) << ",[";
        for (std::uint32_t a = 0; a < na; a++) o << (a ? "," : "") << num(q[a]);
        o << "],[";
        for (std::uint32_t a = 0; a < na; a++) o << (a ? "," : "") << n[a];
        o << "]]";
        first = false;
    }
}

std::string json_of(const ScenarioBundle &sb, const robot_config_t &cfg, agent_t *ag, const std::vector<SlotInfo> &slots)
{
    agent_space_t sp;
    robot_config_space(&cfg, &sp);
    const std::uint32_t bits = space_state_bits(&sp);
    const std::uint32_t n_states = 1u << bits;
    const std::uint32_t na = sp.n_actions;
    robot_app_stats_t rs;
    robot_app_get_stats(&rs);

    std::ostringstream o;
    o << "{\"format\":\"dynaqpc-learned 1\",\"scenario\":\"" << sb.name << "\",\"agent\":\"" << kind_name(cfg.agent)
      << "\",\n\"record\":{\"episodes\":" << rs.restored_episodes << ",\"fell_back\":" << (rs.restore_fell_back ? "true" : "false")
      << ",\"slots\":[";
    for (std::size_t i = 0; i < slots.size(); i++) {
        o << (i ? "," : "") << "{\"state\":\"" << slot_state_name(slots[i].state) << "\",\"sequence\":" << slots[i].sequence
          << ",\"episodes\":" << slots[i].episodes << "}";
    }
    o << "]},\n\"space\":{\"components\":[";
    const char *names[4] = {"x", "y", "heading", "code"};
    std::uint32_t shift = 0;
    for (std::uint32_t k = 0; k < sp.n_components; k++) {
        o << (k ? "," : "") << "{\"name\":\"" << names[k] << "\",\"bits\":" << unsigned(sp.bits[k]) << ",\"shift\":" << shift << "}";
        shift += sp.bits[k];
    }
    o << "],\"actions\":[\"forward\",\"backward\",\"left\",\"right\"],\"turn_deg\":" << num(cfg.turn_rad * 180.0 / FW_PI)
      << ",\"aligned\":" << (cfg.aligned_actions ? "true" : "false") << ",\"stop\":\"" << stop_name(cfg) << "\"},\n";
    o << "\"values\":" << values_json(cfg) << ",\n";
    write_grid(o, cfg);
    std::string arena = arena_json(*sb.world);
    while (!arena.empty() && arena.back() == '\n') arena.pop_back();
    o << "},\n\"arena\":" << arena << ",\n";

    // What the agent knows, as its modules describe it (agent_walk).
    Knowledge k(n_states, na);
    (void)agent_walk(ag, AGENT_FACT_TABLE | AGENT_FACT_STATE, Knowledge::take, &k);
    o << "\"fill\":{";
    for (std::size_t i = 0; i < k.fill.size(); i++) {
        const agent_table_fill_t &t = k.fill[i];
        o << (i ? "," : "") << "\"" << t.name << "\":{\"" << t.unit << "\":" << t.used << ",\"capacity\":" << t.capacity;
        if (t.dense >= 0) o << ",\"dense\":" << (t.dense ? "true" : "false");
        o << "}";
    }
    o << "},\n";

    write_states(o, sp, ag, k);
    o << "]}\n";
    return o.str();
}

// `learned --grid`: the scenario's state grid alone (format "dynaqpc-grid 1"), for the tools that
// draw cells: the bits, and the cells' edges of an equal grid or of one fitted to the room.
std::string grid_json(const ScenarioBundle &sb)
{
    std::ostringstream g;
    g << "{\"format\":\"dynaqpc-grid 1\",\"scenario\":\"" << sb.name << "\",\"arena\":[" << num(sb.robot.arena_w) << ","
      << num(sb.robot.arena_h) << "],\"bits\":{\"x\":" << unsigned(sb.robot.bits_x) << ",\"y\":" << unsigned(sb.robot.bits_y)
      << ",\"heading\":" << unsigned(sb.robot.bits_heading) << ",\"sensor\":" << unsigned(sb.robot.bits_code)
      << "},\"stop\":\"" << stop_name(sb.robot) << "\",\n";
    write_grid(g, sb.robot);
    g << "},\n\"values\":" << values_json(sb.robot) << "}\n";
    return g.str();
}

// Why no agent restored from the image: the one line `learned` ends with.
UsageError refusal(const std::string &load, const std::string &what, const std::string &scenario, bool all_empty,
                   bool any_refused, bool any_foreign)
{
    if (all_empty) return UsageError("--load: '" + load + "' is erased: it holds no learned record");
    if (any_refused) {
        return UsageError("--load: '" + load + "' is corrupted: its record's CRCs hold but its tables fail the firmware's checks");
    }
    if (!any_foreign) {
        return UsageError("--load: '" + load + "' is corrupted: no whole record (a CRC fails or the header is not ours)");
    }
    return UsageError("--load: '" + load + "' holds no record of " + what + " on " + scenario +
                      " (another scenario, agent or firmware layout; try --scenario/--agent)");
}

}  // namespace

int cmd_learned(const std::string &program, const std::vector<std::string> &args)
{
    std::string scenario, load, agent;
    bool grid_only = false;
    Options o("learned", "what a flash image holds, decoded by the firmware's own restore code, as JSON on stdout");
    o.add_string("--scenario", "S", "paper-sim, paper-lab, or a scenario file (the one it learned on)", &scenario);
    o.add_string("--load", "FILE", "a flash image (`train --save FILE`, a board's backup)", &load);
    o.add_choice("--agent", "NAME", "the algorithm that learned it: " + agent_kind_list() + " (default: whichever the image holds)",
                 &agent, agent_kind_names());
    o.add_flag("--grid", "print only the scenario's state grid (cells, their edges, headings, codes, goal cells; "
                         "a grid fitted to the room by `encode auto` included): no --load", &grid_only);
    if (o.parse_or_usage(args, program)) {
        return kExitOk;
    }
    o.require("--scenario");
    if (grid_only) {
        if (o.seen("--load")) throw UsageError("--grid: the scenario's grid alone, without --load");
        std::fputs(grid_json(load_scenario(scenario)).c_str(), stdout);
        return kExitOk;
    }
    o.require("--load", "a flash image: train --save FILE");
    struct stat st;
    if (stat(load.c_str(), &st) != 0) {
        throw UsageError("--load: cannot open '" + load + "': " + std::strerror(errno));
    }
    const ScenarioBundle sb = load_scenario(scenario);
    std::vector<std::string> kinds;
    if (o.seen("--agent")) {
        kinds.push_back(agent);
    } else {
        kinds = agent_kind_names();
    }
    LockstepOptions lo;
    lo.flash_file = load;
    lo.evaluate = true;
    lo.flash_read_only = true;
    // What the slots hold for each agent tried, for the one line that says why nothing restored.
    bool any_foreign = false, any_refused = false, all_empty = true;
    for (const std::string &k : kinds) {
        robot_config_t cfg = sb.robot;
        cfg.agent = agent_kind_of(k);
        std::unique_ptr<Lockstep> sim;
        try {
            sim = std::make_unique<Lockstep>(*sb.world, cfg, lo);
        } catch (const std::runtime_error &e) {
            throw UsageError(std::string("--load: ") + e.what());
        }
        agent_t *ag = sim->agent();
        const std::vector<SlotInfo> slots = slots_of(ag);
        if (sim->restored()) {
            std::fputs(json_of(sb, cfg, ag, slots).c_str(), stdout);
            robot_app_stats_t rs;
            robot_app_get_stats(&rs);
            if (rs.restore_fell_back) {
                std::fprintf(stderr, "%s learned: warning: the newest record in '%s' is damaged or refused; this is the "
                             "older one (%u episodes), which the firmware would restore\n",
                             program.c_str(), load.c_str(), rs.restored_episodes);
            }
            return kExitOk;
        }
        for (const SlotInfo &si : slots) {
            if (si.state != LEARNED_SLOT_EMPTY) all_empty = false;
            if (si.state == LEARNED_SLOT_REFUSED) any_refused = true;
            if (si.state == LEARNED_SLOT_FOREIGN) any_foreign = true;
        }
    }
    throw refusal(load, o.seen("--agent") ? agent : agent_kind_list(), sb.name, all_empty, any_refused, any_foreign);
}

}  // namespace dynaqpc
