// SPDX-License-Identifier: MIT
// dynaqpc world: the arena and the robot in Box2D 2.4.1.
//
// Top-down, zero gravity: the floor's friction is modelled per wheel, not by Box2D. Each physics
// step, before b2World::Step:
//  1. the wheel speed controller slews its command from the wheel's measured speed toward the
//     target by at most max_accel * dt;
//  2. each wheel cancels the body's sideways velocity at its contact point with an impulse (ideal
//     tyres that never skid sideways). Both wheels sit on the axle through the centre of mass,
//     so the sideways velocity is the same at both and the impulses apply no torque;
//  3. each wheel pushes along the body's x with the force that brings its contact point's speed
//     to the command in one step (a stiff speed loop), clamped to what max_accel needs. Left and
//     right forces are solved together, because each one moves both wheels' contact points.
// Free driving then tracks the command exactly (speed of the left contact point v - w*h, right
// v + w*h, h = track/2), straight driving has no drift and the turn rate is (v_r - v_l) / track.
// In contact, Box2D's solver stops the body; the clamped force is the motor's stall force.
#include <algorithm>
#include <cmath>

#include <box2d/box2d.h>

#include "world/random.h"
#include "world/world.h"
#include "fw/fw_util.h"

namespace world {

namespace {

constexpr double kPi = FW_PI;
// A contact the solver resisted with less than this impulse (N*s) is not a push: Box2D leaves
// round-off sized impulses on resting contacts.
constexpr float kPushImpulse = 1e-5f;
constexpr double kGravity = 9.81;  // m/s^2, for the tyres' friction

enum Stream : std::uint32_t { kStart = 1, kRange = 2, kGyro = 3, kGps = 4, kActuation = 6, kGyroScale = 7 };  // 5: Cricket

// Sets the bump flag when the robot begins touching anything, or when the solver has to push
// the robot back (it drove or turned into something). PostSolve reports each touching contact
// of every sub-step with the impulses the solver applied.
class BumpListener : public b2ContactListener {
public:
    b2Fixture *robot = nullptr;
    bool bumped = false;

    void BeginContact(b2Contact *c) override
    {
        if (c->GetFixtureA() == robot || c->GetFixtureB() == robot) bumped = true;
    }
    void PostSolve(b2Contact *c, const b2ContactImpulse *impulse) override
    {
        if (c->GetFixtureA() != robot && c->GetFixtureB() != robot) return;
        for (int i = 0; i < impulse->count; ++i) {
            if (impulse->normalImpulses[i] > kPushImpulse) bumped = true;
        }
    }
};

// The closest fixture along a ray, skipping the robot's own body.
class ClosestHit : public b2RayCastCallback {
public:
    explicit ClosestHit(const b2Fixture *skip) : skip_(skip) {}
    float fraction = 1.0f;
    bool hit = false;

    float ReportFixture(b2Fixture *fixture, const b2Vec2 &, const b2Vec2 &, float f) override
    {
        if (fixture == skip_) return -1.0f;  // ignore and go on
        hit = true;
        fraction = f;
        return f;  // clip the ray: only closer hits remain of interest
    }

private:
    const b2Fixture *skip_;
};

}  // namespace

double wrap_angle(double a)
{
    a = std::fmod(a, 2.0 * kPi);
    if (a <= -kPi) a += 2.0 * kPi;
    if (a > kPi) a -= 2.0 * kPi;
    return a;
}

struct World::Impl {
    Scenario sc;
    // A pointer so that a changed room (set_obstacles) is a fresh Box2D world, built as the
    // constructor builds one: the same contacts in the same order as a World made from the
    // changed scenario.
    std::unique_ptr<b2World> world = std::make_unique<b2World>(b2Vec2(0.0f, 0.0f));
    b2Body *robot = nullptr;
    b2Body *walls = nullptr;
    b2Fixture *robot_fixture = nullptr;
    BumpListener bump;
    RandomStream start_rng, range_rng, gyro_rng, gps_rng;
    // `actuation`: its own stream, so that an exact robot (no line) draws nothing new and a
    // wheel's gain, drawn once here, is the same robot for the World's whole life.
    RandomStream actuation_rng;
    double gain_l = 1.0, gain_r = 1.0;
    double gyro_scale = 1.0;  // `gyro scale`: drawn once, from a stream of its own
    double target_l = 0.0, target_r = 0.0;
    double half_track = 0.0;
    double mass = 0.0, inertia = 0.0, max_force = 0.0;
    double time = 0.0;
    std::uint64_t steps = 0;

