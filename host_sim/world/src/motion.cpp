// SPDX-License-Identifier: MIT
// dynaqpc world: actions -> wheel speed targets for one control period.
//
// The wheel controller (world.cpp) slews its command by at most max_accel * dt per physics step
// and the wheel follows the command exactly when free; the body integrates position with the
// speed after each step (Box2D's semi-implicit Euler). So a wheel's travel over the period for a
// constant target v is dt * sum_k c_k, c_k = c_(k-1) + clamp(v - c_(k-1), +-max_accel * dt),
// c_0 = its speed now. That sum never decreases as v grows, so bisection finds the v that gives
// the wanted travel, to float precision, in 60 halvings.
#include <algorithm>
#include <cmath>

#include "world/motion.h"

namespace world {

namespace {

double travel(const Scenario &s, double target, double current)
{
    const double dt = s.timing.physics_dt;
    const double dv = s.robot.max_accel * dt;
    double c = current, sum = 0.0;
    for (int k = 0; k < s.timing.substeps; ++k) {
        c += std::clamp(target - c, -dv, dv);
        sum += c;
    }
    return sum * dt;
}

double solve(const Scenario &s, double want, double current)
{
    double lo = -s.robot.max_speed, hi = s.robot.max_speed;
    if (want >= travel(s, hi, current)) return hi;
    if (want <= travel(s, lo, current)) return lo;
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (travel(s, mid, current) < want) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return 0.5 * (lo + hi);
}

}  // namespace

WheelSpeeds action_wheel_travel(const Scenario &s, Action a)
{
    const double d = s.actions.step;
    const double arc = s.actions.turn * s.robot.track / 2.0;
    switch (a) {
    case Action::Forward: return {d, d};
    case Action::Backward: return {-d, -d};
    case Action::TurnLeft: return {-arc, arc};
    case Action::TurnRight: return {arc, -arc};
    }
    return {0.0, 0.0};
}

WheelSpeeds wheel_targets_for_travel(const Scenario &s, WheelSpeeds target_travel,
                                     WheelSpeeds current)
{
    return {solve(s, target_travel.left, current.left),
            solve(s, target_travel.right, current.right)};
}

WheelSpeeds wheel_targets_for(const Scenario &s, Action a, WheelSpeeds current)
{
    return wheel_targets_for_travel(s, action_wheel_travel(s, a), current);
}

}  // namespace world
