// SPDX-License-Identifier: MIT
// Tests of the simulated world: driving, turning, actions, range rays, bumps, start poses,
// determinism, gyro/GPS noise and the Cricket listener's lines.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <vector>

// cmocka 1.1.5's header has no extern "C" of its own.
extern "C" {
#include "test_common.h"
}
#include "world/cricket.h"
#include "world/motion.h"
#include "world/random.h"
#include "world/scenario.h"
#include "world/world.h"
#include "fw/fw_util.h"

int run_scenario_tests(void);

namespace {

constexpr double kPi = FW_PI;
constexpr double s_dt_ = 0.016;  // the default physics step, s

// An empty 10 m x 10 m arena with a 0.6 x 0.5 robot (track 0.4) and the given extra lines.
world::Scenario open_arena(const std::string &extra,
                           const std::string &ranger = "ranger kind sonar min 0.01 max 3.0\n")
{
    std::string text =
        "arena 10 10\n"
        "goal 9 9 0.3\n"
        "robot length 0.6 width 0.5 mass 9 track 0.4 max_speed 2 max_accel 60\n" +
        ranger + extra;
    if (text.find("\nray ") == std::string::npos) text += "ray 0\n";
    world::Scenario s;
    std::string err;
    if (!world::parse_scenario(text, "open.scn", &s, &err)) {
        std::fprintf(stderr, "%s\n", err.c_str());
        fail();
    }
    return s;
}

world::Scenario shipped(const char *name)
{
    world::Scenario s;
    std::string err;
    if (!world::load_scenario(name, &s, &err)) {
        std::fprintf(stderr, "%s\n", err.c_str());
        fail();
    }
    return s;
}

void test_straight_drive(void **state)
{
    (void)state;
    const world::Scenario s = open_arena("");
    for (double heading : {0.0, 0.5235987755982988, -2.0}) {
        world::World w(s, 1);
        const world::Pose start{5.0 - 1.0 * std::cos(heading), 5.0 - 1.0 * std::sin(heading),
                                heading};
        w.reset(start);
        w.set_wheel_targets(1.2, 1.2);
        double along = 0.0, lateral = 0.0;
        while (along < 2.0) {
            w.step();
            const world::Pose p = w.pose();
            const double dx = p.x - start.x, dy = p.y - start.y;
            along = dx * std::cos(heading) + dy * std::sin(heading);
            lateral = -dx * std::sin(heading) + dy * std::cos(heading);
            assert_true(std::fabs(lateral) < 1e-3);
            assert_true(w.time_s() < 10.0);
        }
        assert_true(std::fabs(world::wrap_angle(w.pose().heading - heading)) < 1e-4);
        const world::WheelSpeeds v = w.wheel_speeds();
        assert_true(std::fabs(v.left - 1.2) < 1e-3 && std::fabs(v.right - 1.2) < 1e-3);
        assert_false(w.bumped());
    }
}

void test_turn_rate(void **state)
{
    (void)state;
    const world::Scenario s = open_arena("");
    const double cases[][2] = {{-0.3, 0.5}, {0.8, 0.2}, {-0.6, 0.6}, {1.0, 1.3}};
    for (const auto &c : cases) {
        world::World w(s, 1);
        w.reset({5.0, 5.0, 0.0});
        w.set_wheel_targets(c[0], c[1]);
        for (int i = 0; i < 12; ++i) w.step();  // past the ramp
        const double expect = (c[1] - c[0]) / s.robot.track;
        assert_true(std::fabs(w.yaw_rate() - expect) <= 0.02 * std::fabs(expect));
        // And the heading advances at that rate over a further 0.48 s.
        const double h0 = w.pose().heading;
        for (int i = 0; i < 30; ++i) w.step();
        const double turned = world::wrap_angle(w.pose().heading - h0);
        assert_true(std::fabs(turned - expect * 0.48) <= 0.02 * std::fabs(expect * 0.48));
    }
}

void test_actions(void **state)
{
    (void)state;
    for (const char *name : {"paper-sim", "paper-lab"}) {
        const world::Scenario s = shipped(name);
        world::World w(s, 3);
        // A start far from everything: the arena's most open point on a coarse grid.
        world::Pose best{0, 0, 0};
        double room = -1.0;
        for (double y = 0.3; y < s.arena_h; y += 0.1) {
            for (double x = 0.3; x < s.arena_w; x += 0.1) {
                if (world::clearance(s, x, y) > room && std::hypot(x - s.goal.cx, y - s.goal.cy) >
                                                             s.goal.radius + 0.5) {
                    room = world::clearance(s, x, y);
                    best = {x, y, 0.3};
                }
            }
        }
        assert_true(room > 0.6);
        w.reset(best);
        const world::Action seq[] = {world::Action::Forward,  world::Action::Forward,
                                     world::Action::TurnLeft, world::Action::Backward,
                                     world::Action::TurnRight, world::Action::TurnRight,
                                     world::Action::Forward};
        for (world::Action a : seq) {
            const world::Pose before = w.pose();
            const world::WheelSpeeds v = world::wheel_targets_for(s, a, w.wheel_speeds());
            w.set_wheel_targets(v.left, v.right);
            w.step_period();
            const world::Pose after = w.pose();
            const double turned = world::wrap_angle(after.heading - before.heading);
            const double moved = (after.x - before.x) * std::cos(before.heading) +
                                 (after.y - before.y) * std::sin(before.heading);
            switch (a) {
            case world::Action::Forward:
                assert_true(std::fabs(moved - s.actions.step) < 0.01);
                assert_true(std::fabs(turned) < 0.01);
                break;
            case world::Action::Backward:
                assert_true(std::fabs(moved + s.actions.step) < 0.01);
                assert_true(std::fabs(turned) < 0.01);
                break;
            case world::Action::TurnLeft:
                assert_true(std::fabs(turned - s.actions.turn) < 0.01);
                break;
            case world::Action::TurnRight:
                assert_true(std::fabs(turned + s.actions.turn) < 0.01);
                break;
            }
            assert_false(w.bumped());
        }
    }
}

// Long random action sequences with the shipped robots in open space: wheel targets from
// wheel_targets_for() stay below max_speed (the compensation for the speeds a period starts with
// does not run away) and every action does what it says.
void test_actions_random_sequence(void **state)
{
    (void)state;
    for (const char *name : {"paper-sim", "paper-lab"}) {
        world::Scenario s = shipped(name);
        s.obstacles.clear();
        s.arena_w = s.arena_h = 200.0;
        s.actions.turn = FW_PI / 4.0;  // what one period can turn (the shipped 90 degrees take two)
        world::World w(s, 21);
        world::RandomStream pick(21, 7);
        w.reset({100.0, 100.0, 0.0});
        for (int i = 0; i < 3000; ++i) {
            const auto a = static_cast<world::Action>(static_cast<int>(pick.uniform() * 4));
            const world::Pose before = w.pose();
            const world::WheelSpeeds v = world::wheel_targets_for(s, a, w.wheel_speeds());
            assert_true(std::fabs(v.left) < s.robot.max_speed * 0.95);
            assert_true(std::fabs(v.right) < s.robot.max_speed * 0.95);
            w.set_wheel_targets(v.left, v.right);
            w.step_period();
            const world::Pose after = w.pose();
            const double turned = world::wrap_angle(after.heading - before.heading);
            const double moved = std::hypot(after.x - before.x, after.y - before.y);
            switch (a) {
            case world::Action::Forward:
            case world::Action::Backward:
                assert_true(std::fabs(turned) < 0.005);
                assert_true(moved > s.actions.step - 0.01 && moved < s.actions.step + 0.01);
                break;
            case world::Action::TurnLeft:
                assert_true(std::fabs(turned - s.actions.turn) < 0.005);
                assert_true(moved < 0.05);
                break;
            case world::Action::TurnRight:
                assert_true(std::fabs(turned + s.actions.turn) < 0.005);
                assert_true(moved < 0.05);
                break;
            }
            if (std::hypot(after.x - 100.0, after.y - 100.0) > 80.0) w.reset({100.0, 100.0, 0.0});
        }
        assert_false(w.bumped());
    }
}

void test_rays_known_geometry(void **state)
{
    (void)state;
    // Robot at (5, 5) facing +x; a box whose near face is at x = 6.9.
    const world::Scenario s = open_arena(
        "obstacle box 7.0 5.0 0.2 2.0\n"
        "ray 0\n"              // 0: front outline (x = 0.3) -> 1.6 m
        "ray 0 -0.3 0\n"       // 1: rear outline, looking forward through the body -> 2.2 m
        "ray 180\n"            // 2: back: the wall at x = 0 is 4.7 m away -> max (3.0)
        "ray 90\n"             // 3: left: wall at y = 10 is 4.75 m away -> max
        "ray 0 0 0\n");        // 4: from the centre -> 1.9 m
    world::World w(s, 1);
    w.reset({5.0, 5.0, 0.0});
    float r[5];
    w.range_readings(r);
    assert_true(std::fabs(r[0] - 1.6f) < 1e-4f);
    assert_true(std::fabs(r[1] - 2.2f) < 1e-4f);
    assert_true(r[2] == 3.0f);
    assert_true(r[3] == 3.0f);
    assert_true(std::fabs(r[4] - 1.9f) < 1e-4f);
    // Turned by 90 degrees the front ray meets the wall at y = 10: 10 - 5 - 0.3 = 4.7 > max;
    // moved near that wall it reads the distance.
    w.reset({5.0, 8.0, kPi / 2});
    w.range_readings(r);
    assert_true(std::fabs(r[0] - 1.7f) < 1e-4f);
}

void test_ray_noise(void **state)
{
    (void)state;
    world::Scenario s = open_arena("obstacle box 7.0 5.0 0.2 2.0\nray 0\nray 180\n");
    s.ranger.noise_sd = 0.01;
    s.ranger.noise_prop = 0.02;  // sd at 1.6 m: 0.01 + 0.032 = 0.042
    world::World w(s, 7);
    w.reset({5.0, 5.0, 0.0});
    double sum = 0.0, sum2 = 0.0;
    const int n = 4000;
    for (int i = 0; i < n; ++i) {
        float r[2];
        w.range_readings(r);
        assert_true(r[1] == 3.0f);  // nothing there: max, never noisy
        assert_true(r[0] >= 0.01f && r[0] < 3.0f);
        sum += r[0];
        sum2 += static_cast<double>(r[0]) * r[0];
    }
    const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
    assert_true(std::fabs(mean - 1.6) < 0.005);
    assert_true(std::fabs(sd - 0.042) < 0.004);
    // Below min range: min range.
    world::Scenario close = open_arena("obstacle box 5.6 5.0 0.2 2.0\nray 0\n",
                                       "ranger kind sonar min 0.5 max 3.0\n");
    world::World wc(close, 1);
    wc.reset({5.0, 5.0, 0.0});
    float r0;
    wc.true_ranges(&r0);
    assert_true(r0 == 0.5f);
}

void test_bump_wall(void **state)
{
    (void)state;
    const world::Scenario s = open_arena("");
    world::World w(s, 1);
    w.reset({8.5, 5.0, 0.0});  // front at 8.8, wall at 10
    w.set_wheel_targets(1.0, 1.0);
    w.step_period();
    assert_false(w.bumped());
    for (int i = 0; i < 20; ++i) w.step_period();  // 4 s: would be 4 m
    assert_true(w.bumped());
    const world::Pose p = w.pose();
    assert_true(p.x <= 10.0 - 0.3 + 0.005);  // stopped at the wall
    assert_true(p.x > 10.0 - 0.3 - 0.03);
    assert_true(std::fabs(p.y - 5.0) < 0.01);
    const world::WheelSpeeds v = w.wheel_speeds();
    assert_true(std::fabs(v.left) < 0.05 && std::fabs(v.right) < 0.05);
    // Still pushing: a bump again.
    w.clear_bump();
    w.step_period();
    assert_true(w.bumped());
    // Backing away from the wall is not a bump.
    w.clear_bump();
    w.set_wheel_targets(-1.0, -1.0);
    w.step_period();
    assert_false(w.bumped());
    assert_true(w.pose().x < p.x - 0.1);
    // Turning on the spot against the wall: the corners hit it.
    world::World t(s, 1);
    t.reset({10.0 - 0.26, 5.0, kPi / 2});  // side 0.01 m off the wall
    t.set_wheel_targets(-0.5, 0.5);
    t.step_period();
    t.step_period();
    assert_true(t.bumped());
    // An obstacle, not only walls.
    const world::Scenario so = open_arena("obstacle circle 6.0 5.0 0.3\n");
    world::World wo(so, 1);
    wo.reset({5.0, 5.0, 0.0});
    wo.set_wheel_targets(0.8, 0.8);
    for (int i = 0; i < 10; ++i) wo.step_period();
    assert_true(wo.bumped());
    assert_true(wo.pose().x < 6.0 - 0.3 - 0.3 + 0.01);
}

void test_start_poses(void **state)
{
    (void)state;
    for (const char *name : {"paper-sim", "paper-lab"}) {
        const world::Scenario s = shipped(name);
        world::World w(s, 11);
        double min_x = 1e9, max_x = -1e9;
        for (int i = 0; i < 300; ++i) {
            const world::Pose p = w.sample_start_pose();
            assert_true(world::start_position_ok(s, p.x, p.y));
            assert_true(p.heading >= -kPi && p.heading < kPi);
            min_x = std::fmin(min_x, p.x);
            max_x = std::fmax(max_x, p.x);
            w.reset(p);
            assert_false(w.in_goal());
            w.step();  // at rest: no contact at all
            assert_false(w.bumped());
            const world::Pose q = w.pose();
            assert_true(std::fabs(q.x - p.x) < 1e-5 && std::fabs(q.y - p.y) < 1e-5);
        }
        assert_true(max_x - min_x > s.arena_w / 2);  // spread over the arena
    }
}

void test_goal(void **state)
{
    (void)state;
    const world::Scenario s = shipped("paper-sim");
    world::World w(s, 1);
    w.reset({4.3, 4.0, 0.0});
    assert_true(w.in_goal());
    w.reset({4.51, 4.0, 0.0});
    assert_false(w.in_goal());
}

struct Trace {
    std::vector<double> poses;
    std::vector<float> ranges;
    std::vector<double> other;
};

Trace run_trace(const world::Scenario &s, std::uint32_t seed)
{
    Trace t;
    world::World w(s, seed);
    world::RandomStream actions(seed, 99);
    w.reset(w.sample_start_pose());
    std::vector<float> r(static_cast<std::size_t>(w.ray_count()));
    for (int i = 0; i < 400; ++i) {
        const auto a = static_cast<world::Action>(static_cast<int>(actions.uniform() * 4));
        const world::WheelSpeeds v = world::wheel_targets_for(s, a, w.wheel_speeds());
        w.set_wheel_targets(v.left, v.right);
        w.step_period();
        const world::Pose p = w.pose();
        t.poses.insert(t.poses.end(), {p.x, p.y, p.heading});
        w.range_readings(r.data());
        t.ranges.insert(t.ranges.end(), r.begin(), r.end());
        const world::Pose g = w.gps_pose();
        t.other.insert(t.other.end(), {w.gyro_rate(), g.x, g.y, g.heading,
                                       w.bumped() ? 1.0 : 0.0});
        w.clear_bump();
        if (i % 100 == 99) w.reset(w.sample_start_pose());
    }
    return t;
}

// `actuation gain G noise S`: each wheel runs at its gain (drawn once per World, in
// [1 - G, 1 + G]) times each command's 1 + S N(0, 1); without the line, exactly the target.
void test_actuation(void **state)
{
    (void)state;
    {
        world::World exact(open_arena(""), 5);
        const world::WheelSpeeds g = exact.wheel_gains();
        assert_true(g.left == 1.0 && g.right == 1.0);
        exact.set_wheel_targets(0.7, -0.3);
        assert_true(exact.wheel_targets().left == 0.7 && exact.wheel_targets().right == -0.3);
    }
    // Gain alone: the targets are the command times the drawn gains, the same for a seed, other
    // gains for another seed; every gain within [0.9, 1.1] and their spread over many seeds covers it.
    const world::Scenario gs = open_arena("actuation gain 0.1\n");
    double lo = 2.0, hi = 0.0;
    for (std::uint32_t seed = 1; seed <= 200; ++seed) {
        world::World w(gs, seed);
        const world::WheelSpeeds g = w.wheel_gains();
        for (double x : {g.left, g.right}) {
            assert_true(x >= 0.9 && x <= 1.1);
            lo = std::min(lo, x);
            hi = std::max(hi, x);
        }
        w.set_wheel_targets(1.0, -0.5);
        assert_true(w.wheel_targets().left == g.left && w.wheel_targets().right == -0.5 * g.right);
        world::World again(gs, seed);
        assert_true(again.wheel_gains().left == g.left && again.wheel_gains().right == g.right);
    }
    assert_true(lo < 0.91 && hi > 1.09);
    // A gain mismatch bends a straight drive toward the slower wheel.
    {
        world::World w(gs, 3);
        const world::WheelSpeeds g = w.wheel_gains();
        w.reset({5.0, 5.0, 0.0});
        w.set_wheel_targets(0.5, 0.5);
        for (int i = 0; i < 60; ++i) w.step();
        const double turned = w.pose().heading;
        assert_true((turned > 0.0) == (g.right > g.left));
        assert_true(std::fabs(turned) > 0.01);
    }
    // Noise: per command, mean 1, sd S (within sampling error); the gains stay as drawn.
    const world::Scenario ns = open_arena("actuation noise 0.05\n");
    world::World w(ns, 9);
    assert_true(w.wheel_gains().left == 1.0 && w.wheel_gains().right == 1.0);
    double sum = 0.0, sq = 0.0;
    const int n = 4000;
    for (int i = 0; i < n; ++i) {
        w.set_wheel_targets(1.0, 1.0);
        for (double x : {w.wheel_targets().left, w.wheel_targets().right}) {
            sum += x;
            sq += x * x;
        }
    }
    const double mean = sum / (2 * n), sd = std::sqrt(sq / (2 * n) - mean * mean);
    assert_true(std::fabs(mean - 1.0) < 0.003);
    assert_true(std::fabs(sd - 0.05) < 0.003);
    // The clamp to max_speed still applies after the factors.
    w.set_wheel_targets(100.0, -100.0);
    assert_true(w.wheel_targets().left == 2.0 && w.wheel_targets().right == -2.0);
}

// The other imperfections of a real base: a motor deadband, tyres that slide sideways past their
// friction, a gyro scale error drawn once per robot, Cricket transmissions missed or reflected.
void test_imperfections(void **state)
{
    (void)state;
    // Deadband: a target below it does not turn the wheel.
    {
        world::World w(open_arena("actuation deadband 0.05\n"), 1);
        w.set_wheel_targets(0.03, -0.2);
        assert_true(w.wheel_targets().left == 0.0 && w.wheel_targets().right == -0.2);
        w.set_wheel_targets(-0.049, 0.05);
        assert_true(w.wheel_targets().left == 0.0 && w.wheel_targets().right == 0.05);
    }
    // Sideways grip: a fast arc needs 3.75 m/s^2 of centripetal force; at mu 0.2 (1.96 m/s^2)
    // the robot slides out of it, with ideal tyres it does not.
    for (const char *extra : {"", "actuation slip_mu 0.2\n"}) {
        world::World w(open_arena(extra), 1);
        w.reset({3.0, 5.0, 0.0});
        w.set_wheel_targets(1.0, 2.0);
        double slide = 0.0;
        for (int i = 0; i < 40; ++i) {
            const world::Pose a = w.pose();
            w.step();
            const world::Pose b = w.pose();
            const double mid = a.heading + 0.5 * world::wrap_angle(b.heading - a.heading);
            const double sideways = -(b.x - a.x) * std::sin(mid) + (b.y - a.y) * std::cos(mid);
            if (i >= 10) slide = std::max(slide, std::fabs(sideways) / s_dt_);
        }
        if (extra[0] == '\0') {
            assert_true(slide < 0.05);
        } else {
            assert_true(slide > 0.1);
        }
    }
    // Gyro scale: the rate times a factor drawn once per robot within [0.97, 1.03]; none without.
    {
        const world::Scenario g = open_arena("gyro scale 0.03\n");
        double lo = 2.0, hi = 0.0;
        for (std::uint32_t seed = 1; seed <= 50; ++seed) {
            world::World w(g, seed);
            w.reset({5.0, 5.0, 0.0});
            w.set_wheel_targets(-0.4, 0.4);
            for (int i = 0; i < 12; ++i) w.step();
            const double k = w.gyro_rate() / w.yaw_rate();
            assert_true(k >= 0.97 && k <= 1.03);
            lo = std::min(lo, k);
            hi = std::max(hi, k);
        }
        assert_true(lo < 0.98 && hi > 1.02);
        world::World exact(open_arena(""), 1);
        exact.reset({5.0, 5.0, 0.0});
        exact.set_wheel_targets(-0.4, 0.4);
        for (int i = 0; i < 12; ++i) exact.step();
        assert_true(exact.gyro_rate() == exact.yaw_rate());
    }
    // Cricket: half the transmissions missed; of the rest, a fifth reflected, up to 1 m long.
    {
        world::Scenario lab = shipped("paper-lab");
        const std::size_t all = [&] {
            world::CricketListener l(lab, 9);
            std::vector<world::CricketLine> lines;
            for (int k = 1; k <= 600; ++k) l.advance(k * 0.1, 1.2, 2.1, &lines);
            return lines.size();
        }();
        lab.cricket.dropout = 0.5;
        lab.cricket.outlier = 0.2;
        world::CricketListener l(lab, 9);
        std::vector<world::CricketLine> lines;
        for (int k = 1; k <= 600; ++k) l.advance(k * 0.1, 1.2, 2.1, &lines);
        assert_true(lines.size() > all * 4 / 10 && lines.size() < all * 6 / 10);
        std::size_t long_ones = 0;
        for (const world::CricketLine &c : lines) {
            const double extra = c.range_m - c.true_range_m;
            assert_true(extra > -0.06 && extra < 1.06);
            long_ones += extra > 0.06 ? 1u : 0u;
        }
        assert_true(long_ones > lines.size() / 10 && long_ones < lines.size() * 3 / 10);
    }
}

void test_determinism(void **state)
{
    (void)state;
    for (const char *name : {"paper-sim", "paper-lab"}) {
        const world::Scenario s = shipped(name);
        const Trace a = run_trace(s, 42), b = run_trace(s, 42), c = run_trace(s, 43);
        assert_true(a.poses == b.poses);
        assert_int_equal(a.ranges.size(), b.ranges.size());
        assert_memory_equal(a.ranges.data(), b.ranges.data(), a.ranges.size() * sizeof(float));
        assert_true(a.other == b.other);
        assert_false(a.poses == c.poses);
    }
}

void test_gyro_gps_noise(void **state)
{
    (void)state;
    const world::Scenario lab = shipped("paper-lab");
    world::World w(lab, 5);
    w.reset({1.0, 2.5, 0.0});
    double sum = 0.0, sum2 = 0.0;
    const int n = 5000;
    for (int i = 0; i < n; ++i) {
        const double g = w.gyro_rate();
        sum += g;
        sum2 += g * g;
    }
    double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
    assert_true(std::fabs(mean - lab.gyro.bias) < 0.001);
    assert_true(std::fabs(sd - lab.gyro.noise_sd) < 0.001);
    // No GPS in the lab: the true pose.
    const world::Pose g = w.gps_pose();
    assert_true(g.x == w.pose().x && g.y == w.pose().y);

    const world::Scenario sim = shipped("paper-sim");
    world::World ws(sim, 5);
    ws.reset({1.0, 4.0, kPi - 0.001});  // heading noise must wrap
    sum = sum2 = 0.0;
    for (int i = 0; i < n; ++i) {
        const world::Pose p = ws.gps_pose();
        assert_true(p.heading > -kPi && p.heading <= kPi);
        sum += p.x - 1.0;
        sum2 += (p.x - 1.0) * (p.x - 1.0);
    }
    mean = sum / n;
    sd = std::sqrt(sum2 / n - mean * mean);
    assert_true(std::fabs(mean) < 0.002);
    assert_true(std::fabs(sd - sim.gps.xy_sd) < 0.002);
}

void test_sensor_code(void **state)
{
    (void)state;
    const world::Scenario s = shipped("paper-sim");
    world::World w(s, 1);
    // Below the north wall (y = 8), nothing else within 1 m (the ring around the goal is further).
    // Facing it or away, the body is 0.5 m from it; side on, 0.7 m (so that the front and back
    // sonars at +-33.75 degrees see it beyond 1 m).
    std::vector<float> r(16);
    const double headings[] = {kPi / 2, -kPi / 2, 0.0, kPi};
    const std::uint32_t codes[] = {1u, 8u, 2u, 4u};  // front, back, left, right
    for (int i = 0; i < 4; ++i) {
        const double h = headings[i];
        const double half = (i < 2) ? 0.30 : 0.25;  // half length or half width toward the wall
        const double gap = (i < 2) ? 0.5 : 0.7;
        w.reset({4.0, 8.0 - gap - half, h});
        w.true_ranges(r.data());
        assert_int_equal(world::sensor_code(s, r.data()), codes[i]);
    }
}

void test_cricket_lines(void **state)
{
    (void)state;
    const world::Scenario s = shipped("paper-lab");
    const world::CricketSpec &c = s.cricket;
    world::CricketListener listener(s, 9);
    assert_int_equal(listener.beacon_count(), static_cast<int>(c.beacons.size()));
    std::vector<world::CricketLine> lines;
    const double x = 1.2, y = 2.1;
    for (int k = 1; k <= 60 * 125; ++k) {  // 60 s in 8 ms steps
        listener.advance(k * 0.008, x, y, &lines);
    }
    // Each beacon about 60 / 1.0 times.
    assert_true(lines.size() > c.beacons.size() * 45 && lines.size() < c.beacons.size() * 91);
    std::map<int, long> last_ts;
    long prev_ts = -1;
    int intervals = 0;
    for (const world::CricketLine &l : lines) {
        char id[64], sp[64];
        long db = 0, dr = 0, tm = 0, ts = 0;
        int used = 0;
        const int n = std::sscanf(l.text.c_str(),
                                  "VR=2.0,ID=%63[^,],SP=%63[^,],DB=%ld,DR=%ld,TM=%ld,TS=%ld\r\n%n",
                                  id, sp, &db, &dr, &tm, &ts, &used);
        assert_int_equal(n, 6);
        assert_int_equal(static_cast<std::size_t>(used), l.text.size());
        assert_true(l.text.size() >= 2 && l.text.compare(l.text.size() - 2, 2, "\r\n") == 0);
        assert_string_equal(id, c.beacons[static_cast<std::size_t>(l.beacon)].id.c_str());
        assert_string_equal(sp, c.space.c_str());
        const world::Beacon &b = c.beacons[static_cast<std::size_t>(l.beacon)];
        const double dz = b.z - c.listener_height;
        const double truth = std::sqrt((b.x - x) * (b.x - x) + (b.y - y) * (b.y - y) + dz * dz);
        assert_true(std::fabs(db / 100.0 - truth) < 5 * c.noise_sd + 0.01);
        assert_true(std::fabs(dr * 1e-6 * c.speed_of_sound - db / 100.0) < 0.006);
        assert_true(ts >= prev_ts);  // time order
        prev_ts = ts;
        assert_true(std::fabs(ts - l.time_s * 1000.0) <= 0.5);
        auto it = last_ts.find(l.beacon);
        if (it != last_ts.end()) {
            const long gap = ts - it->second;
            assert_true(gap >= 667 && gap <= 1333);
            assert_true(std::labs(tm - gap) <= 1);
            ++intervals;
        }
        last_ts[l.beacon] = ts;
    }
    assert_true(intervals > 200);
    // Same seed, same lines, however the time is sliced.
    world::CricketListener again(s, 9);
    std::vector<world::CricketLine> coarse;
    for (int k = 1; k <= 60 * 5; ++k) again.advance(k * 0.2, x, y, &coarse);
    assert_int_equal(coarse.size(), lines.size());
    for (std::size_t i = 0; i < lines.size(); ++i) {
        assert_string_equal(coarse[i].text.c_str(), lines[i].text.c_str());
    }
    // Time never goes back.
    const std::size_t before = coarse.size();
    again.advance(10.0, x, y, &coarse);
    assert_int_equal(coarse.size(), before);
}

// Rooms that change: only obstacles may differ between the two layouts, and a World whose
// obstacles are replaced is the changed room (its start poses are a World's made from it).
void test_change_layout(void **state)
{
    (void)state;
    const world::Scenario a = shipped("paper-lab");
    world::Scenario b = a;
    world::Obstacle box;
    box.shape = world::Obstacle::Shape::Box;
    box.cx = 2.8;
    box.cy = 2.95;
    box.w = 0.3;
    box.h = 0.5;
    b.obstacles.push_back(box);
    b.learning.sets = 1;  // the protocol may differ
    b.learning.episodes = 3;
    assert_string_equal(world::layout_change_problem(a, b).c_str(), "");
    world::Scenario c = b;
    c.goal.cx += 0.1;
    assert_string_equal(world::layout_change_problem(a, c).c_str(),
                        "the goal (the firmware is given it) differs (only obstacles may change)");
    c = b;
    c.robot.mass = 3.0;
    assert_true(world::layout_change_problem(a, c).find("the robot differs") == 0);
    c = b;
    c.encoding.x_bits = 4;
    assert_true(world::layout_change_problem(a, c).find("the encoding differs") == 0);
    c = b;
    c.learning.gamma = 0.9;
    assert_true(world::layout_change_problem(a, c).find("the learning line") == 0);
    c = b;
    c.ranger.rays[1].angle += 0.01;
    assert_true(world::layout_change_problem(a, c).find("the ranger") == 0);
    // Where aligned steps stop is the parser's verdict (actions stop): how it was asked for
    // (auto, centre) may differ, not the stop.
    c = b;
    c.actions.centred = true;
    assert_true(world::layout_change_problem(a, c).find("the actions differs") == 0);
    c = b;
    c.actions.stop = "past";
    assert_string_equal(world::layout_change_problem(a, c).c_str(), "");

    world::World changed(a, 5);
    changed.set_obstacles(b.obstacles);
    world::World fresh(b, 5);
    assert_int_equal(changed.scenario().obstacles.size(), b.obstacles.size());
    for (int i = 0; i < 300; ++i) {
        const world::Pose p = changed.sample_start_pose(), q = fresh.sample_start_pose();
        assert_true(p.x == q.x && p.y == q.y && p.heading == q.heading);
        assert_true(world::obstacle_distance(box, p.x, p.y) > world::robot_radius(a.robot));
    }
    // The box is there: from the west of it, facing east, the front ray reads it at 0.25 m
    // (the ray starts on the robot's front edge, 0.125 m ahead of its centre).
    const world::Pose west{2.65 - 0.125 - 0.25, 2.95, 0.0};
    changed.reset(west);
    float r[8];
    changed.true_ranges(r);
    assert_true(std::fabs(r[0] - 0.25f) < 1e-3f);
}

}  // namespace

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_straight_drive),
        cmocka_unit_test(test_turn_rate),
        cmocka_unit_test(test_actions),
        cmocka_unit_test(test_actions_random_sequence),
        cmocka_unit_test(test_rays_known_geometry),
        cmocka_unit_test(test_ray_noise),
        cmocka_unit_test(test_bump_wall),
        cmocka_unit_test(test_start_poses),
        cmocka_unit_test(test_goal),
        cmocka_unit_test(test_actuation),
        cmocka_unit_test(test_imperfections),
        cmocka_unit_test(test_determinism),
        cmocka_unit_test(test_gyro_gps_noise),
        cmocka_unit_test(test_sensor_code),
        cmocka_unit_test(test_cricket_lines),
        cmocka_unit_test(test_change_layout),
    };
    int failed = cmocka_run_group_tests_name("world", tests, nullptr, nullptr);
    failed += run_scenario_tests();
    return failed;
}
