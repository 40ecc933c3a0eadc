// SPDX-License-Identifier: MIT
// Tests of the scenario files: the shipped ones, every kind of refusal, and garbage.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

// cmocka 1.1.5's header has no extern "C" of its own.
extern "C" {
#include "test_common.h"
}
#include "world/grid_fit.h"
#include "world/random.h"
#include "world/scenario.h"

#ifndef WORLD_TEST_DOCS
#define WORLD_TEST_DOCS "docs/scenarios.md"
#endif
#ifndef WORLD_TEST_SCENARIOS
#define WORLD_TEST_SCENARIOS "tests/unit/world/scenarios"
#endif

int run_scenario_tests(void);

namespace {

bool starts_with(const std::string &s, const std::string &prefix)
{
    return s.compare(0, prefix.size(), prefix) == 0;
}

void test_paper_sim_parses(void **state)
{
    (void)state;
    world::Scenario s;
    std::string err;
    bool ok = world::load_scenario("paper-sim", &s, &err);
    if (!ok) std::fprintf(stderr, "%s\n", err.c_str());
    assert_true(ok);
    assert_string_equal(s.name.c_str(), "paper-sim");
    assert_true(s.arena_w == 8.0 && s.arena_h == 8.0);
    assert_true(s.goal.cx == 4.0 && s.goal.cy == 4.0);
    assert_int_equal(s.ranger.rays.size(), 16);
    assert_true(s.ranger.kind == world::RangerSpec::Kind::Sonar);
    assert_true(s.ranger.min_range == 0.01 && s.ranger.max_range == 2.0);
    assert_int_equal(s.code_bits.size(), 4);
    for (const world::CodeBit &b : s.code_bits) assert_int_equal(b.rays.size(), 4);
    assert_int_equal(s.encoding.x_bits, 5);
    assert_int_equal(s.encoding.y_bits, 5);
    assert_int_equal(s.encoding.heading_bits, 4);
    assert_int_equal(s.encoding.sensor_bits, 4);
    assert_true(s.gps.enabled);
    assert_true(s.cricket.beacons.empty());
    assert_int_equal(s.timing.substeps, 12);
    assert_true(s.learning.epsilon == 0.01 && s.learning.alpha == 0.9 &&
                s.learning.gamma == world::Learning::kGammaFromRoom);
    assert_int_equal(s.learning.planning, 0);  // idle-time planning, as shipped
    assert_int_equal(s.learning.step_cap, 5000);
    assert_int_equal(s.learning.sets, 40);
    assert_int_equal(s.learning.episodes, 200);
    assert_true(s.rewards.bump == -100.0 && s.rewards.goal == 100.0 && s.rewards.step == -1.0);
    // Default mount points lie on the body's outline.
    for (const world::Ray &r : s.ranger.rays) {
        bool on_x = std::abs(std::abs(r.x) - 0.30) < 1e-9 && std::abs(r.y) <= 0.25 + 1e-9;
        bool on_y = std::abs(std::abs(r.y) - 0.25) < 1e-9 && std::abs(r.x) <= 0.30 + 1e-9;
        assert_true(on_x || on_y);
    }
}

void test_paper_lab_parses(void **state)
{
    (void)state;
    world::Scenario s;
    std::string err;
    bool ok = world::load_scenario("paper-lab", &s, &err);
    if (!ok) std::fprintf(stderr, "%s\n", err.c_str());
    assert_true(ok);
    assert_true(s.arena_w == 4.3 && s.arena_h == 3.2);
    assert_int_equal(s.ranger.rays.size(), 3);
    assert_true(s.ranger.kind == world::RangerSpec::Kind::Ir);
    assert_int_equal(s.code_bits.size(), 3);
    assert_true(s.code_bits[0].threshold == 0.30);
    assert_int_equal(s.encoding.x_bits, 3);
    assert_int_equal(s.encoding.y_bits, 3);
    assert_int_equal(s.encoding.heading_bits, 4);
    assert_int_equal(s.encoding.sensor_bits, 3);
    assert_false(s.gps.enabled);
    assert_true(s.cricket.beacons.size() >= 4 && s.cricket.beacons.size() <= 6);
    for (const world::Beacon &b : s.cricket.beacons) assert_true(b.z == 2.5);
    assert_true(std::abs(s.cricket.min_interval - 0.668) < 1e-12);
    assert_true(std::abs(s.cricket.max_interval - 1.332) < 1e-12);
    assert_true(s.learning.epsilon == 0.1);
    assert_int_equal(s.learning.step_cap, 200);
    assert_int_equal(s.learning.sets, 5);
    assert_int_equal(s.learning.episodes, 20);
    assert_true(s.goal.cells);
}

// `goal ... cells`: the goal is the cells of the state grid whose centres are in the circle. In
// a 4 x 4 m arena with 2 x 2 bits (1 m cells), a 0.6 m circle at (2.5, 2.5) holds one centre.
// `learning gamma auto` (and no gamma at all) leave the discount to the firmware; a number is
// the paper's mode; anything else is refused with the line.
void test_gamma_auto(void **state)
{
    (void)state;
    const std::string head = "arena 4 4\nrobot length 0.3 width 0.2 track 0.18\n"
                             "ranger kind ir min 0.1 max 0.8\nray 0\nencode x 2 y 2 heading 2\ngoal 2.5 2.5 0.6\n";
    world::Scenario s;
    std::string err;
    assert_true(world::parse_scenario(head, "g.scn", &s, &err));
    assert_true(s.learning.gamma == world::Learning::kGammaFromRoom);
    assert_true(world::parse_scenario(head + "learning gamma auto\n", "g.scn", &s, &err));
    assert_true(s.learning.gamma == world::Learning::kGammaFromRoom);
    assert_true(world::parse_scenario(head + "learning gamma 0.95 epsilon 0.2\n", "g.scn", &s, &err));
    assert_true(s.learning.gamma == 0.95 && s.learning.epsilon == 0.2);
    assert_false(world::parse_scenario(head + "learning gamma 1.5\n", "g.scn", &s, &err));
    assert_non_null(std::strstr(err.c_str(), "g.scn:7"));
    assert_false(world::parse_scenario(head + "learning gamma autoo\n", "g.scn", &s, &err));
    assert_non_null(std::strstr(err.c_str(), "gamma"));
}

// A code bit whose threshold no reading crosses never changes: readings lie in [min, max], so a
// threshold above max is always set and one at or below min never; max itself (a hit read below
// it) and anything just above min change. rooms --check and train warn of such a bit, its line
// and the ranger's range (a new user's 5 ToF rays of 0.04-0.30 m with `code_bit 0.40 0`).
void test_constant_code_bits(void **state)
{
    (void)state;
    const std::string head = "arena 4 4\nrobot length 0.3 width 0.2 track 0.18\n"
                             "ranger kind ir min 0.04 max 0.30\nray 0\nray 45\nencode x 2 y 2 heading 2\n"
                             "goal 2.5 2.5 0.6\n";
    world::Scenario s;
    std::string err;
    assert_true(world::parse_scenario(head + "code_bit 0.30 0\ncode_bit 0.041 1\n", "b.scn", &s, &err));
    assert_true(world::constant_code_bits(s).empty());
    assert_true(world::parse_scenario(head + "code_bit 0.40 0\ncode_bit 0.2 0 1\ncode_bit 0.04 1\n"
                                             "code_bit 0.03 0\n",
                                      "b.scn", &s, &err));
    const std::vector<world::ConstantCodeBit> c = world::constant_code_bits(s);
    assert_int_equal(c.size(), 3);
    assert_int_equal(c[0].bit, 0);
    assert_int_equal(c[0].line, 8);
    assert_true(c[0].always);
    assert_int_equal(c[1].bit, 2);
    assert_int_equal(c[1].line, 10);
    assert_false(c[1].always);
    assert_int_equal(c[2].line, 11);
    assert_string_equal(world::constant_code_bit_warning(s, c[0]).c_str(),
                        "code_bit 0.4 (bit 0) is always set: its rays read 0.04 to 0.3 m (the ranger's min and "
                        "max), all below 0.4, so it tells the robot nothing; give a threshold above 0.04 and up to "
                        "0.3 m");
    assert_non_null(std::strstr(world::constant_code_bit_warning(s, c[2]).c_str(), "code_bit 0.03 (bit 3) is never set"));
}

// `encode auto`: the cells fitted to the room (world/grid_fit.h). A 4 x 2 m floor with a 0.1 m
// partition at x 1.95-2.05 (y 0-1.4: a 0.6 m doorway above it) and 0.5 m steps: along x a cut at
// each face of the partition, the partition its own thin cell, the gaps on either side cut into
// the nearest whole number of cells of 1 m (twice the step); along y a cut at the doorway's jamb. Cells and goal
// cells follow the fit; a room that needs more than 32 cells is refused with the count.
void test_encode_auto(void **state)
{
    (void)state;
    const std::string head = "arena 4 2\nrobot length 0.3 width 0.2 track 0.18\n"
                             "ranger kind ir min 0.1 max 0.8\nray 0\ngoal 3.5 1.7 0.3 cells\n"
                             "actions step 0.5 turn_deg 90 aligned 1 past 0.2\n"
                             "obstacle box 2.0 0.7 0.1 1.4\n";
    world::Scenario s;
    std::string err;
    assert_true(world::parse_scenario(head + "encode auto heading 2\n", "a.scn", &s, &err));
    assert_true(s.encoding.fitted);
    const std::vector<double> &x = s.encoding.x_edges, &y = s.encoding.y_edges;
    assert_int_equal(x.size(), 6u);  // 0, 0.975, 1.95, 2.05, 3.025, 4
    assert_true(std::fabs(x[0]) < 1e-12 && std::fabs(x[2] - 1.95) < 1e-9 && std::fabs(x[3] - 2.05) < 1e-9);
    assert_true(std::fabs(x[1] - 0.975) < 1e-9 && std::fabs(x.back() - 4.0) < 1e-12);
    assert_int_equal(y.size(), 3u);  // 0, 1.4, 2
    assert_true(std::fabs(y[1] - 1.4) < 1e-9);
    assert_int_equal(s.encoding.x_bits, 3);  // 5 cells
    assert_int_equal(s.encoding.y_bits, 1);
    assert_int_equal(world::grid_cells(s, 0), 5);
    assert_int_equal(world::grid_cell(s, 0, 2.0), 2);  // inside the partition's own cell
    assert_int_equal(world::grid_cell(s, 0, 3.9), 4);
    assert_int_equal(world::grid_cell(s, 0, -1.0), 0);
    assert_int_equal(world::grid_cell(s, 1, 1.5), 1);
    // The goal cell: x [3.025, 4], y [1.4, 2], centre (3.51, 1.7) inside the 0.3 m circle at (3.5, 1.7).
    assert_true(world::in_goal(s, 3.1, 1.45));
    assert_false(world::in_goal(s, 2.9, 1.45));
    // A largest cell side given: 0.5 m cells.
    assert_true(world::parse_scenario(head + "encode auto cell 0.5\n", "a.scn", &s, &err));
    assert_int_equal(world::grid_cells(s, 0), 9);  // 4 + the partition + 4
    // Heading bits: as given, else 4; with fixed turns that divide the circle into a power of two,
    // one sector a heading they reach (45 degrees: 8, 3 bits); 16 when given.
    assert_int_equal(s.encoding.heading_bits, 4);
    std::string fixed = head;
    fixed.replace(fixed.find("turn_deg 90 aligned 1 past 0.2"), std::strlen("turn_deg 90 aligned 1 past 0.2"),
                  "turn_deg 45 aligned 0");
    assert_true(world::parse_scenario(fixed + "encode auto\n", "a.scn", &s, &err));
    assert_int_equal(s.encoding.heading_bits, 3);
    assert_true(world::parse_scenario(fixed + "encode auto heading 4\n", "a.scn", &s, &err));
    assert_int_equal(s.encoding.heading_bits, 4);
    fixed.replace(fixed.find("turn_deg 45"), std::strlen("turn_deg 45"), "turn_deg 60");  // 6 headings: not a power of two
    assert_true(world::parse_scenario(fixed + "encode auto\n", "a.scn", &s, &err));
    assert_int_equal(s.encoding.heading_bits, 4);
    // A goal no fitted cell centre reaches gets a cell centred on it (its square cuts too).
    std::string off = head;
    off.replace(off.find("goal 3.5 1.7 0.3 cells"), std::strlen("goal 3.5 1.7 0.3 cells"), "goal 2.6 0.4 0.25 cells");
    assert_true(world::parse_scenario(off + "encode auto\n", "a.scn", &s, &err));
    assert_true(world::in_goal(s, 2.6, 0.4));
    assert_int_equal(world::goal_cells(s).size(), 1u);
    // Where aligned steps stop (`actions stop`): auto gives the cell's centre on a fitted grid
    // whose cells the robot turns inside (0.36 m across its corners, 1 m cells), else `past`.
    assert_true(world::parse_scenario(head + "encode auto\n", "a.scn", &s, &err));
    assert_true(s.actions.centred);
    assert_true(world::parse_scenario(head + "encode x 2 y 1 heading 2\n", "a.scn", &s, &err));
    assert_false(s.actions.centred);  // an equal grid
    assert_true(world::parse_scenario(head + "encode auto cell 0.3\n", "a.scn", &s, &err));
    assert_false(s.actions.centred);  // cells narrower than the robot's turn
    // The cell side follows the robot that turns inside it: twice the step, widened to the
    // diagonal + 2 x 0.08 m; a robot too large to turn inside twice its step keeps that side.
    auto side_for = [&](const char *robot, double step) {
        std::string r = head;
        r.replace(r.find("robot length 0.3 width 0.2"), std::strlen("robot length 0.3 width 0.2"), robot);
        r.replace(r.find("step 0.5 turn_deg 90 aligned 1 past 0.2"),
                  std::strlen("step 0.5 turn_deg 90 aligned 1 past 0.2"),
                  "step " + std::to_string(step) + " turn_deg 90 aligned 1 past 0.1");
        assert_true(world::parse_scenario(r + "encode auto\n", "a.scn", &s, &err));
        return world::fit_cell_side(s);
    };
    assert_true(std::fabs(side_for("robot length 0.25 width 0.2", 0.25) - 0.5) < 1e-12);  // the lab robot
    assert_true(s.actions.centred);
    assert_true(std::fabs(side_for("robot length 0.34 width 0.28", 0.25) - (std::hypot(0.34, 0.28) + 0.16)) < 1e-12);
    assert_true(s.actions.centred);
    assert_true(std::fabs(side_for("robot length 0.6 width 0.5", 0.25) - 0.5) < 1e-12);  // the sonar robot
    assert_false(s.actions.centred);
    std::string stop = head;
    stop.replace(stop.find("past 0.2"), std::strlen("past 0.2"), "past 0.2 stop past");
    assert_true(world::parse_scenario(stop + "encode auto\n", "a.scn", &s, &err));
    assert_false(s.actions.centred);
    stop.replace(stop.find("stop past"), std::strlen("stop past"), "stop centre");
    assert_true(world::parse_scenario(stop + "encode x 2 y 1 heading 2\n", "a.scn", &s, &err));
    assert_true(s.actions.centred);
    stop.replace(stop.find("stop centre"), std::strlen("stop centre"), "stop middle");
    assert_false(world::parse_scenario(stop + "encode auto\n", "a.scn", &s, &err));
    assert_non_null(std::strstr(err.c_str(), "actions stop 'middle': unknown (auto, past, centre)"));
    std::string fixed_centre = fixed;
    fixed_centre.replace(fixed_centre.find("aligned 0"), std::strlen("aligned 0"), "aligned 0 stop centre");
    assert_false(world::parse_scenario(fixed_centre + "encode auto\n", "a.scn", &s, &err));
    assert_non_null(std::strstr(err.c_str(), "needs aligned 1"));
    // Refused: bits with auto, past not inside a cell, more than 32 cells.
    assert_false(world::parse_scenario(head + "encode auto x 3\n", "a.scn", &s, &err));
    assert_non_null(std::strstr(err.c_str(), "unknown field 'x'"));
    assert_false(world::parse_scenario(head + "encode auto cell 0.1\n", "a.scn", &s, &err));
    assert_non_null(std::strstr(err.c_str(), "past"));
    std::string longer = head;
    longer.replace(0, std::strlen("arena 4 2"), "arena 8 2");  // 9 + 1 + 28 cells of about 0.21 m along x
    assert_false(world::parse_scenario(longer + "encode auto cell 0.21\n", "a.scn", &s, &err));
    assert_non_null(std::strstr(err.c_str(), "needs 38 cells"));
    assert_non_null(std::strstr(err.c_str(), "cells along x"));
}

// encode auto and `past`: the firmware steps over a fitted cell narrower than `past` and cannot
// stop `past` inside one exactly that wide, so neither may hold the whole goal or be a cell.
void test_encode_auto_past(void **state)
{
    (void)state;
    const std::string head = "arena 4 2\nrobot length 0.25 width 0.2 track 0.18\n"
                             "ranger kind ir min 0.1 max 0.8\nray 0\n"
                             "actions step 0.25 turn_deg 90 aligned 1 past 0.2\nencode auto heading 2\n";
    world::Scenario s;
    std::string err;
    // A box exactly `past` wide against the wall: no cell is `past` wide (in single precision).
    assert_true(world::parse_scenario(head + "goal 3.5 1.5 0.3 cells\nobstacle box 0.1 1.0 0.2 0.4\n", "a.scn",
                                      &s, &err));
    const std::vector<double> &x = s.encoding.x_edges;
    for (std::size_t k = 0; k + 1 < x.size(); k++) {
        assert_true(static_cast<float>(x[k + 1]) - static_cast<float>(x[k]) != 0.2f);
    }
    assert_true(std::fabs(x[1] - 0.2) > 1e-9);
    // A goal above the end of a thin wall, whose only cell centred in it is the wall's 0.1 m
    // column: a cell centred on the goal is cut instead, wide enough to stop in.
    const std::string wall = "obstacle box 2.0 0.7 0.1 1.4\n";
    assert_true(world::parse_scenario(head + wall + "goal 2.0 1.7 0.3 cells\n", "a.scn", &s, &err));
    bool stop = false;
    for (const world::CellBox &c : world::goal_cells(s)) {
        stop = stop || (c.x1 - c.x0 > 0.2 && c.y1 - c.y0 > 0.2);
    }
    assert_true(stop);
    // The same with a goal too small to hold a cell a step can end in: refused, saying why (here
    // the goal's own square merges with the wall's faces, and no cell centre is left in it).
    assert_false(world::parse_scenario(head + wall + "goal 2.0 1.7 0.06 cells\n", "a.scn", &s, &err));
    assert_non_null(std::strstr(err.c_str(), "goal ... cells: "));
    // A goal on the wall's face whose own square cuts where the wall's faces do: its only cell
    // is still the wall's column, and the file says so.
    assert_false(world::parse_scenario(head + wall + "goal 1.95 1.6 0.07 cells\n", "a.scn", &s, &err));
    assert_non_null(std::strstr(err.c_str(), "narrower than 'past' (0.2 m)"));
}

// Whether the grid's edges `e` hold a cut at `v` (m).
static bool has_edge(const std::vector<double> &e, double v)
{
    for (double x : e) {
        if (std::fabs(x - v) < 1e-9) return true;
    }
    return false;
}

// encode auto's rule 5: a bin in the middle of a 1 m aisle sits where the aisle's two equal
// cells meet, its edge 1 cm beyond the lab robot's turn from the centred stops around it; the
// aisle's cut moves onto the bin's face, keeping its two cells, each wider than a turn. A turned
// box, or stops `past` the edge, leave the grid as rules 1-4 cut it.
void test_encode_auto_pinch(void **state)
{
    (void)state;
    const std::string head = "arena 5.5 3\nrobot length 0.25 width 0.2 track 0.18\n"
                             "ranger kind ir min 0.1 max 0.8\nray 0\nencode auto heading 2\n"
                             "obstacle box 1.4 1.1 0.4 2.2\nobstacle box 2.8 1.9 0.4 2.2\ngoal 5 0.5 0.3 cells\n";
    const std::string centre = "actions step 0.25 turn_deg 90 aligned 1 past 0.16\n";
    const std::string bin = "obstacle circle 2.1 2.6 0.15\n";
    world::Scenario s;
    std::string err;
    assert_true(world::parse_scenario(head + centre, "a.scn", &s, &err));
    const std::vector<double> plain_x = s.encoding.x_edges, plain_y = s.encoding.y_edges;
    assert_true(has_edge(plain_x, 1.6) && has_edge(plain_x, 2.1) && has_edge(plain_x, 2.6));  // the aisle in two
    assert_true(world::parse_scenario(head + centre + bin, "a.scn", &s, &err));
    assert_true(s.actions.centred);
    const std::vector<double> &x = s.encoding.x_edges;
    assert_int_equal(x.size(), plain_x.size());
    assert_true(has_edge(x, 1.6) && has_edge(x, 1.95) && has_edge(x, 2.6) && !has_edge(x, 2.1));
    assert_true(s.encoding.y_edges == plain_y);  // 2.45 or 2.75 would leave a row under 0.32 m
    // Every cell of the aisle is as wide as the robot's turn.
    const double turn = std::hypot(0.25, 0.2) / 2.0;
    for (std::size_t i = 0; i + 1 < x.size(); i++) {
        if (x[i + 1] > 1.6 && x[i] < 2.6) assert_true(x[i + 1] - x[i] >= 2.0 * turn);
    }
    // A turned box where the bin was, or `past` stops: rules 1-4's grid.
    assert_true(world::parse_scenario(head + centre + "obstacle box 2.1 2.6 0.2 0.2 45\n", "a.scn", &s, &err));
    assert_true(s.encoding.x_edges == plain_x);
    std::string past = centre;
    past.replace(past.find("past 0.16"), std::strlen("past 0.16"), "past 0.16 stop past");
    assert_true(world::parse_scenario(head + past, "a.scn", &s, &err));
    const std::vector<double> past_x = s.encoding.x_edges;
    assert_true(world::parse_scenario(head + past + bin, "a.scn", &s, &err));
    assert_false(s.actions.centred);
    assert_true(s.encoding.x_edges == past_x);
}

// A plain goal circle (no `cells`) and steps that stop at cell centres: the episode ends only
// when a step ends in the circle, so the fit cuts the goal's square when no stop lies in it (a
// dining room drawn by hand learned 0 of 20 sets before, 20 of 20 after). Stops `past` an edge
// land anywhere across the step, and keep rules 1-4's grid.
void test_encode_auto_plain_goal(void **state)
{
    (void)state;
    const std::string head = "arena 3.6 3.6\nrobot length 0.25 width 0.2 track 0.18\n"
                             "ranger kind ir min 0.1 max 0.8\nray 0\nencode auto heading 2\n"
                             "obstacle box 1.8 1.8 1.2 0.8\nobstacle box 0.2 1.8 0.4 1.4\n";
    const std::string centre = "actions step 0.25 turn_deg 90 aligned 1 past 0.16\n";
    const std::string past = "actions step 0.25 turn_deg 90 aligned 1 past 0.16 stop past\n";
    world::Scenario s;
    std::string err;
    // With `cells` the goal square is cut already: the plain goal must get the same grid.
    assert_true(world::parse_scenario(head + centre + "goal 1.8 0.35 0.25 cells\n", "g.scn", &s, &err));
    const std::vector<double> cells_x = s.encoding.x_edges, cells_y = s.encoding.y_edges;
    assert_true(world::parse_scenario(head + centre + "goal 1.8 0.35 0.25\n", "g.scn", &s, &err));
    assert_true(s.actions.centred);
    assert_true(s.encoding.x_edges == cells_x && s.encoding.y_edges == cells_y);
    assert_false(world::goal_cells(s).empty());
    // Stops past the edge: no cut at the goal's square, and no cell centre in the circle.
    assert_true(world::parse_scenario(head + past + "goal 1.8 0.35 0.25\n", "g.scn", &s, &err));
    assert_false(s.actions.centred);
    assert_true(world::goal_cells(s).empty());
    // A goal too small for a cell of its own (0.14 m, under `past`) is refused with its line, as
    // is a centred robot's goal between the centres of an equal grid; `stop past` reaches both.
    assert_false(world::parse_scenario(head + centre + "goal 1.8 1.3 0.07\n", "g.scn", &s, &err));
    assert_non_null(std::strstr(err.c_str(), "g.scn:9: goal: no step ends in the circle"));
    assert_true(world::parse_scenario(head + past + "goal 1.8 1.3 0.07\n", "g.scn", &s, &err));
    std::string equal = head;
    equal.replace(equal.find("encode auto heading 2"), std::strlen("encode auto heading 2"), "encode x 3 y 3 heading 2");
    const std::string centre_stop = "actions step 0.25 turn_deg 90 aligned 1 past 0.16 stop centre\n";
    assert_false(world::parse_scenario(equal + centre_stop + "goal 1.8 0.35 0.25\n", "g.scn", &s, &err));
    assert_non_null(std::strstr(err.c_str(), "goal: no step ends in the circle"));
    assert_true(world::parse_scenario(equal + centre_stop + "goal 2.025 0.675 0.25\n", "g.scn", &s, &err));
}

// The goal's square cut leaves no sliver a turn cannot clear: a goal 0.2 m from two walls gets a
// cell reaching to them, not a 0.2 m row and column beside them (a hand-drawn zig-zag room relapsed
// in 51 of 272 episodes with them, 3 of 273 without); a goal in the open keeps all four faces.
void test_encode_auto_goal_sliver(void **state)
{
    (void)state;
    const std::string head = "arena 5 3\nrobot length 0.25 width 0.2 track 0.18\n"
                             "ranger kind ir min 0.1 max 0.8\nray 0\nencode auto heading 2\n"
                             "actions step 0.25 turn_deg 90 aligned 1 past 0.16\n";
    world::Scenario s;
    std::string err;
    const double turn = std::hypot(0.25, 0.2);
    assert_true(world::parse_scenario(head + "goal 4.5 0.5 0.3\n", "z.scn", &s, &err));
    for (const std::vector<double> *e : {&s.encoding.x_edges, &s.encoding.y_edges}) {
        assert_true((*e)[1] >= turn && e->back() - (*e)[e->size() - 2] >= turn);
    }
    assert_false(world::goal_cells(s).empty());
    assert_true(world::parse_scenario(head + "goal 2.5 1.5 0.3\n", "z.scn", &s, &err));
    assert_true(has_edge(s.encoding.x_edges, 2.2) && has_edge(s.encoding.x_edges, 2.8));
    assert_true(has_edge(s.encoding.y_edges, 1.2) && has_edge(s.encoding.y_edges, 1.8));
}

// `learning model paper tiles 1,1,0,0`: Dyna-QPC's model and the paper's model's tile widths; an
// unknown model or malformed widths are refused with the line.
void test_learning_model(void **state)
{
    (void)state;
    const std::string head = "arena 4 4\nrobot length 0.3 width 0.2 track 0.18\n"
                             "ranger kind ir min 0.1 max 0.8\nray 0\nencode x 2 y 2 heading 2\ngoal 2.5 2.5 0.6\n";
    world::Scenario s;
    std::string err;
    assert_true(world::parse_scenario(head, "m.scn", &s, &err));
    assert_true(s.learning.model == "relocatable" && s.learning.model_tiles.empty());
    assert_true(world::parse_scenario(head + "learning model paper tiles 1,0,2,0\n", "m.scn", &s, &err));
    assert_true(s.learning.model == "paper");
    assert_true(s.learning.model_tiles == std::vector<int>({1, 0, 2, 0}));
    assert_false(world::parse_scenario(head + "learning model cmac\n", "m.scn", &s, &err));
    assert_non_null(std::strstr(err.c_str(), "m.scn:7"));
    assert_non_null(std::strstr(err.c_str(), "unknown (relocatable, paper)"));
    assert_false(world::parse_scenario(head + "learning model paper tiles 1,1,0\n", "m.scn", &s, &err));
    assert_non_null(std::strstr(err.c_str(), "four widths"));
    assert_false(world::parse_scenario(head + "learning tiles 1,1,0,5\n", "m.scn", &s, &err));
    assert_false(world::parse_scenario(head + "learning tiles 1,,0,0\n", "m.scn", &s, &err));
}

// `learning explore MODE kappa K`: the exploration (egreedy by default) and its bonus's scale.
void test_explore(void **state)
{
    (void)state;
    const std::string head = "arena 4 4\nrobot length 0.3 width 0.2 track 0.18\n"
                             "ranger kind ir min 0.1 max 0.8\nray 0\nencode x 2 y 2 heading 2\ngoal 2.5 2.5 0.6\n";
    world::Scenario s;
    std::string err;
    assert_true(world::parse_scenario(head, "g.scn", &s, &err));
    assert_string_equal(s.learning.explore.c_str(), "egreedy");
    assert_true(s.learning.kappa == 0.0);
    assert_true(world::parse_scenario(head + "learning explore plan-bonus kappa 0.05\n", "g.scn", &s, &err));
    assert_string_equal(s.learning.explore.c_str(), "plan-bonus");
    assert_true(s.learning.kappa == 0.05);
    assert_true(world::parse_scenario(head + "learning explore act-bonus\n", "g.scn", &s, &err));
    assert_string_equal(s.learning.explore.c_str(), "act-bonus");
    assert_false(world::parse_scenario(head + "learning explore bonus\n", "g.scn", &s, &err));
    assert_true(starts_with(err, "g.scn:7: learning explore: 'bonus' is not egreedy, plan-bonus or act-bonus"));
    assert_false(world::parse_scenario(head + "learning kappa -1\n", "g.scn", &s, &err));
    assert_non_null(std::strstr(err.c_str(), "kappa"));
}

void test_goal_cells(void **state)
{
    (void)state;
    const std::string head = "arena 4 4\nrobot length 0.3 width 0.2 track 0.18\n"
                             "ranger kind ir min 0.1 max 0.8\nray 0\nencode x 2 y 2 heading 2\n";
    world::Scenario s;
    std::string err;
    assert_true(world::parse_scenario(head + "goal 2.5 2.5 0.6 cells\n", "g.scn", &s, &err));
    assert_true(s.goal.cells);
    assert_true(world::in_goal(s, 2.01, 2.99));   // in the cell, outside the circle
    assert_true(world::in_goal(s, 2.5, 2.5));
    assert_false(world::in_goal(s, 2.5, 1.99));   // inside the circle, in the cell below
    assert_false(world::in_goal(s, 3.05, 2.5));
    // Every pose in the goal's cell, or within the start margin of it, is refused as a start:
    // (2.02, 2.98) is 0.68 m from the circle's centre, beyond its radius plus margin (0.65 m).
    assert_false(world::start_position_ok(s, 2.02, 2.98));
    assert_false(world::start_position_ok(s, 1.97, 2.97));  // 0.71 m out, 3 cm from the cell
    assert_true(world::start_position_ok(s, 1.5, 2.5));
    // A circle against a wall is inside the arena, and the wall is no obstacle (4.5 - 4.2 is a
    // shade under 0.3 in double: it was refused as overlapping the file's first obstacle).
    const std::string hall = "arena 4.5 4\nrobot length 0.3 width 0.2 track 0.18\n"
                             "ranger kind ir min 0.1 max 0.8\nray 0\nencode x 2 y 2 heading 2\n"
                             "obstacle box 1 1 0.4 0.4\n";
    assert_true(world::parse_scenario(hall + "goal 4.2 2.95 0.3\n", "g.scn", &s, &err));
    assert_false(world::parse_scenario(hall + "goal 1.3 1.3 0.3 cells\n", "g.scn", &s, &err));
    assert_true(err.find("goal overlaps the obstacle on line 6") != std::string::npos);
    // Without 'cells' the circle itself is the goal.
    assert_true(world::parse_scenario(head + "goal 2.5 2.5 0.6\n", "g.scn", &s, &err));
    assert_false(s.goal.cells);
    assert_false(world::in_goal(s, 2.01, 2.99));
    assert_true(world::in_goal(s, 2.5, 2.0));
    // A word other than 'cells', and a circle that holds no cell centre: file:line errors.
    assert_false(world::parse_scenario(head + "goal 2.5 2.5 0.6 squares\n", "g.scn", &s, &err));
    assert_true(starts_with(err, "g.scn:6: goal: 'squares' after the radius (only 'cells')"));
    assert_false(world::parse_scenario(head + "goal 2.0 2.0 0.3 cells\n", "g.scn", &s, &err));
    assert_true(starts_with(err, "g.scn:6: goal ... cells: no cell of the state grid"));
    // (1.5, 1.5) and (2.5, 2.5) are 0.7071068 m from (2, 2): on the circle, for a float.
    assert_false(world::parse_scenario(head + "goal 2 2 0.70711 cells\n", "g.scn", &s, &err));
    assert_true(starts_with(err, "g.scn:6: goal ... cells: a cell centre lies on the circle"));
    assert_false(world::parse_scenario("arena 4 4\nrobot length 0.3 width 0.2 track 0.18\n"
                                       "ranger kind ir min 0.1 max 0.8\nray 0\n"
                                       "encode x 10 y 2 heading 2\ngoal 2 2 0.5 cells\n",
                                       "g.scn", &s, &err));
    assert_true(starts_with(err, "g.scn:6: goal ... cells: the circle spans more than 64 cells"));
}

void test_name_resolution(void **state)
{
    (void)state;
    std::string p = world::resolve_scenario_path("paper-lab");
    assert_true(p.size() > 14 && p.compare(p.size() - 14, 14, "/paper-lab.scn") == 0);
    assert_string_equal(world::resolve_scenario_path("my/own.scn").c_str(), "my/own.scn");
    assert_string_equal(world::resolve_scenario_path("other").c_str(), "other");
    // The realistic profile: paper-lab / paper-sim with every imperfection at its default, and
    // otherwise the same robot and room.
    for (const char *name : {"paper-lab", "paper-sim"}) {
        world::Scenario exact, real;
        std::string err;
        assert_true(world::load_scenario(name, &exact, &err));
        assert_true(world::load_scenario(std::string(name) + "-real", &real, &err));
        assert_false(exact.actuation.enabled);
        assert_true(real.actuation.enabled && real.actuation.gain == 0.05 && real.actuation.noise == 0.05 &&
                    real.actuation.deadband == 0.02 && real.actuation.slip_mu == 0.6);
        assert_true(real.gyro.scale == 0.03 && exact.gyro.scale == 0.0);
        assert_true(real.obstacles.size() == exact.obstacles.size() && real.robot.track == exact.robot.track);
        if (!real.cricket.beacons.empty()) {
            assert_true(real.cricket.dropout == 0.05 && real.cricket.outlier == 0.02);
        }
    }
}

// The full example in docs/scenarios.md is a valid scenario.
void test_doc_example(void **state)
{
    (void)state;
    std::ifstream in(WORLD_TEST_DOCS, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string doc = ss.str();
    const std::size_t section = doc.find("## A full example");
    assert_true(section != std::string::npos);
    const std::size_t open = doc.find("```\n", section);
    assert_true(open != std::string::npos);
    const std::size_t close = doc.find("```", open + 4);
    assert_true(close != std::string::npos);
    world::Scenario s;
    std::string err;
    const bool ok = world::parse_scenario(doc.substr(open + 4, close - open - 4), "example", &s, &err);
    if (!ok) std::fprintf(stderr, "%s\n", err.c_str());
    assert_true(ok);
    assert_int_equal(s.ranger.rays.size(), 4);
    assert_int_equal(s.cricket.beacons.size(), 3);
    assert_int_equal(s.encoding.sensor_bits, 2);
    assert_true(std::abs(s.ranger.rays[3].x + 0.125) < 1e-12);
}

struct BadFile {
    const char *file;
    int line;         // 0: no line number in the message
    const char *why;  // a piece of the message
};

const BadFile kBadFiles[] = {
    {"unknown_key.scn", 6, "unknown key 'bogus'"},
    {"missing_value.scn", 2, "missing value"},
    {"extra_value.scn", 6, "extra value '7'"},
    {"non_numeric.scn", 6, "'zero' is not a number"},
    {"out_of_range.scn", 6, "out of range"},
    {"duplicate.scn", 7, "duplicate 'goal' (first on line 2)"},
    {"duplicate_robot.scn", 6, "duplicate 'robot' (first on line 3)"},
    {"missing_goal.scn", 4, "missing required key 'goal'"},
    {"goal_in_obstacle.scn", 3, "goal overlaps the obstacle on line 2"},
    {"goal_outside.scn", 2, "goal outside the arena"},
    {"no_room.scn", 1, "no room for a start pose"},
    {"gps_too_wide.scn", 1, "arena larger than 32.767 m with gps"},
    {"bad_ray_index.scn", 6, "code_bit ray index 4"},
    {"bad_timing.scn", 6, "not a whole number"},
    {"bad_past.scn", 7, "actions past 0.5 is not inside the next cell"},
    {"unknown_field.scn", 3, "unknown field 'wheels'"},
    {"missing_field.scn", 3, "missing field 'robot width'"},
    {"missing_ranger_min.scn", 4, "missing field 'ranger min'"},
    {"bad_beacon.scn", 6, "beacon id '1:2:3'"},
    {"bad_model.scn", 6, "learning model 'cmac': unknown (relocatable, paper)"},
    {"bad_actuation.scn", 7, "actuation gain 0.7 out of range [0, 0.5]"},
    {"garbage.bin", 3, "not a text file"},
    {"does_not_exist.scn", 0, "cannot open"},
    {"", 0, "cannot read"},  // the directory itself
};

void test_bad_files(void **state)
{
    (void)state;
    for (const BadFile &b : kBadFiles) {
        std::string path = std::string(WORLD_TEST_SCENARIOS) + "/" + b.file;
        if (b.file[0] == '\0') path = WORLD_TEST_SCENARIOS;
        world::Scenario s;
        std::string err;
        bool ok = world::load_scenario(path, &s, &err);
        std::fprintf(stderr, "  %s\n", err.c_str());
        assert_false(ok);
        std::string prefix = path + ":";
        if (b.line > 0) prefix += std::to_string(b.line) + ": ";
        if (!starts_with(err, prefix) || err.find(b.why) == std::string::npos) {
            std::fprintf(stderr, "expected '%s...%s'\n", prefix.c_str(), b.why);
            fail();
        }
    }
}

void test_text_rules(void **state)
{
    (void)state;
    const std::string base =
        "arena 6 4\ngoal 5 3 0.3\nrobot length 0.3 width 0.2 track 0.18\n"
        "ranger kind ir min 0.1 max 0.8\nray 0\n";
    world::Scenario s;
    std::string err;
    // CRLF, tabs, comments, no final newline: fine.
    assert_true(world::parse_scenario("arena\t6 4 # room\r\ngoal 5 3 0.3\r\n"
                                      "robot length 0.3 width 0.2 track 0.18\r\n"
                                      "ranger kind ir min 0.1 max 0.8\r\nray 0",
                                      "t.scn", &s, &err));
    assert_int_equal(s.encoding.sensor_bits, 0);
    // Defaults.
    assert_true(world::parse_scenario(base, "t.scn", &s, &err));
    assert_int_equal(s.timing.substeps, 12);
    assert_true(s.robot.mass == 5.0);
    assert_false(s.gps.enabled);
    // Empty text: the first missing key, at line 1.
    assert_false(world::parse_scenario("", "e.scn", &s, &err));
    assert_string_equal(err.c_str(), "e.scn:1: missing required key 'arena'");
    // nan and inf are not numbers; numbers must be whole tokens.
    assert_false(world::parse_scenario(base + "start margin nan\n", "t.scn", &s, &err));
    assert_true(starts_with(err, "t.scn:6: 'nan' is not a number"));
    assert_false(world::parse_scenario(base + "start margin 0.1x\n", "t.scn", &s, &err));
    assert_true(starts_with(err, "t.scn:6: "));
    assert_false(world::parse_scenario(base + "solver velocity_iterations 2.5\n", "t.scn", &s,
                                       &err));
    assert_true(starts_with(err, "t.scn:6: '2.5' is not an integer"));
    // A field without its value, a duplicate field.
    assert_false(world::parse_scenario(base + "gyro bias\n", "t.scn", &s, &err));
    assert_true(starts_with(err, "t.scn:6: missing value for 'gyro bias'"));
    assert_false(world::parse_scenario(base + "gyro bias 0 bias 0\n", "t.scn", &s, &err));
    assert_true(starts_with(err, "t.scn:6: duplicate field 'bias'"));
    // actuation: both fields optional; out of range, not a number, unknown, twice: refused.
    assert_true(world::parse_scenario(base + "actuation gain 0.1 noise 0.05\n", "t.scn", &s, &err));
    assert_true(s.actuation.enabled && s.actuation.gain == 0.1 && s.actuation.noise == 0.05);
    assert_true(world::parse_scenario(base + "actuation\n", "t.scn", &s, &err));
    assert_true(s.actuation.enabled && s.actuation.gain == 0.0 && s.actuation.noise == 0.0);
    assert_true(world::parse_scenario(base, "t.scn", &s, &err));
    assert_false(s.actuation.enabled);
    assert_false(world::parse_scenario(base + "actuation gain 0.6\n", "t.scn", &s, &err));
    assert_true(starts_with(err, "t.scn:6: actuation gain 0.6 out of range [0, 0.5]"));
    assert_false(world::parse_scenario(base + "actuation noise -0.1\n", "t.scn", &s, &err));
    assert_true(starts_with(err, "t.scn:6: actuation noise -0.1 out of range"));
    assert_false(world::parse_scenario(base + "actuation gain x\n", "t.scn", &s, &err));
    assert_true(starts_with(err, "t.scn:6: 'x' is not a number (actuation gain)"));
    assert_false(world::parse_scenario(base + "actuation slip 1\n", "t.scn", &s, &err));
    assert_true(starts_with(err, "t.scn:6: unknown field 'slip' for 'actuation'"));
    assert_true(world::parse_scenario(base + "actuation deadband 0.03 slip_mu 0.6\ngyro scale 0.03\n", "t.scn", &s, &err));
    assert_true(s.actuation.deadband == 0.03 && s.actuation.slip_mu == 0.6 && s.gyro.scale == 0.03);
    assert_false(world::parse_scenario(base + "gyro scale 0.3\n", "t.scn", &s, &err));
    assert_true(starts_with(err, "t.scn:6: gyro scale 0.3 out of range [0, 0.2]"));
    assert_false(world::parse_scenario(base + "actuation deadband 2\n", "t.scn", &s, &err));
    assert_true(starts_with(err, "t.scn:6: actuation deadband 2 out of range [0, 1]"));
    assert_false(world::parse_scenario(base + "actuation gain 0.1\nactuation noise 0.1\n", "t.scn", &s, &err));
    assert_true(starts_with(err, "t.scn:7: duplicate 'actuation' (first on line 6)"));
    // encode sensor must match the code bits.
    assert_false(world::parse_scenario(base + "encode sensor 2\ncode_bit 0.3 0\n", "t.scn", &s,
                                       &err));
    assert_true(starts_with(err, "t.scn:6: encode sensor 2"));
    // A ray mounted outside the body.
    assert_false(world::parse_scenario(base + "ray 0 0.5 0\n", "t.scn", &s, &err));
    assert_true(starts_with(err, "t.scn:6: ray mount point outside"));
    // An obstacle poking out of the arena.
    assert_false(world::parse_scenario(base + "obstacle circle 0.1 1 0.2\n", "t.scn", &s, &err));
    assert_true(starts_with(err, "t.scn:6: obstacle outside the arena: it reaches x = -0.1 m, past the west wall at 0 m"));
    // Beacons need a ceiling above the listener.
    assert_false(world::parse_scenario(base + "beacon 1:2:3:4:5:6:7:8 1 1 0.05\n", "t.scn", &s,
                                       &err));
    assert_true(starts_with(err, "t.scn:6: beacon not above the listener"));
    // Lines that end in CR alone (an old Mac's) are named, not taken for one long line.
    assert_false(world::parse_scenario("arena 4 3\rgoal 1 1 0.3\r", "t.scn", &s, &err));
    assert_true(starts_with(err, "t.scn:1: a carriage return inside the line: lines that end in CR alone"));
    // One beacon's id spelled two ways is one beacon: the firmware compares the 8 bytes.
    assert_false(world::parse_scenario(base + "beacon 1:5e:3c:3c:a:0:0:b1 1 1 2.5\nbeacon 01:5E:3c:3c:0a:00:00:b1 2 1 2.5\n",
                                       "t.scn", &s, &err));
    assert_true(starts_with(err, "t.scn:7: duplicate beacon id '01:5E:3c:3c:0a:00:00:b1' (the same 8 bytes as "
                                 "'1:5e:3c:3c:a:0:0:b1')"));
    // A huge arena that is all obstacle: refused after a bounded search (at most 10^6 points).
    assert_false(world::parse_scenario("arena 1000 1000\ngoal 1 0.15 0.1\nobstacle box 500 500.15 1000 999.7\n"
                                       "robot length 0.3 width 0.2 track 0.18\n"
                                       "ranger kind ir min 0.1 max 0.8\nray 0\n",
                                       "big.scn", &s, &err));
    assert_true(starts_with(err, "big.scn:1: no room for a start pose"));
    // Very long lines are refused, not read without bound.
    assert_false(world::parse_scenario(base + "# " + std::string(2000, 'x') + "\n", "t.scn", &s,
                                       &err));
    assert_true(starts_with(err, "t.scn:6: line longer than"));
}

// Mutated copies of the shipped scenario and plain noise: the parser returns, with either a
// scenario or a "file:line: " error, and never crashes (run it under host-asan too).
void test_fuzz(void **state)
{
    (void)state;
    std::ifstream in(world::resolve_scenario_path("paper-sim"), std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string good = ss.str();
    assert_true(good.size() > 100);
    world::RandomStream rng(12345, 0);
    const char alphabet[] = "0123456789.-+e# \t\nabcxyz_\r:,=\x01\xff";
    int accepted = 0, refused = 0;
    for (int round = 0; round < 3000; ++round) {
        std::string text = good;
        int edits = 1 + static_cast<int>(rng.uniform() * 8);
        for (int e = 0; e < edits && !text.empty(); ++e) {
            std::size_t at = static_cast<std::size_t>(rng.uniform() * static_cast<double>(text.size()));
            char c = alphabet[static_cast<std::size_t>(rng.uniform() * (sizeof alphabet - 1))];
            switch (static_cast<int>(rng.uniform() * 4)) {
            case 0: text[at] = c; break;
            case 1: text.insert(at, 1, c); break;
            case 2: text.erase(at, 1 + static_cast<std::size_t>(rng.uniform() * 20)); break;
            default: text.resize(at); break;
            }
        }
        if (round % 10 == 0) {  // pure noise
            text.resize(static_cast<std::size_t>(rng.uniform() * 400));
            for (char &ch : text) ch = static_cast<char>(rng.uniform() * 256);
        }
        world::Scenario s;
        std::string err;
        if (world::parse_scenario(text, "fuzz.scn", &s, &err)) {
            ++accepted;
            assert_false(s.ranger.rays.empty());
        } else {
            ++refused;
            int line = 0;
            assert_int_equal(std::sscanf(err.c_str(), "fuzz.scn:%d: ", &line), 1);
            assert_true(line >= 1);
        }
    }
    assert_true(accepted > 0 && refused > 0);
}

}  // namespace

int run_scenario_tests(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_paper_sim_parses),
        cmocka_unit_test(test_paper_lab_parses),
        cmocka_unit_test(test_goal_cells),
        cmocka_unit_test(test_gamma_auto),
        cmocka_unit_test(test_constant_code_bits),
        cmocka_unit_test(test_encode_auto),
        cmocka_unit_test(test_encode_auto_past),
        cmocka_unit_test(test_encode_auto_pinch),
        cmocka_unit_test(test_encode_auto_plain_goal),
        cmocka_unit_test(test_encode_auto_goal_sliver),
        cmocka_unit_test(test_explore),
        cmocka_unit_test(test_learning_model),
        cmocka_unit_test(test_name_resolution),
        cmocka_unit_test(test_doc_example),
        cmocka_unit_test(test_bad_files),
        cmocka_unit_test(test_text_rules),
        cmocka_unit_test(test_fuzz),
    };
    return cmocka_run_group_tests_name("world_scenario", tests, nullptr, nullptr);
}