    Impl(const Scenario &s, std::uint32_t seed)
        : sc(s), start_rng(seed, kStart), range_rng(seed, kRange), gyro_rng(seed, kGyro),
          gps_rng(seed, kGps), actuation_rng(seed, kActuation)
    {
        if (sc.actuation.enabled) {
            const double g = sc.actuation.gain;
            gain_l = actuation_rng.uniform(1.0 - g, 1.0 + g);
            gain_r = actuation_rng.uniform(1.0 - g, 1.0 + g);
        }
        if (sc.gyro.scale > 0.0) {
            RandomStream scale_rng(seed, kGyroScale);
            gyro_scale = scale_rng.uniform(1.0 - sc.gyro.scale, 1.0 + sc.gyro.scale);
        }
        build();
    }

    void build();
    void build_obstacles();
    void drive();
    void ranges(float out[]) const;
};

void World::Impl::build()
{
    world->SetAllowSleeping(false);
    world->SetContactListener(&bump);

    // Walls: four boxes outside the arena, their inner faces on its edges.
    const float w = static_cast<float>(sc.arena_w), h = static_cast<float>(sc.arena_h);
    const float t = 1.0f;  // thickness
    b2BodyDef static_def;
    walls = world->CreateBody(&static_def);
    b2PolygonShape box;
    box.SetAsBox(t / 2, h / 2 + t, b2Vec2(-t / 2, h / 2), 0.0f);
    walls->CreateFixture(&box, 0.0f);
    box.SetAsBox(t / 2, h / 2 + t, b2Vec2(w + t / 2, h / 2), 0.0f);
    walls->CreateFixture(&box, 0.0f);
    box.SetAsBox(w / 2 + t, t / 2, b2Vec2(w / 2, -t / 2), 0.0f);
    walls->CreateFixture(&box, 0.0f);
    box.SetAsBox(w / 2 + t, t / 2, b2Vec2(w / 2, h + t / 2), 0.0f);
    walls->CreateFixture(&box, 0.0f);

    build_obstacles();

    const RobotSpec &r = sc.robot;
    b2BodyDef def;
    def.type = b2_dynamicBody;
    def.position.Set(w / 2, h / 2);
    def.allowSleep = false;
    robot = world->CreateBody(&def);
    b2PolygonShape body;
    body.SetAsBox(static_cast<float>(r.length / 2), static_cast<float>(r.width / 2));
    b2FixtureDef fd;
    fd.shape = &body;
    fd.density = static_cast<float>(r.mass / (r.length * r.width));
    fd.friction = static_cast<float>(r.friction);
    fd.restitution = 0.0f;
    robot_fixture = robot->CreateFixture(&fd);
    bump.robot = robot_fixture;

    half_track = r.track / 2.0;
    mass = robot->GetMass();
    inertia = robot->GetInertia();
    // Stall force per wheel: twice what the steepest allowed change of speed needs, straight
    // (m a / 2 per wheel) or turning on the spot (I a / (2 h^2) per wheel).
    max_force = 2.0 * r.max_accel *
                std::max(mass / 2.0, inertia / (2.0 * half_track * half_track));
}

void World::Impl::build_obstacles()
{
    for (const Obstacle &o : sc.obstacles) {
        if (o.shape == Obstacle::Shape::Box) {
            b2PolygonShape p;
            p.SetAsBox(static_cast<float>(o.w / 2), static_cast<float>(o.h / 2),
                       b2Vec2(static_cast<float>(o.cx), static_cast<float>(o.cy)),
                       static_cast<float>(o.angle));
            walls->CreateFixture(&p, 0.0f);
        } else {
            b2CircleShape c;
            c.m_p.Set(static_cast<float>(o.cx), static_cast<float>(o.cy));
            c.m_radius = static_cast<float>(o.radius);
            walls->CreateFixture(&c, 0.0f);
        }
    }
}

void World::Impl::drive()
{
    const double dt = sc.timing.physics_dt;
    const b2Rot q = robot->GetTransform().q;
    const b2Vec2 fwd = q.GetXAxis(), side = q.GetYAxis();
    const b2Vec2 v = robot->GetLinearVelocity();
    const double w = robot->GetAngularVelocity();
    const double vf = b2Dot(v, fwd);
    const double speed_l = vf - w * half_track, speed_r = vf + w * half_track;

    // 1. The command slews from the wheel's measured speed (so a wheel stalled by a wall starts
    //    again from 0, with no wound-up command pushing on).
    const double dv = sc.robot.max_accel * dt;
    const double cmd_l = speed_l + std::clamp(target_l - speed_l, -dv, dv);
    const double cmd_r = speed_r + std::clamp(target_r - speed_r, -dv, dv);

    // 2. No sideways slip: cancel the sideways velocity (both wheels' share at once); with
    //    `actuation slip_mu`, only as far as the tyres' friction allows (the rest slides).
    const float lateral = b2Dot(v, side);
    double grip = -mass * lateral;
    if (sc.actuation.slip_mu > 0.0) {
        const double most = sc.actuation.slip_mu * mass * kGravity * dt;
        grip = std::clamp(grip, -most, most);
    }
    robot->ApplyLinearImpulseToCenter(static_cast<float>(grip) * side, true);

    // 3. Forces that bring both contact points to the command in one step.
    const double err_l = cmd_l - speed_l;
    const double err_r = cmd_r - speed_r;
    const double f_sum = mass * 0.5 * (err_l + err_r) / dt;                  // F_l + F_r
    const double f_diff = inertia * (err_r - err_l) /                         // F_r - F_l
                          (2.0 * half_track * half_track * dt);
    const double f_l = std::clamp(0.5 * (f_sum - f_diff), -max_force, max_force);
    const double f_r = std::clamp(0.5 * (f_sum + f_diff), -max_force, max_force);
    const float ht = static_cast<float>(half_track);
    robot->ApplyForce(static_cast<float>(f_l) * fwd, robot->GetWorldPoint(b2Vec2(0.0f, ht)), true);
    robot->ApplyForce(static_cast<float>(f_r) * fwd, robot->GetWorldPoint(b2Vec2(0.0f, -ht)), true);
}

void World::Impl::ranges(float out[]) const
{
    const RangerSpec &g = sc.ranger;
    const b2Transform xf = robot->GetTransform();
    const float max_range = static_cast<float>(g.max_range);
    const float min_range = static_cast<float>(g.min_range);
    for (std::size_t i = 0; i < g.rays.size(); ++i) {
        const Ray &ray = g.rays[i];
        const b2Vec2 p1 = b2Mul(xf, b2Vec2(static_cast<float>(ray.x), static_cast<float>(ray.y)));
        const b2Vec2 dir = b2Mul(xf.q, b2Vec2(static_cast<float>(std::cos(ray.angle)),
                                              static_cast<float>(std::sin(ray.angle))));
        const b2Vec2 p2 = p1 + max_range * dir;
        ClosestHit hit(robot_fixture);
        world->RayCast(&hit, p1, p2);
        if (!hit.hit) {
            out[i] = max_range;
        } else {
            out[i] = std::max(min_range, hit.fraction * max_range);
        }
    }
}

World::World(const Scenario &scenario, std::uint32_t seed)
    : impl_(std::make_unique<Impl>(scenario, seed))
{
}

World::~World() = default;
World::World(World &&) noexcept = default;
World &World::operator=(World &&) noexcept = default;

const Scenario &World::scenario() const { return impl_->sc; }

Pose World::sample_start_pose()
{
    const Scenario &s = impl_->sc;
    RandomStream &rng = impl_->start_rng;
    Pose p;
    bool found = false;
    for (int tries = 0; tries < 100000 && !found; ++tries) {
        p.x = rng.uniform(0.0, s.arena_w);
        p.y = rng.uniform(0.0, s.arena_h);
        found = start_position_ok(s, p.x, p.y);
    }
    if (!found) {
        // Nearly no free space: scan the parser's start grid from a random cell (the parser
        // refused the file unless some cell of that grid is free).
        const double step = start_grid_step(s);
        const long nx = static_cast<long>(std::ceil(s.arena_w / step));
        const long ny = static_cast<long>(std::ceil(s.arena_h / step));
        const long n = nx * ny;
        const long first = static_cast<long>(rng.uniform() * static_cast<double>(n));
        for (long k = 0; k < n && !found; ++k) {
            const long c = (first + k) % n;
            p.x = step / 2 + step * static_cast<double>(c % nx);
            p.y = step / 2 + step * static_cast<double>(c / nx);
            found = p.x < s.arena_w && p.y < s.arena_h && start_position_ok(s, p.x, p.y);
        }
    }
    p.heading = rng.uniform(-kPi, kPi);
    return p;
}

void World::reset(const Pose &pose)
{
    Impl &m = *impl_;
    m.robot->SetTransform(b2Vec2(static_cast<float>(pose.x), static_cast<float>(pose.y)),
                          static_cast<float>(pose.heading));
    m.robot->SetLinearVelocity(b2Vec2(0.0f, 0.0f));
    m.robot->SetAngularVelocity(0.0f);
    m.target_l = m.target_r = 0.0;
    m.bump.bumped = false;
}

void World::set_obstacles(const std::vector<Obstacle> &obstacles)
{
    Impl &m = *impl_;
    m.sc.obstacles = obstacles;
    m.world = std::make_unique<b2World>(b2Vec2(0.0f, 0.0f));  // the old bodies go with the old world
    m.bump.bumped = false;
    m.target_l = m.target_r = 0.0;
    m.build();
}

void World::set_wheel_targets(double left, double right)
{
    Impl &m = *impl_;
    const ActuationSpec &a = m.sc.actuation;
    if (a.enabled) {
        // The motor runs at its gain times the command, each command a little off.
        left *= m.gain_l;
        right *= m.gain_r;
        if (a.noise > 0.0) {
            left *= 1.0 + a.noise * m.actuation_rng.normal();
            right *= 1.0 + a.noise * m.actuation_rng.normal();
        }
    }
    if (a.deadband > 0.0) {
        // Below its breakaway the motor does not turn.
        if (std::fabs(left) < a.deadband) left = 0.0;
        if (std::fabs(right) < a.deadband) right = 0.0;
    }
    const double vmax = m.sc.robot.max_speed;
    impl_->target_l = std::clamp(left, -vmax, vmax);
    impl_->target_r = std::clamp(right, -vmax, vmax);
}

WheelSpeeds World::wheel_targets() const { return {impl_->target_l, impl_->target_r}; }

void World::step()
{
    Impl &m = *impl_;
    m.drive();
    m.world->Step(static_cast<float>(m.sc.timing.physics_dt), m.sc.solver.velocity_iterations,
                 m.sc.solver.position_iterations);
    ++m.steps;
    m.time = static_cast<double>(m.steps) * m.sc.timing.physics_dt;
}

void World::step_period()
{
    for (int i = 0; i < impl_->sc.timing.substeps; ++i) step();
}

Pose World::pose() const
{
    const b2Body *b = impl_->robot;
    return {b->GetPosition().x, b->GetPosition().y, wrap_angle(b->GetAngle())};
}

WheelSpeeds World::wheel_speeds() const
{
    const Impl &m = *impl_;
    const double vf = b2Dot(m.robot->GetLinearVelocity(), m.robot->GetTransform().q.GetXAxis());
    const double w = m.robot->GetAngularVelocity();
    return {vf - w * m.half_track, vf + w * m.half_track};
}

double World::yaw_rate() const { return impl_->robot->GetAngularVelocity(); }

WheelSpeeds World::wheel_gains() const { return {impl_->gain_l, impl_->gain_r}; }

bool World::bumped() const { return impl_->bump.bumped; }
void World::clear_bump() { impl_->bump.bumped = false; }

bool World::in_goal() const
{
    const Pose p = pose();
    return world::in_goal(impl_->sc, p.x, p.y);
}

double World::time_s() const { return impl_->time; }
std::uint64_t World::steps() const { return impl_->steps; }

int World::ray_count() const { return static_cast<int>(impl_->sc.ranger.rays.size()); }

void World::true_ranges(float out[]) const { impl_->ranges(out); }

void World::range_readings(float out[])
{
    Impl &m = *impl_;
    m.ranges(out);
    const RangerSpec &g = m.sc.ranger;
    const float max_range = static_cast<float>(g.max_range);
    // The largest float below max_range: a noisy hit must not read as "nothing there".
    const float below_max = std::nextafter(max_range, 0.0f);
    for (std::size_t i = 0; i < g.rays.size(); ++i) {
        if (out[i] >= max_range) continue;  // nothing within range: exact, no noise
        const double sd = g.noise_sd + g.noise_prop * out[i];
        if (sd <= 0.0) continue;
        const double noisy = out[i] + sd * m.range_rng.normal();
        out[i] = std::clamp(static_cast<float>(noisy), static_cast<float>(g.min_range), below_max);
    }
}

double World::gyro_rate()
{
    const GyroSpec &g = impl_->sc.gyro;
    double rate = g.scale > 0.0 ? yaw_rate() * impl_->gyro_scale + g.bias : yaw_rate() + g.bias;
    if (g.noise_sd > 0.0) rate += g.noise_sd * impl_->gyro_rng.normal();
    return rate;
}

Pose World::gps_pose()
{
    Pose p = pose();
    const GpsSpec &g = impl_->sc.gps;
    if (!g.enabled) return p;
    RandomStream &rng = impl_->gps_rng;
    p.x += g.xy_sd * rng.normal();
    p.y += g.xy_sd * rng.normal();
    p.heading = wrap_angle(p.heading + g.heading_sd * rng.normal());
    return p;
}

}  // namespace world
