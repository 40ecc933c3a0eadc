// SPDX-License-Identifier: MIT
// Tests of the room generator and the passage check (world/rooms.h), and of the rooms committed
// under host_sim/rooms/: each parses, passes, and is what its documented command generates.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

// cmocka 1.1.5's header has no extern "C" of its own.
extern "C" {
#include "test_common.h"
}
#include "world/grid_fit.h"
#include "world/rooms.h"
#include "world/user_rooms.h"
#include "world/scenario.h"

#ifndef WORLD_TEST_ROOMS
#define WORLD_TEST_ROOMS "host_sim/rooms"
#endif

namespace {

const char *const kRobots[] = {"paper-lab", "paper-sim"};

std::string read(const std::string &path)
{
    std::ifstream in(path, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::string base_text(const std::string &robot)
{
    const std::string t = read(world::resolve_scenario_path(robot));
    assert_true(!t.empty());
    return t;
}

std::string label(const std::string &robot)
{
    return "host_sim/scenarios/" + robot + ".scn";
}

std::string command(const std::string &robot, std::uint32_t seed)
{
    return "dynaqpc-sim rooms --robot " + robot + " --seed " + std::to_string(seed);
}

world::Room make(const std::string &robot, std::uint32_t seed, std::uint32_t index)
{
    char name[96];
    std::snprintf(name, sizeof name, "%s-%u-%03u.scn", robot.c_str(), seed, index);
    world::Room room;
    std::string err;
    const bool ok = world::generate_room(base_text(robot), label(robot), command(robot, seed), seed, index,
                                         name, &room, &err);
    if (!ok) std::fprintf(stderr, "%s\n", err.c_str());
    assert_true(ok);
    return room;
}

// The key of a line (before any comment), or "" for a comment or blank line.
std::string key_of(const std::string &line)
{
    std::istringstream ss(line.substr(0, line.find('#')));
    std::string k;
    ss >> k;
    return k;
}

// The lines of `text` that are not comments, blank, `obstacle` or `goal`.
std::vector<std::string> non_layout_lines(const std::string &text)
{
    std::vector<std::string> out;
    std::istringstream ss(text);
    std::string line;
    while (std::getline(ss, line)) {
        const std::string k = key_of(line);
        if (!k.empty() && k != "obstacle" && k != "goal") out.push_back(line);
    }
    return out;
}

// The base scenario with its layout replaced by `layout` (obstacle and goal lines).
// The base's lines with `layout`; `encode`, when given, in place of the base's encode line.
world::Scenario with_layout(const std::string &robot, const std::string &layout, const std::string &encode = "")
{
    std::string text;
    for (const std::string &l : non_layout_lines(base_text(robot))) {
        text += (!encode.empty() && key_of(l) == "encode" ? encode : l) + "\n";
    }
    text += layout;
    world::Scenario s;
    std::string err;
    const bool ok = world::parse_scenario(text, "layout.scn", &s, &err);
    if (!ok) std::fprintf(stderr, "%s\n", err.c_str());
    assert_true(ok);
    return s;
}

// A wall across the room at x = `x` (thickness 0.1 m), with a door of `door` m from y = `y0`.
std::string wall_with_door(double arena_h, double x, double y0, double door)
{
    door = std::round(door * 1000.0) / 1000.0;  // so that the file's numbers are exact
    char buf[256];
    std::snprintf(buf, sizeof buf, "obstacle box %.4f %.4f 0.1 %.4f\nobstacle box %.4f %.4f 0.1 %.4f\n", x,
                  y0 / 2, y0, x, (y0 + door + arena_h) / 2, arena_h - y0 - door);
    return buf;
}

void test_shipped_scenarios_pass(void **state)
{
    (void)state;
    for (const char *robot : kRobots) {
        world::Scenario s;
        std::string err;
        assert_true(world::load_scenario(robot, &s, &err));
        const world::PassageReport r = world::check_passages(s);
        if (!r.ok) std::fprintf(stderr, "%s: %s\n", robot, r.problem.c_str());
        assert_true(r.ok);
        assert_true(r.start_points > 0 && r.goal_points > 0);
        assert_int_equal(r.stranded_points, 0);
    }
}

// A door a little narrower than the robot's diagonal is refused, a little wider accepted.
void test_narrow_door_refused(void **state)
{
    (void)state;
    struct Case {
        const char *robot;
        double wall_x, door_y;
        const char *goal;
    } cases[] = {
        {"paper-lab", 2.0, 1.2, "goal 3.75 2.55 0.3 cells\n"},
        {"paper-sim", 2.5, 3.0, "goal 5.5 4.0 0.5\n"},
    };
    for (const Case &c : cases) {
        world::Scenario base;
        std::string err;
        assert_true(world::load_scenario(c.robot, &base, &err));
        const double diag = 2.0 * world::robot_radius(base.robot);
        const world::Scenario narrow =
            with_layout(c.robot, wall_with_door(base.arena_h, c.wall_x, c.door_y, 0.9 * diag) + c.goal);
        const world::PassageReport rn = world::check_passages(narrow);
        assert_false(rn.ok);
        assert_true(rn.stranded_points > 0);
        assert_true(rn.problem.find("cannot reach the goal") != std::string::npos);
        // It names the door as where the way is narrowest, about as wide as the door.
        double width = 0, px = 0, py = 0;
        const std::size_t at = rn.problem.find("narrows to ");
        assert_true(at != std::string::npos);
        assert_int_equal(std::sscanf(rn.problem.c_str() + at, "narrows to %lf m at (%lf, %lf)", &width, &px, &py), 3);
        const double step_ = world::start_grid_step(narrow);
        assert_true(std::fabs(px - c.wall_x) <= 0.05 + step_);  // in the 0.1 m wall's door
        assert_true(py >= c.door_y && py <= c.door_y + 0.9 * diag);
        assert_true(width <= 0.9 * diag + 1e-9 && width >= 0.9 * diag - 2 * step_);
        const world::Scenario wide =
            with_layout(c.robot, wall_with_door(base.arena_h, c.wall_x, c.door_y, 1.2 * diag) + c.goal);
        const world::PassageReport rw = world::check_passages(wide);
        if (!rw.ok) std::fprintf(stderr, "%s: %s\n", c.robot, rw.problem.c_str());
        assert_true(rw.ok);
        // The narrow room strands exactly the starts left of the wall.
        long left = 0;
        const double step = world::start_grid_step(narrow);
        for (double y = step / 2; y < narrow.arena_h; y += step) {
            for (double x = step / 2; x < c.wall_x; x += step) left += world::start_position_ok(narrow, x, y);
        }
        assert_int_equal(rn.stranded_points, left);
    }
}

// A goal the robot cannot get into, and a goal walled in.
void test_unreachable_goal_refused(void **state)
{
    (void)state;
    // paper-sim's goal (radius 0.5) between two boxes 0.7 m apart: the 0.78 m robot fits nowhere.
    const world::Scenario tight = with_layout(
        "paper-sim", "obstacle box 3.15 4 1 3\nobstacle box 4.85 4 1 3\ngoal 4 4 0.3\n");
    const world::PassageReport rt = world::check_passages(tight);
    assert_false(rt.ok);
    assert_true(rt.problem.find("fits nowhere in the goal") != std::string::npos);
    // paper-lab's goal boxed in by three walls and the east wall.
    const world::Scenario boxed = with_layout(
        "paper-lab", "obstacle box 3.0 2.55 0.1 1.2\nobstacle box 3.65 3.1 1.3 0.1\n"
                     "obstacle box 3.65 2.0 1.3 0.1\ngoal 3.75 2.55 0.3 cells\n");
    const world::PassageReport rb = world::check_passages(boxed);
    assert_false(rb.ok);
    assert_true(rb.problem.find("cannot reach the goal") != std::string::npos);
    assert_true(rb.problem.find("walls close it off from the goal") != std::string::npos);
}

// The walk of a robot that stops at centres: at the robot's cell side the den's armchair closes
// the way behind the sofa, and the fit moves the side (rule 7) until every stop reaches the goal;
// a partition's thin cells are stepped over, not stops; an S on paper-lab's floor leaves no way
// closed; a robot that stops past an edge has no such walk.
void test_stop_walk(void **state)
{
    (void)state;
    const std::string drawn = std::string(WORLD_TEST_ROOMS) + "/drawn/";
    world::Scenario den, den_half_metre, partitions, s_lab, sim;
    std::string err;
    assert_true(world::load_scenario(drawn + "paper-lab-sofa-den.scn", &den, &err));
    std::ifstream in(drawn + "paper-lab-sofa-den.scn");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t at = text.find("\nencode auto ");
    assert_true(at != std::string::npos);
    text.replace(at, 13, "\nencode auto cell 0.5 ");  // a side the user gives: no refit
    assert_true(world::parse_scenario(text, "den.scn", &den_half_metre, &err));
    assert_true(world::load_scenario(std::string(WORLD_TEST_ROOMS) +
                                         "/users-circle-tune/paper-lab-circle-partitions-31-011.scn",
                                     &partitions, &err));
    assert_true(world::load_scenario(drawn + "paper-lab-s-lab.scn", &s_lab, &err));
    assert_true(world::load_scenario("paper-sim", &sim, &err));

    const world::StopWalkReport d = world::stop_walk(den_half_metre);
    assert_true(d.stranded * world::kWalkStrandedShare >= d.cells);
    bool armchair = false;
    for (const world::TightStop &t : d.blocking) {
        assert_true(t.clearance > 0.0 && t.clearance < world::robot_radius(den.robot));
        armchair = armchair || (t.i == 1 && t.j == 6 && t.line == 6);
    }
    assert_true(armchair);
    assert_true(den_half_metre.encoding.walk_refit.to == 0.0);

    const world::Encoding::WalkRefit &r = den.encoding.walk_refit;
    assert_true(r.from == 0.5 && r.to > 0.0 && r.to != r.from);
    assert_int_equal(r.stranded, d.stranded);
    assert_int_equal(r.stops, d.cells);
    const world::StopWalkReport refit = world::stop_walk(den);
    assert_true(refit.cells > 0);
    assert_int_equal(refit.stranded, 0);

    assert_int_equal(world::stop_walk(partitions).stranded, 0);
    assert_true(partitions.encoding.walk_refit.from == 0.0);  // nothing stranded: not tried
    const world::StopWalkReport ok = world::stop_walk(s_lab);
    assert_true(ok.cells > 0);
    assert_int_equal(ok.stranded, 0);
    assert_true(s_lab.encoding.walk_refit.to == 0.0);
    assert_int_equal(world::stop_walk(sim).cells, 0);  // stops past an edge, not at centres
}

// Slots beside furniture at an angle or round: a bedroom whose goal corner lies behind 0.34 m
// beside a nightstand and the bed warns; a kitchen island's 0.42 m ways and an S of square
// partitions do not.
void test_tight_slot(void **state)
{
    (void)state;
    const std::string drawn = std::string(WORLD_TEST_ROOMS) + "/drawn/";
    world::Scenario bedroom, kitchen, s_lab;
    std::string err;
    assert_true(world::load_scenario(drawn + "paper-lab-bedroom-angled-bed.scn", &bedroom, &err));
    assert_true(world::load_scenario(drawn + "paper-lab-kitchen-island.scn", &kitchen, &err));
    assert_true(world::load_scenario(drawn + "paper-lab-s-lab.scn", &s_lab, &err));
    const world::SlotReport b = world::tight_slot(bedroom);
    assert_true(world::slot_warns(b));
    assert_true(b.behind * 2 > b.starts);
    assert_true(b.width > 2.0 * world::robot_radius(bedroom.robot) && b.width < b.limit);
    assert_true(std::fabs(b.limit - 2.0 * (world::robot_radius(bedroom.robot) + world::kPinchClearance)) < 1e-12);
    assert_int_equal(b.line, 8);
    assert_false(world::slot_warns(world::tight_slot(kitchen)));
    const world::SlotReport s = world::tight_slot(s_lab);
    assert_true(s.starts > 0);
    assert_int_equal(s.behind, 0);
}

// Rule 7 keeps a side only where some stop is left: on a 4.2 m floor of small pins (turned boxes,
// which cut no cell) at every centre of the 0.475 m side's 9 x 9 grid, that side's stops all lie
// within a turn of a pin, so none is stranded either; the 0.5 m grid keeps the goal's stop.
void test_walk_refit_needs_a_stop(void **state)
{
    (void)state;
    std::ifstream in(std::string(WORLD_TEST_ROOMS) + "/drawn/paper-lab-sofa-den.scn");
    std::ostringstream text;
    text << "arena 4.2 4.2\ngoal 0.25 0.25 0.05\nobstacle box 0.127 0.127 0.02 0.02 45\n";
    for (int i = 0; i < 9; i++) {
        for (int j = 0; j < 9; j++) {
            if (i == 0 && j == 0) continue;
            text << "obstacle box " << 4.2 / 9 * (i + 0.5) << " " << 4.2 / 9 * (j + 0.5) << " 0.02 0.02 45\n";
        }
    }
    for (std::string line; std::getline(in, line);) {
        const std::string key = line.substr(0, line.find(' '));
        if (key != "arena" && key != "obstacle" && key != "goal") text << line << "\n";
    }
    world::Scenario pins;
    std::string err;
    assert_true(world::parse_scenario(text.str(), "pins.scn", &pins, &err));
    assert_true(pins.encoding.walk_refit.to == 0.0);
    assert_int_equal(pins.encoding.x_edges.size(), 9);  // the 0.5 m side's 8 cells
    const world::StopWalkReport w = world::stop_walk(pins);
    assert_true(w.cells > 0);
    assert_true(w.stranded * world::kWalkStrandedShare >= w.cells);
}

void test_generated_rooms(void **state)
{
    (void)state;
    for (const char *robot : kRobots) {
        world::Scenario base;
        std::string err;
        assert_true(world::load_scenario(robot, &base, &err));
        const std::vector<std::string> kept = non_layout_lines(base_text(robot));
        int walls = 0, obstacles = 0;
        for (std::uint32_t seed : {1u, 77u}) {
            for (std::uint32_t i = 1; i <= 6; i++) {
                const world::Room room = make(robot, seed, i);
                // Parsed again from its text, as a user's train --scenario would.
                world::Scenario s;
                assert_true(world::parse_scenario(room.text, "again.scn", &s, &err));
                assert_true(world::check_passages(s).ok);
                // Everything but the layout is the base's, line for line and in order.
                assert_true(non_layout_lines(room.text) == kept);
                assert_true(s.arena_w == base.arena_w && s.arena_h == base.arena_h);
                assert_true(s.goal.cells == base.goal.cells);
                assert_int_equal(s.cricket.beacons.size(), base.cricket.beacons.size());
                assert_true(!s.obstacles.empty());
                assert_true(room.obstacles >= 1);
                walls += room.walls;
                obstacles += room.obstacles;
                assert_string_equal(s.name.c_str(), "again");
            }
        }
        // Over 12 rooms both kinds of piece appear, several per room.
        assert_true(walls >= 6);
        assert_true(obstacles >= 24);
    }
}

void test_same_seed_same_room(void **state)
{
    (void)state;
    for (const char *robot : kRobots) {
        const world::Room a = make(robot, 5, 3), b = make(robot, 5, 3);
        assert_true(a.text == b.text);
        assert_int_equal(a.draw, b.draw);
        // Another index or seed is another room (its layout, not only its header).
        const world::Room c = make(robot, 5, 4), d = make(robot, 6, 3);
        assert_true(a.scenario.obstacles.size() != c.scenario.obstacles.size() ||
                    a.scenario.obstacles[0].cx != c.scenario.obstacles[0].cx);
        assert_true(a.scenario.goal.cx != d.scenario.goal.cx || a.scenario.goal.cy != d.scenario.goal.cy ||
                    a.scenario.obstacles.size() != d.scenario.obstacles.size());
    }
}

// ---- Far-goal rooms and the longest path -----------------------------------------------------

std::string far_command(const std::string &robot, world::FarFamily f, double w, double h, std::uint32_t seed)
{
    return "dynaqpc-sim rooms --robot " + robot + " --far " + world::far_family_name(f) + " --floor " +
           world::floor_name(w, h) + " --seed " + std::to_string(seed);
}

world::Room make_far(const std::string &robot, world::FarFamily f, double w, double h, std::uint32_t seed,
                     std::uint32_t index)
{
    world::RoomSpec spec;
    spec.far = true;
    spec.family = f;
    spec.floor_w = w;
    spec.floor_h = h;
    const std::string name = world::room_file_name(robot, spec, w, h, seed, index);
    world::Room room;
    std::string err;
    const bool ok = world::generate_room(base_text(robot), label(robot), far_command(robot, f, w, h, seed), seed,
                                         index, spec, name, &room, &err);
    if (!ok) std::fprintf(stderr, "%s\n", err.c_str());
    assert_true(ok);
    return room;
}

// A corridor worked out by hand, on paper-sim's equal grid (32 x 32 cells of 0.25 m; the shipped
// file fits its cells to the room instead). paper-sim's robot (radius 0.3905 m) in a band from y = 3.48 to
// 4.39 m across the 8 m arena: its centre fits at y 3.8705-3.9995, all in state row 15 (3.75-4.0
// m), and at x 0.3905-7.6095, state columns 1-30: thirty places in a row. The goal circle
// (7.3, 3.93, r 0.3) holds points of columns 28-30. The worst start is column 1 facing north or
// south: one turn, then 27 steps east (facing west, 27 steps backward): 28 actions.
void test_longest_path_corridor(void **state)
{
    (void)state;
    const std::string walls = "obstacle box 4 1.74 8 3.48\nobstacle box 4 6.195 8 3.61\n";
    const std::string equal = "encode x 5 y 5 heading 4 sensor 4";
    const world::Scenario s = with_layout("paper-sim", walls + "goal 7.3 3.93 0.3\n", equal);
    assert_true(world::check_passages(s).ok);
    const world::PathReport r = world::longest_path(s);
    assert_int_equal(r.nx, 32);
    assert_int_equal(r.ny, 32);
    assert_int_equal(r.places, 30);
    assert_int_equal(r.stranded, 0);
    assert_int_equal(r.longest, 28);
    // The start pairs by their actions: column 1 facing north or south needs 28, facing east or
    // west 27 as column 2 facing north or south does; train's learned threshold counts them.
    assert_int_equal(static_cast<long>(r.by_actions.size()), 29);
    long counted = 0;
    for (long k : r.by_actions) counted += k;
    assert_int_equal(counted, r.start_states);
    assert_int_equal(r.beyond(28), 0);
    assert_int_equal(r.beyond(27), 2);
    assert_int_equal(r.beyond(26), 6);
    assert_int_equal(r.beyond(-1), r.start_states);
    // The goal two columns nearer: 26.
    const world::Scenario nearer = with_layout("paper-sim", walls + "goal 6.8 3.93 0.3\n", equal);
    assert_int_equal(world::longest_path(nearer).longest, 26);
    // A wall across the corridor at x = 4 strands the starts west of it.
    const world::Scenario cut = with_layout("paper-sim", walls + "obstacle box 4 3.935 0.1 0.91\ngoal 7.3 3.93 0.3\n", equal);
    const world::PathReport rc = world::longest_path(cut);
    assert_int_equal(rc.longest, -1);
    assert_true(rc.stranded > 0 && rc.stranded < rc.start_states);
}

// The shipped scenarios' longest paths, as docs/scenarios.md quotes them.
void test_longest_path_shipped(void **state)
{
    (void)state;
    const long expect[2] = {14, 18};  // paper-sim on its fitted 18 x 18 cells
    for (int k = 0; k < 2; k++) {
        world::Scenario s;
        std::string err;
        assert_true(world::load_scenario(kRobots[k], &s, &err));
        assert_int_equal(world::longest_path(s).longest, expect[k]);
    }
}

void test_floor_check(void **state)
{
    (void)state;
    world::Scenario sim, lab;
    std::string err;
    assert_true(world::load_scenario("paper-sim", &sim, &err));
    assert_true(world::load_scenario("paper-lab", &lab, &err));
    int xb = 0, yb = 0;
    assert_true(world::floor_check(sim, 16, 4, &xb, &yb, &err));
    assert_int_equal(xb, 6);
    assert_int_equal(yb, 4);
    assert_true(world::floor_check(sim, 16, 16, &xb, &yb, &err));
    assert_int_equal(xb + yb, 12);
    assert_true(world::floor_check(lab, 8.6, 1.6, &xb, &yb, &err));
    assert_int_equal(xb, 4);
    assert_int_equal(yb, 2);
    assert_false(world::floor_check(sim, 10, 8, nullptr, nullptr, &err));
    assert_true(err.find("times 1/4, 1/2, 1, 2 or 4") != std::string::npos);
    assert_false(world::floor_check(lab, 8, 4, nullptr, nullptr, &err));
    assert_false(world::floor_check(sim, 64, 8, nullptr, nullptr, &err));
    assert_false(world::floor_check(sim, 0, 8, nullptr, nullptr, &err));
}

// Every family, on the base's floor and a larger one, has its goal farther than the base
// scenario's own longest path, says so in its text, and keeps the base's other lines.
void test_far_families(void **state)
{
    (void)state;
    struct Floor {
        const char *robot;
        double w, h;
        int x_bits, y_bits;
    } floors[] = {{"paper-lab", 4.3, 3.2, 3, 3}, {"paper-lab", 8.6, 1.6, 4, 2}, {"paper-lab", 8.6, 3.2, 4, 3},
                  {"paper-sim", 8, 8, 5, 5},     {"paper-sim", 16, 4, 6, 4},    {"paper-sim", 4, 16, 4, 6}};
    for (const Floor &f : floors) {
        world::Scenario base;
        std::string err;
        assert_true(world::load_scenario(f.robot, &base, &err));
        const long base_longest = world::longest_path(base).longest;
        std::vector<std::string> kept;  // the base's lines but the floor's
        for (const std::string &l : non_layout_lines(base_text(f.robot))) {
            const std::string k = key_of(l);
            if (k != "arena" && k != "encode" && k != "beacon") kept.push_back(l);
        }
        for (int fam = 0; fam < world::kFarFamilies; fam++) {
            for (std::uint32_t index : {1u, 2u}) {
                const world::Room room = make_far(f.robot, static_cast<world::FarFamily>(fam), f.w, f.h, 7, index);
                if (room.path.longest <= base_longest) {
                    std::fprintf(stderr, "%s %s %gx%g: longest %ld\n", f.robot, room.family.c_str(), f.w, f.h,
                                 room.path.longest);
                }
                assert_true(room.path.longest > base_longest);
                assert_string_equal(room.family.c_str(), world::far_family_name(static_cast<world::FarFamily>(fam)));
                world::Scenario s;
                assert_true(world::parse_scenario(room.text, "again.scn", &s, &err));
                assert_true(world::check_passages(s).ok);
                assert_int_equal(world::longest_path(s).longest, room.path.longest);
                assert_true(room.text.find("\n# longest_path_actions " + std::to_string(room.path.longest) + ":") !=
                            std::string::npos);
                assert_true(s.arena_w == f.w && s.arena_h == f.h);
                if (s.encoding.fitted) {  // the base's `encode auto`: the bits the room's cells need
                    assert_true(s.encoding.x_bits <= f.x_bits && s.encoding.y_bits <= f.y_bits);
                } else {
                    assert_int_equal(s.encoding.x_bits, f.x_bits);
                    assert_int_equal(s.encoding.y_bits, f.y_bits);
                }
                assert_int_equal(s.encoding.heading_bits, base.encoding.heading_bits);
                std::vector<std::string> mine;
                for (const std::string &l : non_layout_lines(room.text)) {
                    const std::string k = key_of(l);
                    if (k != "arena" && k != "encode" && k != "beacon") mine.push_back(l);
                }
                assert_true(mine == kept);
                if (f.w == base.arena_w && f.h == base.arena_h) {
                    assert_true(non_layout_lines(room.text) == non_layout_lines(base_text(f.robot)));
                } else if (!base.cricket.beacons.empty()) {
                    assert_int_equal(s.cricket.beacons.size(), 8);
                }
            }
        }
    }
}

void test_far_same_seed_same_room(void **state)
{
    (void)state;
    const world::Room a = make_far("paper-sim", world::FarFamily::CulDeSac, 16, 4, 5, 3);
    const world::Room b = make_far("paper-sim", world::FarFamily::CulDeSac, 16, 4, 5, 3);
    assert_true(a.text == b.text);
    const world::Room c = make_far("paper-sim", world::FarFamily::CulDeSac, 16, 4, 5, 4);
    assert_true(a.scenario.goal.cx != c.scenario.goal.cx || a.scenario.goal.cy != c.scenario.goal.cy ||
                a.scenario.obstacles.size() != c.scenario.obstacles.size());
    assert_int_equal(static_cast<int>(world::far_family_of_index(1)), static_cast<int>(world::FarFamily::Hall));
    assert_int_equal(static_cast<int>(world::far_family_of_index(4)), static_cast<int>(world::FarFamily::Serpentine));
    assert_int_equal(static_cast<int>(world::far_family_of_index(6)), static_cast<int>(world::FarFamily::Open));
}

// A committed far room: what its name (robot, family, floor, seed, index) generates now.
struct FarName {
    std::string robot, family;
    double w = 0, h = 0;
    unsigned seed = 0, index = 0;
};

FarName check_far_file(const std::filesystem::path &path)
{
    const std::string file = path.filename().string();
    char robot[8] = {0}, family[16] = {0}, tail[8] = {0};
    FarName n;
    assert_int_equal(std::sscanf(file.c_str(), "paper-%3[a-z]-%15[a-z]-%lfx%lf-%u-%u%7s", robot, family, &n.w,
                                 &n.h, &n.seed, &n.index, tail),
                     7);
    assert_string_equal(tail, ".scn");
    n.robot = std::string("paper-") + robot;
    n.family = family;
    world::FarFamily f;
    assert_true(world::far_family_from_name(n.family, &f));
    const world::Room again = make_far(n.robot, f, n.w, n.h, n.seed, n.index);
    const std::string text = read(path.string());
    if (again.text != text) std::fprintf(stderr, "%s differs from what its command generates now\n", file.c_str());
    assert_true(again.text == text);
    world::Scenario s;
    std::string err;
    assert_true(world::load_scenario(path.string(), &s, &err));
    assert_true(world::check_passages(s).ok);
    return n;
}

// far-tune/ and far-eval/: at least 12 rooms per robot, every family in each, a floor larger
// than the base's in each, seeds apart. far-large-tune/ and far-large-eval/ (floors the firmware's
// tables refuse today): what they generate, at least 4 rooms each, seeds apart.
void test_committed_far_rooms(void **state)
{
    (void)state;
    std::map<std::string, std::set<unsigned>> seeds;
    for (const char *set : {"far-tune", "far-eval"}) {
        std::map<std::string, int> per_robot;
        std::map<std::string, std::set<std::string>> families;
        std::map<std::string, int> larger;
        const std::string dir = std::string(WORLD_TEST_ROOMS) + "/" + set;
        assert_true(std::filesystem::is_directory(dir));
        for (const auto &entry : std::filesystem::directory_iterator(dir)) {
            if (entry.path().extension() != ".scn") continue;
            const FarName n = check_far_file(entry.path());
            world::Scenario base;
            std::string err;
            assert_true(world::load_scenario(n.robot, &base, &err));
            per_robot[n.robot]++;
            families[n.robot].insert(n.family);
            larger[n.robot] += n.w * n.h > base.arena_w * base.arena_h + 1e-9 ||
                               std::max(n.w, n.h) > std::max(base.arena_w, base.arena_h) + 1e-9;
            seeds[std::string(set) + "/" + n.robot].insert(n.seed);
        }
        for (const char *robot : kRobots) {
            assert_true(per_robot[robot] >= 12);
            assert_int_equal(families[robot].size(), world::kFarFamilies);
            assert_true(larger[robot] >= 4);
        }
    }
    for (const char *robot : kRobots) {
        for (unsigned s : seeds[std::string("far-tune/") + robot]) {
            assert_int_equal(seeds[std::string("far-eval/") + robot].count(s), 0);
        }
    }
    std::set<unsigned> large_seeds[2];
    for (int k = 0; k < 2; k++) {
        const std::string large = std::string(WORLD_TEST_ROOMS) + (k == 0 ? "/far-large-tune" : "/far-large-eval");
        assert_true(std::filesystem::is_directory(large));
        int n_large = 0;
        for (const auto &entry : std::filesystem::directory_iterator(large)) {
            if (entry.path().extension() != ".scn") continue;
            large_seeds[k].insert(check_far_file(entry.path()).seed);
            n_large++;
        }
        assert_true(n_large >= 4);
    }
    for (unsigned s : large_seeds[0]) assert_int_equal(large_seeds[1].count(s), 0);
}

// The committed sets: at least 10 rooms per robot in each, each accepted, each exactly what its
// name's (robot, seed, index) generates now, and the two sets from different seeds.
void test_committed_rooms(void **state)
{
    (void)state;
    std::map<std::string, std::set<std::uint32_t>> seeds;  // set/robot -> seeds used
    for (const char *set : {"tune", "eval"}) {
        std::map<std::string, int> per_robot;
        const std::string dir = std::string(WORLD_TEST_ROOMS) + "/" + set;
        assert_true(std::filesystem::is_directory(dir));
        for (const auto &entry : std::filesystem::directory_iterator(dir)) {
            const std::string file = entry.path().filename().string();
            if (entry.path().extension() != ".scn") continue;
            char robot[32] = {0};
            unsigned seed = 0, index = 0;
            char tail[8] = {0};
            assert_int_equal(std::sscanf(file.c_str(), "paper-%3[a-z]-%u-%u%7s", robot, &seed, &index, tail), 4);
            assert_string_equal(tail, ".scn");
            const std::string r = std::string("paper-") + robot;
            world::Scenario s;
            std::string err;
            const bool ok = world::load_scenario(entry.path().string(), &s, &err);
            if (!ok) std::fprintf(stderr, "%s\n", err.c_str());
            assert_true(ok);
            assert_true(world::check_passages(s).ok);
            const world::Room again = make(r, seed, index);
            if (again.text != read(entry.path().string())) {
                std::fprintf(stderr, "%s/%s differs from what its command generates now\n", set, file.c_str());
            }
            assert_true(again.text == read(entry.path().string()));
            per_robot[r]++;
            seeds[std::string(set) + "/" + r].insert(seed);
        }
        for (const char *robot : kRobots) assert_true(per_robot[robot] >= 10);
    }
    for (const char *robot : kRobots) {
        for (std::uint32_t s : seeds[std::string("tune/") + robot]) {
            assert_int_equal(seeds[std::string("eval/") + robot].count(s), 0);
        }
    }
}

// Rooms like users' rooms (world/user_rooms.h): every family for both robots parses again from its
// text, passes the passage check, reaches the goal on its fitted grid (encode auto), keeps the
// base's robot, and is the same text for the same seed and index.
world::Room make_user(const std::string &robot, world::UserFamily f, std::uint32_t seed, std::uint32_t index,
                      world::UserGoal goal = world::UserGoal::Base)
{
    const std::string name = robot + "-" + world::user_family_name(f) + "-" + std::to_string(seed) + ".scn";
    world::Room room;
    std::string err;
    const bool ok = world::generate_user_room(base_text(robot), label(robot), command(robot, seed), seed, index, f,
                                              goal, name, &room, &err);
    if (!ok) std::fprintf(stderr, "%s\n", err.c_str());
    assert_true(ok);
    return room;
}

void test_user_rooms(void **state)
{
    (void)state;
    for (const char *robot : kRobots) {
        world::Scenario base;
        std::string err;
        assert_true(world::load_scenario(robot, &base, &err));
        for (int f = 0; f < world::kUserFamilies; f++) {
            const auto family = static_cast<world::UserFamily>(f);
            for (std::uint32_t index = 1; index <= 2; index++) {
                const world::Room room = make_user(robot, family, 5, index);
                world::Scenario s;
                assert_true(world::parse_scenario(room.text, "again.scn", &s, &err));
                assert_true(s.encoding.fitted);
                assert_true(world::check_passages(s).ok);
                assert_true(world::longest_path(s).longest > 0);
                assert_true(s.robot.length == base.robot.length && s.code_bits.size() == base.code_bits.size());
                assert_true(!s.obstacles.empty());
                assert_true(room.text == make_user(robot, family, 5, index).text);
                assert_true(room.text != make_user(robot, family, 6, index).text);
            }
        }
        world::UserFamily f{};
        assert_true(world::user_family_from_name("s-floor", &f) && f == world::UserFamily::SFloor);
        assert_false(world::user_family_from_name("s_floor", &f));
        assert_true(world::user_family_of_index(1) == world::UserFamily::Partitions);
        assert_true(world::user_family_of_index(6) == world::UserFamily::Partitions);
    }
}

// --goal circle (UserGoal::Circle): every family for both robots draws a plain circle, not the
// base's `cells`, of radius 0.4 to 1 robot diagonals, that some stop of the robot reaches (the file
// parses: encode auto refuses a goal no step ends in); the base's rooms keep the base's goal line.
void test_user_rooms_circle_goal(void **state)
{
    (void)state;
    for (const char *robot : kRobots) {
        world::Scenario base;
        std::string err;
        assert_true(world::load_scenario(robot, &base, &err));
        const double d = 2.0 * world::robot_radius(base.robot);
        for (int f = 0; f < world::kUserFamilies; f++) {
            const auto family = static_cast<world::UserFamily>(f);
            const world::Room room = make_user(robot, family, 31, 1, world::UserGoal::Circle);
            world::Scenario s;
            assert_true(world::parse_scenario(room.text, "again.scn", &s, &err));
            assert_false(s.goal.cells);
            assert_true(s.goal.radius >= world::kUserGoalRadius[0] * d - 0.005);
            assert_true(s.goal.radius <= world::kUserGoalRadius[1] * d + 0.005);
            assert_true(world::check_passages(s).ok);
            const world::Room as_base = make_user(robot, family, 31, 1);
            assert_true(world::parse_scenario(as_base.text, "base.scn", &s, &err));
            assert_true(s.goal.cells == base.goal.cells && s.goal.radius == base.goal.radius);
        }
    }
    world::UserGoal g{};
    assert_true(world::user_goal_from_name("circle", &g) && g == world::UserGoal::Circle);
    assert_true(world::user_goal_from_name("base", &g) && g == world::UserGoal::Base);
    assert_false(world::user_goal_from_name("cells", &g));
}

// The committed rooms like users' rooms: at least 12 per robot in each of users-tune and
// users-eval (the base's goal), users-circle-tune and users-circle-eval (--goal circle) and
// users-circle-walls-tune and -eval (along-walls, --goal circle), each what its command generates
// now, each tuning set on other seeds than its evaluation set.
void test_committed_user_rooms(void **state)
{
    (void)state;
    std::map<std::string, std::set<std::uint32_t>> seeds;
    for (const char *set : {"users-tune", "users-eval", "users-circle-tune", "users-circle-eval",
                            "users-circle-walls-tune", "users-circle-walls-eval"}) {
        std::map<std::string, int> per_robot;
        const std::string dir = std::string(WORLD_TEST_ROOMS) + "/" + set;
        assert_true(std::filesystem::is_directory(dir));
        for (const auto &entry : std::filesystem::directory_iterator(dir)) {
            if (entry.path().extension() != ".scn") continue;
            const std::string file = entry.path().filename().string();
            // paper-<robot>-<family>-<seed>-<index>.scn, the family itself may hold dashes
            const std::string stem = file.substr(0, file.size() - 4);
            const std::size_t i2 = stem.rfind('-'), i1 = stem.rfind('-', i2 - 1);
            const std::uint32_t index = static_cast<std::uint32_t>(std::stoul(stem.substr(i2 + 1)));
            const std::uint32_t seed = static_cast<std::uint32_t>(std::stoul(stem.substr(i1 + 1, i2 - i1 - 1)));
            const std::string r = stem.substr(0, 9);  // paper-lab, paper-sim
            std::string fam = stem.substr(10, i1 - 10);
            const bool circle = fam.rfind("circle-", 0) == 0;  // paper-<robot>-circle-<family>-...
            if (circle) fam = fam.substr(7);
            assert_true(circle == (std::string(set).find("circle") != std::string::npos));
            world::UserFamily f{};
            assert_true(world::user_family_from_name(fam, &f));
            world::Room room;
            std::string err;
            const std::string cmd = "dynaqpc-sim rooms --robot " + r + " --users " + fam +
                                    (circle ? " --goal circle" : "") + " --seed " + std::to_string(seed);
            assert_true(world::generate_user_room(base_text(r), label(r), cmd, seed, index, f,
                                                  circle ? world::UserGoal::Circle : world::UserGoal::Base, file, &room,
                                                  &err));
            if (room.text != read(entry.path().string())) {
                std::fprintf(stderr, "%s/%s differs from what its command generates now\n", set, file.c_str());
            }
            assert_true(room.text == read(entry.path().string()));
            per_robot[r]++;
            seeds[std::string(set) + "/" + r].insert(seed);
        }
        for (const char *robot : kRobots) assert_true(per_robot[robot] >= 12);
    }
    for (const char *robot : kRobots) {
        for (const char *kind : {"users", "users-circle", "users-circle-walls"}) {
            for (std::uint32_t s : seeds[std::string(kind) + "-tune/" + robot]) {
                assert_int_equal(seeds[std::string(kind) + "-eval/" + robot].count(s), 0);
            }
        }
    }
}

}  // namespace

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shipped_scenarios_pass),
        cmocka_unit_test(test_narrow_door_refused),
        cmocka_unit_test(test_unreachable_goal_refused),
        cmocka_unit_test(test_stop_walk),
        cmocka_unit_test(test_tight_slot),
        cmocka_unit_test(test_walk_refit_needs_a_stop),
        cmocka_unit_test(test_generated_rooms),
        cmocka_unit_test(test_user_rooms),
        cmocka_unit_test(test_user_rooms_circle_goal),
        cmocka_unit_test(test_committed_user_rooms),
        cmocka_unit_test(test_same_seed_same_room),
        cmocka_unit_test(test_committed_rooms),
        cmocka_unit_test(test_longest_path_corridor),
        cmocka_unit_test(test_longest_path_shipped),
        cmocka_unit_test(test_floor_check),
        cmocka_unit_test(test_far_families),
        cmocka_unit_test(test_far_same_seed_same_room),
        cmocka_unit_test(test_committed_far_rooms),
    };
    return cmocka_run_group_tests_name("world_rooms", tests, nullptr, nullptr);
}
