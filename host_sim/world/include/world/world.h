// SPDX-License-Identifier: MIT
// dynaqpc world: the simulated arena and robot (Box2D 2.4 inside; none of its types out here).
//
// One World is one arena with one differential-drive robot. It is driven in fixed physics steps
// of scenario.timing.physics_dt (step()), a control period being timing.substeps of them
// (step_period()). Every random draw (start poses, sensor noise) comes from the firmware's PRNG
// seeded from the World's seed, one stream per purpose: the same scenario, seed and sequence of
// calls give bit-identical poses and readings on the same binary.
//
// Not thread-safe; one World per thread. Movable, not copyable.
#ifndef WORLD_WORLD_H
#define WORLD_WORLD_H

#include <cstdint>
#include <memory>
#include <vector>

#include "world/scenario.h"

namespace world {

struct Pose {
    double x = 0.0, y = 0.0;  ///< m, arena frame
    double heading = 0.0;     ///< rad in (-pi, pi], counter-clockwise from +x
};

struct WheelSpeeds {
    double left = 0.0, right = 0.0;  ///< m/s of each wheel's contact point along the body's x
};

class World {
public:
    /// Builds the arena (walls, obstacles) and the robot, at rest at the arena's centre until the
    /// first reset(). `scenario` must come from parse_scenario/load_scenario (it is copied).
    World(const Scenario &scenario, std::uint32_t seed);
    ~World();
    World(World &&) noexcept;
    World &operator=(World &&) noexcept;
    World(const World &) = delete;
    World &operator=(const World &) = delete;

    const Scenario &scenario() const;

    /// A start pose: position uniform over the positions where start_position_ok() holds (the
    /// robot's circumscribed circle plus the start margin clear of walls and obstacles, centre
    /// outside the goal), heading uniform in [-pi, pi). From the "start" PRNG stream.
    Pose sample_start_pose();

    /// Puts the robot at `pose`, at rest, wheel targets 0, bump flag cleared. Time keeps running
    /// (time_s() is not reset). The pose is not checked: use start_position_ok() for that.
    void reset(const Pose &pose);

    /// Replaces the arena's obstacles with `obstacles` (a room that changes during a run: a box
    /// appears, a door closes or opens). The physics is rebuilt as the constructor builds it (the
    /// robot at rest at the arena's centre until the next reset()); time and every random stream
    /// go on as they were, so a change before the first episode gives the same run as a World
    /// made from the changed scenario. Start poses and in_goal() follow the new obstacles. Call
    /// it between episodes, before reset(). The caller checks the change
    /// (layout_change_problem()); at most kMaxObstacles.
    void set_obstacles(const std::vector<Obstacle> &obstacles);

    /// Wheel speed targets, m/s, each clamped to +-robot.max_speed. The wheel controller slews
    /// its command toward them at robot.max_accel and drives each wheel with a force (limited to
    /// what max_accel needs) so the wheel's speed follows the command. With the scenario's
    /// `actuation` line each target is first multiplied by its wheel's gain (drawn once, at
    /// construction) and by 1 + noise x N(0, 1) (drawn per call and wheel, "actuation" stream);
    /// wheel_targets() returns what the wheels then aim at.
    void set_wheel_targets(double left, double right);
    WheelSpeeds wheel_targets() const;

    /// One physics step of timing.physics_dt.
    void step();
    /// timing.substeps physics steps: one control period.
    void step_period();

    Pose pose() const;
    /// Measured speeds of the wheels' contact points along the body's x, m/s (what encoders see:
    /// 0 when the robot is held by a wall).
    WheelSpeeds wheel_speeds() const;
    /// Body yaw rate, rad/s, true value.
    double yaw_rate() const;
    /// The wheels' gains of `actuation gain` (1, 1 for an exact robot).
    WheelSpeeds wheel_gains() const;

    /// True if, since the last clear_bump() or reset(), the robot began touching a wall or an
    /// obstacle or pushed against one (a contact that the solver had to resist). Backing away
    /// from a touched wall is not a bump. The contact itself stops the robot; the flag is all the
    /// firmware gets.
    bool bumped() const;
    void clear_bump();

    /// True if the robot's centre is inside the goal circle.
    bool in_goal() const;

    /// Simulated seconds since construction (physics steps x physics_dt).
    double time_s() const;
    std::uint64_t steps() const;

    /// Number of range rays = scenario.ranger.rays.size().
    int ray_count() const;
    /// One reading per ray into out[0 .. ray_count()): the closest hit along each ray from its
    /// mount point, never the robot itself; below min_range reads min_range; nothing within
    /// max_range reads exactly max_range (no noise); otherwise Gaussian noise of sd
    /// noise_sd + noise_prop * range, clamped to [min_range, max_range). Draws noise from the
    /// "range" stream. Call it once per control period.
    void range_readings(float out[]);
    /// The same without noise (for tests and viewers; draws nothing).
    void true_ranges(float out[]) const;

    /// Gyro: yaw_rate() + gyro.bias + Gaussian noise of gyro.noise_sd, rad/s ("gyro" stream).
    double gyro_rate();
    /// GPS: pose() with Gaussian noise of gps.xy_sd per axis and gps.heading_sd on the heading
    /// (wrapped to (-pi, pi]); the true pose when the scenario has no `gps` line ("gps" stream).
    Pose gps_pose();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// Wraps an angle to (-pi, pi].
double wrap_angle(double a);

}  // namespace world

#endif  // WORLD_WORLD_H
