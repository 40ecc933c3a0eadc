// SPDX-License-Identifier: MIT
// dynaqpc-sim rooms: seeded random rooms for a robot, one scenario file each (world/rooms.h).
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "commands.h"
#include "options.h"
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

}  // namespace

int cmd_rooms(const std::string &program, const std::vector<std::string> &args)
{
    std::string robot, base, out, check, far, floor, changed, users, profile = "exact";
    std::uint32_t seed = 1, count = 10;
    Options o("rooms", "seeded random rooms for a robot: its scenario with a new layout, one file each");
    o.add_choice("--robot", "R", "whose scenario the rooms keep: paper-lab or paper-sim", &robot,
                 {"paper-lab", "paper-sim"});
    o.add_string("--base", "FILE",
                 "instead of --robot: the scenario file whose lines the rooms keep (files are named after its stem)",
                 &base);
    o.add_choice("--profile", "P",
                 "with --robot: exact (its scenario, default) or real (the realistic profile's, R-real: every "
                 "imperfection of a real base, docs/scenarios.md; files named R-real-...)",
                 &profile, {"exact", "real"});
    o.add_uint("--seed", "S", "seed of the rooms; room i depends on S and i only (default 1)", &seed, 0,
               UINT32_MAX);
    o.add_uint("--count", "N", "rooms 1..N (default 10)", &count, 1, 999);
    o.add_string("--out", "DIR", "writes DIR/<robot>-<seed>-<i>.scn (i as 001...; with --far "
               "DIR/<robot>-<family>-<W>x<H>-<seed>-<i>.scn), making DIR if needed", &out);
    o.add_choice("--far", "FAMILY",
                 "far-goal rooms instead: hall, open (goal in a corner), culdesac, serpentine, or mixed "
                 "(room i: hall, open, culdesac, serpentine, hall, ...)",
                 &far, {"hall", "open", "culdesac", "serpentine", "mixed"});
    o.add_choice("--users", "FAMILY",
                 "rooms like users' rooms instead: partitions (with doorways anywhere), s-floor, u-floor, pillars, "
                 "furniture (at an angle), or mixed (room i: each in turn); floors of any size, thin "
                 "partitions, doorways from the robot's diagonal up, encode auto (docs/scenarios.md)",
                 &users, {"partitions", "s-floor", "u-floor", "pillars", "furniture", "mixed"});
    o.add_string("--floor", "WxH",
                 "with --far: the floor in m, each side the base's times 1/4, 1/2, 1, 2 or 4 (the state "
                 "cells keep their size; default: the base's)",
                 &floor);
    o.add_string("--check", "FILE",
                 "instead: check one scenario file as the rooms are checked (it parses; every start "
                 "reaches the goal through passages at least the robot's diagonal wide)",
                 &check);
    o.add_string("--changed", "FILE",
                 "with --check: also check FILE, a room that --check's becomes during a run (train "
                 "--change-at K --changed FILE), and that only its obstacles differ",
                 &changed);
    o.parse(args);
    if (o.help_requested()) {
        o.print_usage(std::cout, program);
        std::cout << "\nEach room keeps the robot, sensors, pose source, timing, encoding, actions, rewards\n"
                     "and learning lines of host_sim/scenarios/<robot>.scn and draws interior walls,\n"
                     "obstacles and a goal; every start reaches the goal through passages at least the\n"
                     "robot's diagonal wide (docs/scenarios.md, \"Generated rooms\").\n"
                     "\nWith --far the rooms are far-goal rooms of one family (or all four in turn, mixed), on\n"
                     "the base's floor or a larger one (--floor; more x/y bits, the same cells), each with\n"
                     "its goal farther than the base's (docs/scenarios.md, \"Far-goal rooms\"). Every row\n"
                     "and --check say the room's longest shortest path from a start, in actions.\n";
        return kExitOk;
    }
    if (o.seen("--check")) {
        for (const char *other :
             {"--robot", "--base", "--profile", "--seed", "--count", "--out", "--far", "--floor", "--users"}) {
            if (o.seen(other)) throw UsageError(std::string("--check: cannot be combined with ") + other);
        }
        auto load = [](const std::string &file, world::Scenario &s) {
            std::string error;
            if (!world::load_scenario(file, &s, &error)) throw UsageError(error);
        };
        auto check_one = [](const world::Scenario &s) {
            const world::PassageReport r = world::check_passages(s);
            if (!r.ok) throw UsageError(s.path + ": " + r.problem);
            std::printf("%s: passages ok: all %ld start points reach the goal (%ld free points in it) through "
                        "passages at least the robot's diagonal (%.3f m) wide\n",
                        s.path.c_str(), r.start_points, r.goal_points, 2.0 * world::robot_radius(s.robot));
            if (const int faces = world::faces_inside_cells(s)) {
                std::printf("%s: warning: %d wall face(s) lie inside state cells of the equal grid (encode x/y): "
                            "a step beside them passes or bumps by where in its cell the robot stands, which the "
                            "state cannot show; 'encode auto' fits the cells to the room (docs/agent.md)\n",
                            s.path.c_str(), faces);
            }
            const world::PathReport p = world::longest_path(s);
            if (p.longest >= 0) {
                std::printf("%s: longest path: %ld actions from the farthest start to the goal at best (%dx%d state "
                            "cells, forward/backward one cell, 90-degree turns)\n",
                            s.path.c_str(), p.longest, p.nx, p.ny);
            } else {
                std::printf("%s: longest path: none: %ld of %ld start (place, heading) pairs cannot reach the goal "
                            "one state cell at a time (%dx%d cells)\n",
                            s.path.c_str(), p.stranded, p.start_states, p.nx, p.ny);
            }
        };
        world::Scenario before, after;
        load(check, before);
        if (o.seen("--changed")) {  // the pair first: a refusal prints nothing else
            load(changed, after);
            const std::string problem = world::layout_change_problem(before, after);
            if (!problem.empty()) {
                throw UsageError("--changed: " + after.path + " is not a change of " + before.path + ": " + problem);
            }
        }
        check_one(before);
        if (o.seen("--changed")) {
            check_one(after);
            std::printf("%s: a change of %s: only the obstacles differ (%zu -> %zu)\n", after.path.c_str(),
                        before.path.c_str(), before.obstacles.size(), after.obstacles.size());
        }
        return kExitOk;
    }
    if (o.seen("--robot") == o.seen("--base")) {
        throw UsageError(o.seen("--robot") ? "--base: cannot be combined with --robot"
                                           : "--robot: required (paper-lab or paper-sim), or --base FILE");
    }
    if (!o.seen("--out") || out.empty()) throw UsageError("--out: required (a directory)");
    if (o.seen("--floor") && !o.seen("--far")) throw UsageError("--floor: needs --far");
    if (o.seen("--users") && o.seen("--far")) throw UsageError("--users: cannot be combined with --far");
    if (o.seen("--changed")) throw UsageError("--changed: only with --check");
    if (o.seen("--profile") && o.seen("--base")) {
        throw UsageError("--profile: only with --robot (a --base file carries its own imperfections)");
    }
    // The realistic profile: the robot's scenario on a real base (host_sim/scenarios/R-real.scn);
    // the same layouts, room for room, as the exact robot's.
    const std::string scn = profile == "real" ? robot + "-real" : robot;
    const std::string base_path = o.seen("--robot") ? world::resolve_scenario_path(scn) : base;
    std::string base_text;
    double floor_w = 0, floor_h = 0;
    try {
        base_text = read_file(base_path);
    } catch (const std::runtime_error &e) {
        throw UsageError(e.what());  // bad input, not a failure while running
    }
    {
        world::Scenario parsed;
        std::string error;
        if (!world::parse_scenario(base_text, base_path, &parsed, &error)) throw UsageError(error);
        floor_w = parsed.arena_w;
        floor_h = parsed.arena_h;
        if (o.seen("--floor")) {
            char tail = 0;
            if (std::sscanf(floor.c_str(), "%lfx%lf%c", &floor_w, &floor_h, &tail) != 2) {
                throw UsageError("--floor: '" + floor + "' is not WxH (metres, e.g. 16x4)");
            }
            if (!world::floor_check(parsed, floor_w, floor_h, nullptr, nullptr, &error)) {
                throw UsageError("--floor: " + error);
            }
        }
    }
    std::string prefix = scn, label = "host_sim/scenarios/" + scn + ".scn";
    std::string command = program + " rooms --robot " + robot + (profile == "real" ? " --profile real" : "") +
                          " --seed " + std::to_string(seed);
    if (o.seen("--base")) {
        const std::size_t slash = base.find_last_of('/');
        prefix = base.substr(slash == std::string::npos ? 0 : slash + 1);
        if (prefix.size() > 4 && prefix.compare(prefix.size() - 4, 4, ".scn") == 0) prefix.resize(prefix.size() - 4);
        label = base;
        command = program + " rooms --base " + base + " --seed " + std::to_string(seed);
    }
    // All rooms first, so that a failure leaves no files behind.
    std::vector<std::pair<std::string, world::Room>> rooms;
    for (std::uint32_t i = 1; i <= count; i++) {
        world::RoomSpec spec;
        std::string room_command = command;
        if (o.seen("--far")) {
            spec.far = true;
            spec.floor_w = floor_w;
            spec.floor_h = floor_h;
            if (far == "mixed") {
                spec.family = world::far_family_of_index(i);
            } else {
                world::far_family_from_name(far, &spec.family);
            }
            // The command that makes this very room (mixed names each room's family).
            const std::string at = command.substr(0, command.rfind(" --seed "));
            room_command = at + " --far " + world::far_family_name(spec.family) + " --floor " +
                           world::floor_name(floor_w, floor_h) + command.substr(command.rfind(" --seed "));
        }
        world::Room room;
        std::string error;
        std::string name;
        if (o.seen("--users")) {
            world::UserFamily family{};
            if (users == "mixed") {
                family = world::user_family_of_index(i);
            } else {
                world::user_family_from_name(users, &family);
            }
            const std::string at = command.substr(0, command.rfind(" --seed "));
            room_command = at + " --users " + world::user_family_name(family) + command.substr(command.rfind(" --seed "));
            char idx[16];
            std::snprintf(idx, sizeof idx, "%03u", i);
            name = prefix + "-" + world::user_family_name(family) + "-" + std::to_string(seed) + "-" + idx + ".scn";
            if (!world::generate_user_room(base_text, label, room_command, seed, i, family, name, &room, &error)) {
                throw std::runtime_error(error);
            }
        } else {
            name = world::room_file_name(prefix, spec, floor_w, floor_h, seed, i);
            if (!world::generate_room(base_text, label, room_command, seed, i, spec, name, &room, &error)) {
                throw std::runtime_error(error);
            }
        }
        rooms.emplace_back(name, std::move(room));
    }
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    if (ec) throw std::runtime_error("--out: cannot make '" + out + "': " + ec.message());
    std::printf("file,walls,obstacles,draw,start_points,longest_path\n");
    for (const auto &r : rooms) {
        const std::string path = out + "/" + r.first;
        write_file(path, r.second.text);
        std::printf("%s,%d,%d,%u,%ld,%ld\n", path.c_str(), r.second.walls, r.second.obstacles, r.second.draw,
                    r.second.passages.start_points, r.second.path.longest);
    }
    return kExitOk;
}

}  // namespace dynaqpc
