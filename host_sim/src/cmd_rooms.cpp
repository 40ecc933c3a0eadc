// SPDX-License-Identifier: MIT
// dynaqpc-sim rooms: seeded random rooms for a robot, one scenario file each (world/rooms.h).
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "commands.h"
#include "learning_record.h"
#include "options.h"
#include "scenario_bridge.h"
#include "world/grid_fit.h"
#include "world/rooms.h"
#include "world/user_rooms.h"
#include "world/scenario.h"

namespace dynaqpc {

namespace {

std::string read_file(const std::string &path)
{
    std::FILE *f = std::fopen(path.c_str(), "rb");
    if (f == nullptr) throw std::runtime_error(path + ": cannot open: " + std::strerror(errno));
    std::string text;
    char buf[65536];
    std::size_t n = 0;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0 && text.size() <= world::kMaxFileBytes) {
        text.append(buf, n);
    }
    const bool failed = std::ferror(f) != 0;
    std::fclose(f);
    if (failed) throw std::runtime_error(path + ": cannot read");
    return text;
}

void write_file(const std::string &path, const std::string &text)
{
    std::FILE *f = std::fopen(path.c_str(), "wb");
    if (f == nullptr) throw std::runtime_error("--out: cannot write '" + path + "': " + std::strerror(errno));
    const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    if (std::fclose(f) != 0 || !ok) throw std::runtime_error("--out: cannot write '" + path + "'");
}

struct RoomsArgs {
    std::string robot, base, out, check, far, floor, changed, users, profile = "exact", goal = "base";
    std::uint32_t seed = 1, count = 10;
};

// The realistic profile: the robot's scenario on a real base (host_sim/scenarios/R-real.scn);
// the same layouts, room for room, as the exact robot's.
std::string robot_scenario(const RoomsArgs &a)
{
    return a.profile == "real" ? a.robot + "-real" : a.robot;
}

void declare_options(Options &o, RoomsArgs &a)
{
    o.add_choice("--robot", "R", "whose scenario the rooms keep: paper-lab or paper-sim", &a.robot,
                 {"paper-lab", "paper-sim"});
    o.add_string("--base", "FILE",
                 "instead of --robot: the scenario file whose lines the rooms keep (files are named after its stem)",
                 &a.base);
    o.add_choice("--profile", "P",
                 "with --robot: exact (its scenario, default) or real (the realistic profile's, R-real: every "
                 "imperfection of a real base, docs/scenarios.md; files named R-real-...)",
                 &a.profile, {"exact", "real"});
    o.add_uint("--seed", "S", "seed of the rooms; room i depends on S and i only (default 1)", &a.seed, 0,
               UINT32_MAX);
    o.add_uint("--count", "N", "rooms 1..N (default 10)", &a.count, 1, 999);
    o.add_string("--out", "DIR", "writes DIR/<robot>-<seed>-<i>.scn (i as 001...; with --far "
               "DIR/<robot>-<family>-<W>x<H>-<seed>-<i>.scn), making DIR if needed", &a.out);
    o.add_choice("--far", "FAMILY",
                 "far-goal rooms instead: hall, open (goal in a corner), culdesac, serpentine, or mixed "
                 "(room i: hall, open, culdesac, serpentine, hall, ...)",
                 &a.far, {"hall", "open", "culdesac", "serpentine", "mixed"});
    o.add_choice("--users", "FAMILY",
                 "rooms like users' rooms instead: partitions (with doorways anywhere), s-floor, u-floor, pillars, "
                 "furniture (at an angle), along-walls (furniture against its wall or a slot off it, some turned), "
                 "or mixed (room i: each of the first five in turn); floors of any size, thin partitions, "
                 "doorways from the robot's diagonal up, encode auto (docs/scenarios.md)",
                 &a.users, {"partitions", "s-floor", "u-floor", "pillars", "furniture", "along-walls", "mixed"});
    o.add_choice("--goal", "G",
                 "with --users: base (the base's goal line, default) or circle (a plain circle as users draw "
                 "one, reached when the robot's centre is inside, of radius 0.4 to 1 robot diagonals; files named "
                 "<robot>-circle-<family>-...)",
                 &a.goal, {"base", "circle"});
    o.add_string("--floor", "WxH",
                 "with --far: the floor in m, each side the base's times 1/4, 1/2, 1, 2 or 4 (the state "
                 "cells keep their size; default: the base's)",
                 &a.floor);
    o.add_string("--check", "FILE",
                 "instead: check one scenario file as the rooms are checked (it parses; every start "
                 "reaches the goal through passages at least the robot's diagonal wide); it also warns "
                 "of code bits no reading changes, where the room's grid or furniture may make the robot "
                 "relapse and when its longest path is longer than train's learned threshold, and says "
                 "when encode auto chose another cell side (docs/scenarios.md)",
                 &a.check);
    o.add_string("--changed", "FILE",
                 "with --check: also check FILE, a room that --check's becomes during a run (train "
                 "--change-at K --changed FILE), and that only its obstacles differ",
                 &a.changed);
}

void print_help()
{
    std::cout << "\nEach room keeps the robot, sensors, pose source, timing, encoding, actions, rewards\n"
                 "and learning lines of host_sim/scenarios/<robot>.scn and draws interior walls,\n"
                 "obstacles and a goal; every start reaches the goal through passages at least the\n"
                 "robot's diagonal wide (docs/scenarios.md, \"Generated rooms\").\n"
                 "\nWith --far the rooms are far-goal rooms of one family (or all four in turn, mixed), on\n"
                 "the base's floor or a larger one (--floor; more x/y bits, the same cells), each with\n"
                 "its goal farther than the base's (docs/scenarios.md, \"Far-goal rooms\"). Every row\n"
                 "and --check say the room's longest shortest path from a start, in actions.\n";
}

// The file as the world reads it, refused as train would refuse it: the firmware's limits (code
// bits, range sensors, Cricket beacons, a pose source) are narrower than the world's.
robot_config_t load_checked(const std::string &file, world::Scenario &s)
{
    const ScenarioBundle b = load_scenario(file);
    s = *b.world;
    return b.robot;
}

// --check's report of one room: its passages, wall faces inside state cells, its longest path
// against the steps within which train counts an episode toward learning (the robot's default).
void check_one(const world::Scenario &s, const robot_config_t &robot)
{
    const world::PassageReport r = world::check_passages(s);
    if (!r.ok) throw UsageError(s.path + ": " + r.problem);  // a refusal is its one line
    std::printf("%s: passages ok: all %ld start points reach the goal (%ld free points in it) through "
                "passages at least the robot's diagonal (%.3f m) wide\n",
                s.path.c_str(), r.start_points, r.goal_points, 2.0 * world::robot_radius(s.robot));
    for (const world::ConstantCodeBit &c : world::constant_code_bits(s)) {
        std::printf("%s:%d: warning: %s\n", s.path.c_str(), c.line, world::constant_code_bit_warning(s, c).c_str());
    }
    if (const std::string w = beacon_rate_warning(s); !w.empty()) {
        std::printf("%s: warning: %s\n", s.path.c_str(), w.c_str());
    }
    if (const int faces = world::faces_inside_cells(s)) {
        std::printf("%s: warning: %d wall face(s) lie inside state cells of the equal grid (encode x/y): "
                    "a step beside them passes or bumps by where in its cell the robot stands, which the "
                    "state cannot show; 'encode auto' fits the cells to the room (docs/agent.md)\n",
                    s.path.c_str(), faces);
    }
    if (const world::Encoding::WalkRefit &w = s.encoding.walk_refit; w.to > 0.0) {
        std::printf("%s: grid: cells of about %.3f m, not %.3f m: there %ld of the %ld stops reached no goal "
                    "stop a step and a turn at a time, here all do (docs/agent.md, \"When furniture closes the "
                    "grid's way\")\n",
                    s.path.c_str(), w.to, w.from, w.stranded, w.stops);
    }
    const world::StopWalkReport walk = world::stop_walk(s);
    if (walk.stranded > 0) {
        std::printf("%s: warning: %ld of the %ld stops the robot's steps end at reach no goal stop "
                    "a step and a turn at a time",
                    s.path.c_str(), walk.stranded, walk.cells);
        for (std::size_t k = 0; k < walk.blocking.size() && k < 3; k++) {
            const world::TightStop &t = walk.blocking[k];
            std::printf("%s cell (%d, %d)'s stop at (%.3f, %.3f) lies %.3f m from %s", k ? ";" : "; beside them,",
                        t.i, t.j, t.x, t.y, t.clearance,
                        t.line ? ("the obstacle on line " + std::to_string(t.line)).c_str() : "the wall");
        }
        std::printf(": its ways from them pass stops where it bumps, and it may never learn them; leave it a "
                    "turn's room (%.3f m) there",
                    world::robot_radius(s.robot));
        if (const world::Encoding::WalkRefit &w = s.encoding.walk_refit; w.from > 0.0 && w.to == 0.0) {
            const auto [lo, hi] =
                std::minmax_element(std::begin(world::kWalkSideFactors), std::end(world::kWalkSideFactors));
            std::printf(" (encode auto tried cells of %.3f to %.3f m: none leaves every stop a way to the goal)",
                        *lo * w.from, *hi * w.from);
        }
        std::printf(" (docs/agent.md, \"What it does not handle yet\")\n");
    }
    if (const world::SlotReport slot = world::tight_slot(s); world::slot_warns(slot)) {
        std::printf("%s: warning: %ld of the %ld start points reach the goal only through a slot narrower "
                    "than %.3f m beside furniture at an angle or round (the obstacle on line %d: about %.3f m at "
                    "(%.3f, %.3f)): the robot's steps pass it by centimetres and relapse there; leave it about "
                    "0.5 m (docs/scenarios.md, \"Leave the robot room on its way to the goal\")\n",
                    s.path.c_str(), slot.behind, slot.starts, slot.limit, slot.line, slot.width, slot.x, slot.y);
    }
    const world::PathReport p = world::longest_path(s);
    if (p.longest >= 0) {
        std::printf("%s: longest path: %ld actions from the farthest start to the goal at best (%dx%d state "
                    "cells, forward/backward one cell, 90-degree turns)\n",
                    s.path.c_str(), p.longest, p.nx, p.ny);
        const std::string late = long_path_warning(p.longest, p.beyond(default_learned_threshold(robot)),
                                                   p.start_states, default_learned_threshold(robot),
                                                   default_threshold_source(robot), s.encoding.fitted);
        if (!late.empty()) std::printf("%s: warning: %s\n", s.path.c_str(), late.c_str());
    } else {
        std::printf("%s: longest path: none: %ld of %ld start (place, heading) pairs cannot reach the goal "
                    "one state cell at a time (%dx%d cells)\n",
                    s.path.c_str(), p.stranded, p.start_states, p.nx, p.ny);
    }
}

void check_rooms(const Options &o, const RoomsArgs &a)
{
    for (const char *other :
         {"--robot", "--base", "--profile", "--seed", "--count", "--out", "--far", "--floor", "--users", "--goal"}) {
        if (o.seen(other)) throw UsageError(std::string("--check: cannot be combined with ") + other);
    }
    world::Scenario before, after;
    const robot_config_t robot = load_checked(a.check, before);
    robot_config_t robot_after{};
    if (o.seen("--changed")) {  // the pair first: a refusal prints nothing else
        robot_after = load_checked(a.changed, after);
        const std::string problem = world::layout_change_problem(before, after);
        if (!problem.empty()) {
            throw UsageError("--changed: " + after.path + " is not a change of " + before.path + ": " + problem);
        }
    }
    check_one(before, robot);
    if (o.seen("--changed")) {
        check_one(after, robot_after);
        std::printf("%s: a change of %s: only the obstacles differ (%zu -> %zu)\n", after.path.c_str(),
                    before.path.c_str(), before.obstacles.size(), after.obstacles.size());
    }
}

// The base scenario's text and the floor the rooms are drawn on (--floor, or the base's).
struct RoomsBase {
    std::string text;
    double floor_w = 0, floor_h = 0;
};

RoomsBase load_base(const Options &o, const RoomsArgs &a)
{
    const std::string base_path = o.seen("--robot") ? world::resolve_scenario_path(robot_scenario(a)) : a.base;
    RoomsBase b;
    try {
        b.text = read_file(base_path);
    } catch (const std::runtime_error &e) {
        throw UsageError(e.what());  // bad input, not a failure while running
    }
    world::Scenario parsed;
    std::string error;
    if (!world::parse_scenario(b.text, base_path, &parsed, &error)) throw UsageError(error);
    b.floor_w = parsed.arena_w;
    b.floor_h = parsed.arena_h;
    if (o.seen("--floor")) {
        char tail = 0;
        if (std::sscanf(a.floor.c_str(), "%lfx%lf%c", &b.floor_w, &b.floor_h, &tail) != 2) {
            throw UsageError("--floor: '" + a.floor + "' is not WxH (metres, e.g. 16x4)");
        }
        if (!world::floor_check(parsed, b.floor_w, b.floor_h, nullptr, nullptr, &error)) {
            throw UsageError("--floor: " + error);
        }
    }
    return b;
}

// How the rooms are named and said to be made: the files' prefix, the base's label, the command.
struct RoomsNaming {
    std::string prefix, label, command;
};

RoomsNaming naming_of(const std::string &program, const Options &o, const RoomsArgs &a)
{
    const std::string scn = robot_scenario(a);
    RoomsNaming n{scn, "host_sim/scenarios/" + scn + ".scn",
                  program + " rooms --robot " + a.robot + (a.profile == "real" ? " --profile real" : "") +
                      " --seed " + std::to_string(a.seed)};
    if (o.seen("--base")) {
        const std::size_t slash = a.base.find_last_of('/');
        n.prefix = a.base.substr(slash == std::string::npos ? 0 : slash + 1);
        if (n.prefix.size() > 4 && n.prefix.compare(n.prefix.size() - 4, 4, ".scn") == 0) {
            n.prefix.resize(n.prefix.size() - 4);
        }
        n.label = a.base;
        n.command = program + " rooms --base " + a.base + " --seed " + std::to_string(a.seed);
    }
    return n;
}

// Room i: a far-goal room (--far), a room like users' (--users) or a generated one.
std::pair<std::string, world::Room> make_room(const Options &o, const RoomsArgs &a, const RoomsBase &b,
                                              const RoomsNaming &n, std::uint32_t i)
{
    const std::string &command = n.command;
    world::RoomSpec spec;
    std::string room_command = command;
    if (o.seen("--far")) {
        spec.far = true;
        spec.floor_w = b.floor_w;
        spec.floor_h = b.floor_h;
        if (a.far == "mixed") {
            spec.family = world::far_family_of_index(i);
        } else {
            world::far_family_from_name(a.far, &spec.family);
        }
        // The command that makes this very room (mixed names each room's family).
        const std::string at = command.substr(0, command.rfind(" --seed "));
        room_command = at + " --far " + world::far_family_name(spec.family) + " --floor " +
                       world::floor_name(b.floor_w, b.floor_h) + command.substr(command.rfind(" --seed "));
    }
    world::Room room;
    std::string error;
    std::string name;
    if (o.seen("--users")) {
        world::UserFamily family{};
        if (a.users == "mixed") {
            family = world::user_family_of_index(i);
        } else {
            world::user_family_from_name(a.users, &family);
        }
        const std::string at = command.substr(0, command.rfind(" --seed "));
        world::UserGoal goal{};
        world::user_goal_from_name(a.goal, &goal);
        const std::string circle = goal == world::UserGoal::Circle ? "circle-" : "";
        room_command = at + " --users " + world::user_family_name(family) +
                       (circle.empty() ? "" : " --goal circle") + command.substr(command.rfind(" --seed "));
        char idx[16];
        std::snprintf(idx, sizeof idx, "%03u", i);
        name = n.prefix + "-" + circle + world::user_family_name(family) + "-" + std::to_string(a.seed) + "-" + idx +
               ".scn";
        if (!world::generate_user_room(b.text, n.label, room_command, a.seed, i, family, goal, name, &room, &error)) {
            throw std::runtime_error(error);
        }
    } else {
        name = world::room_file_name(n.prefix, spec, b.floor_w, b.floor_h, a.seed, i);
        if (!world::generate_room(b.text, n.label, room_command, a.seed, i, spec, name, &room, &error)) {
            throw std::runtime_error(error);
        }
    }
    return {name, std::move(room)};
}

// The rooms, or with --check the check of one scenario file.
void write_rooms(const std::string &program, const Options &o, RoomsArgs &a)
{
    if (o.seen("--check")) {
        check_rooms(o, a);
        return;
    }
    if (o.seen("--robot") == o.seen("--base")) {
        throw UsageError(o.seen("--robot") ? "--base: cannot be combined with --robot"
                                           : "--robot: required (paper-lab or paper-sim), or --base FILE");
    }
    if (!o.seen("--out") || a.out.empty()) throw UsageError("--out: required (a directory)");
    if (o.seen("--floor") && !o.seen("--far")) throw UsageError("--floor: needs --far");
    if (o.seen("--users") && o.seen("--far")) throw UsageError("--users: cannot be combined with --far");
    if (o.seen("--goal") && !o.seen("--users")) throw UsageError("--goal: needs --users");
    if (o.seen("--changed")) throw UsageError("--changed: only with --check");
    if (o.seen("--profile") && o.seen("--base")) {
        throw UsageError("--profile: only with --robot (a --base file carries its own imperfections)");
    }

    const RoomsBase b = load_base(o, a);
    const RoomsNaming n = naming_of(program, o, a);
    // All rooms first, so that a failure leaves no files behind.
    std::vector<std::pair<std::string, world::Room>> rooms;
    for (std::uint32_t i = 1; i <= a.count; i++) {
        rooms.push_back(make_room(o, a, b, n, i));
    }
    std::error_code ec;
    std::filesystem::create_directories(a.out, ec);
    if (ec) throw std::runtime_error("--out: cannot make '" + a.out + "': " + ec.message());
    std::printf("file,walls,obstacles,draw,start_points,longest_path\n");
    for (const auto &r : rooms) {
        const std::string path = a.out + "/" + r.first;
        write_file(path, r.second.text);
        std::printf("%s,%d,%d,%u,%ld,%ld\n", path.c_str(), r.second.walls, r.second.obstacles, r.second.draw,
                    r.second.passages.start_points, r.second.path.longest);
    }
}

}  // namespace

int cmd_rooms(const std::string &program, const std::vector<std::string> &args)
{
    return run_command(
        program, args, "rooms",
        "seeded random rooms for a robot: its scenario with a new layout, one file each",
        declare_options, write_rooms, print_help);
}

}  // namespace dynaqpc
