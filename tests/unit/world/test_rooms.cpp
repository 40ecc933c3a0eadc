// SPDX-License-Identifier: MIT
// Tests of the room generator and the passage check (world/rooms.h), and of the rooms committed
// under host_sim/rooms/: each parses, passes, and is what its documented command generates.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

// cmocka 1.1.5's header has no extern "C" of its own.
extern "C" {
#include "test_common.h"
}
#include "world/rooms.h"
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
world::Scenario with_layout(const std::string &robot, const std::string &layout)
{
    std::string text;
    for (const std::string &l : non_layout_lines(base_text(robot))) text += l + "\n";
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

}  // namespace

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shipped_scenarios_pass),
        cmocka_unit_test(test_narrow_door_refused),
        cmocka_unit_test(test_unreachable_goal_refused),
        cmocka_unit_test(test_generated_rooms),
        cmocka_unit_test(test_same_seed_same_room),
        cmocka_unit_test(test_committed_rooms),
    };
    return cmocka_run_group_tests_name("world_rooms", tests, nullptr, nullptr);
}
