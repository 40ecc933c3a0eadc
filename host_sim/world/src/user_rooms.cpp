// SPDX-License-Identifier: MIT
// dynaqpc world: seeded rooms drawn the way users draw their own (user_rooms.h).
#include "world/user_rooms.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "room_text.h"
#include "world/random.h"

namespace world {

using namespace room_text;

namespace {

constexpr double kPi = 3.14159265358979323846;

// ---- The rules, lengths in robot diagonals D (docs/scenarios.md, "Rooms like users' rooms") ----
constexpr double kFloorLong[2] = {11.0, 20.0};  // the floor's sides, any size in between
constexpr double kFloorShort[2] = {7.0, 12.0};
constexpr double kSonarFloorMax = 13.0;          // m: the sonar robot's rooms stay within its grid
constexpr double kThick[2] = {0.12, 0.4};        // a partition, as users build them: thin
constexpr double kDoor[2] = {1.15, 3.0};         // a doorway: from just over the diagonal
constexpr double kAtWall = 0.35;                 // share of doorways against a wall
constexpr double kPillarR[2] = {0.2, 0.6};
constexpr double kFurniture[2] = {0.8, 3.0};     // a box's sides
constexpr double kSpacing = 2.2;                 // partitions and lanes at least this far apart
// Along the walls: a piece stands against its wall or a slot's width off it (from the diagonal to
// about 1.6 of it: the 0.32-0.5 m slots beside a bed or a nightstand that new users' rooms relapsed
// in), square to the wall or turned a little (users' rooms: 10-35 degrees).
constexpr double kAgainstWall = 0.5;             // share of pieces touching their wall
constexpr double kSlot[2] = {1.0, 1.6};
constexpr double kAskew = 0.6;                   // share of pieces turned off their wall
constexpr double kAskewDeg[2] = {8.0, 30.0};

struct Drawn {
    double w = 0, h = 0;
    std::vector<Obstacle> parts;
    std::vector<std::string> what;
    std::vector<std::array<double, 4>> slots;  // along-walls: x0, x1, y0, y1 between a piece and its wall
    Goal goal;
    std::string shape;  // one line saying what was drawn
};

class UserDrawer {
public:
    UserDrawer(const Scenario &base, UserGoal goal, std::uint32_t seed, std::uint32_t draw)
        : base_(base), goal_(goal), rng_(seed, draw), d_(2.0 * robot_radius(base.robot))
    {
    }
    bool run(UserFamily family, Drawn *out);

private:
    double u(double lo, double hi) { return rng_.uniform(lo, hi); }
    double in_d(const double r[2]) { return u(r[0] * d_, r[1] * d_); }
    bool coin(double p) { return rng_.uniform() < p; }

    void floor(Drawn *o);
    // A partition across the floor at `at` along `axis` (0: a wall of constant x), from `from` to
    // `to` along the other axis, with a doorway of width `door` starting at `door_at` (none when
    // door is 0).
    void partition(Drawn *o, int axis, double at, double from, double to, double door, double door_at,
                   const std::string &what);
    double door_start(double from, double to, double door, int end);  // end: -1 low, 1 high, 0 any
    void pillars(Drawn *o, int n);
    void furniture(Drawn *o, int n);
    void along_walls(Drawn *o, int n);
    bool goal_in_a_slot(Drawn *o);
    bool goal_in(Drawn *o, double x0, double x1, double y0, double y1);

    const Scenario &base_;
    UserGoal goal_;
    RandomStream rng_;
    double d_;
};

void UserDrawer::floor(Drawn *o)
{
    double lo = kFloorLong[0] * d_, hi = kFloorLong[1] * d_;
    double slo = kFloorShort[0] * d_, shi = kFloorShort[1] * d_;
    if (base_.gps.enabled) {  // the sonar robot: within what its grid holds
        hi = std::min(hi, kSonarFloorMax);
        shi = std::min(shi, 0.8 * kSonarFloorMax);
    }
    const double a = std::round(u(lo, hi) * 20.0) / 20.0, b = std::round(u(slo, shi) * 20.0) / 20.0;
    if (coin(0.5)) {
        o->w = a, o->h = b;
    } else {
        o->w = b, o->h = a;
    }
}

double UserDrawer::door_start(double from, double to, double door, int end)
{
    if (end < 0) return from;
    if (end > 0) return to - door;
    return u(from + 0.5 * d_, to - door - 0.5 * d_);
}

void UserDrawer::partition(Drawn *o, int axis, double at, double from, double to, double door, double door_at,
                           const std::string &what)
{
    const double t = q_size(in_d(kThick));
    auto piece = [&](double a, double b) {
        if (b - a < 0.05) return;
        Obstacle p;
        p.shape = Obstacle::Shape::Box;
        const double mid = q_pos(0.5 * (a + b)), len = q_size(b - a);
        if (axis == 0) {
            p.cx = q_pos(at), p.cy = mid, p.w = t, p.h = len;
        } else {
            p.cx = mid, p.cy = q_pos(at), p.w = len, p.h = t;
        }
        o->parts.push_back(p);
        o->what.push_back(what);
    };
    if (door <= 0) {
        piece(from, to);
        return;
    }
    piece(from, door_at);
    piece(door_at + door, to);
}

void UserDrawer::pillars(Drawn *o, int n)
{
    for (int k = 0; k < n; k++) {
        Obstacle c;
        c.shape = Obstacle::Shape::Circle;
        c.radius = q_size(in_d(kPillarR));
        c.cx = q_pos(u(c.radius, o->w - c.radius));
        c.cy = q_pos(u(c.radius, o->h - c.radius));
        o->parts.push_back(c);
        o->what.push_back(c.radius < 0.35 * d_ ? "a bin" : "a round pillar");
    }
}

void UserDrawer::furniture(Drawn *o, int n)
{
    for (int k = 0; k < n; k++) {
        Obstacle b;
        b.shape = Obstacle::Shape::Box;
        b.w = q_size(in_d(kFurniture));
        b.h = q_size(in_d(kFurniture) * 0.6);
        const int deg = static_cast<int>(u(0.0, 90.0));
        b.angle = deg * kPi / 180.0;
        const double r = 0.5 * std::hypot(b.w, b.h);
        if (2 * r >= std::min(o->w, o->h)) continue;
        b.cx = q_pos(u(r, o->w - r));
        b.cy = q_pos(u(r, o->h - r));
        o->parts.push_back(b);
        o->what.push_back("furniture at " + std::to_string(deg) + " degrees");
    }
}

void UserDrawer::along_walls(Drawn *o, int n)
{
    for (int k = 0; k < n; k++) {
        const int wall = static_cast<int>(u(0.0, 4.0));  // 0 west, 1 east, 2 south, 3 north
        const bool across_x = wall < 2;                   // the wall is one of constant x
        Obstacle b;
        const bool round = coin(0.25);
        double deg = 0;
        if (round) {
            b.shape = Obstacle::Shape::Circle;
            b.radius = q_size(in_d(kPillarR));
        } else {
            b.shape = Obstacle::Shape::Box;
            b.w = q_size(in_d(kFurniture));  // along the wall: a wall of constant x has it along y
            b.h = q_size(in_d(kFurniture) * 0.5);
            deg = coin(kAskew) ? std::round(u(kAskewDeg[0], kAskewDeg[1])) * (coin(0.5) ? 1 : -1) : 0.0;
            b.angle = (across_x ? 90.0 + deg : deg) * kPi / 180.0;
        }
        double ex = 0, ey = 0;  // half extents along x and y
        extents(b, &ex, &ey);
        const double gap = coin(kAgainstWall) ? 0.0 : in_d(kSlot);
        const double side = across_x ? o->w : o->h, len = across_x ? o->h : o->w;
        const double half_in = across_x ? ex : ey, half_along = across_x ? ey : ex;
        if (2 * half_in + gap >= 0.5 * side || 2 * half_along >= len) continue;
        const double in = wall % 2 == 0 ? gap + half_in : side - gap - half_in;
        const double at = u(half_along, len - half_along);
        b.cx = q_pos(across_x ? in : at);
        b.cy = q_pos(across_x ? at : in);
        o->parts.push_back(b);
        if (gap > 0.0) {
            const double lo = at - half_along, hi = at + half_along;
            const double w0 = wall % 2 == 0 ? 0.0 : side - gap, w1 = wall % 2 == 0 ? gap : side;
            o->slots.push_back(across_x ? std::array<double, 4>{w0, w1, lo, hi} : std::array<double, 4>{lo, hi, w0, w1});
        }
        const char *where = gap == 0.0 ? "against" : "a slot off";
        o->what.push_back(std::string(round ? "a round piece " : "furniture ") + where + " the " +
                          (wall == 0 ? "west" : wall == 1 ? "east" : wall == 2 ? "south" : "north") + " wall" +
                          (deg != 0.0 ? ", turned " + std::to_string(static_cast<int>(deg)) + " degrees" : ""));
    }
}

// As users place a goal among furniture along the walls: behind a piece, in the slot it leaves to
// its wall (a bedroom's corner behind the nightstands).
bool UserDrawer::goal_in_a_slot(Drawn *o)
{
    const auto &b = o->slots[static_cast<std::size_t>(u(0.0, static_cast<double>(o->slots.size()))) % o->slots.size()];
    return goal_in(o, b[0], b[1], b[2], b[3]);
}

bool UserDrawer::goal_in(Drawn *o, double x0, double x1, double y0, double y1)
{
    // A circle's radius is drawn only for UserGoal::Circle: the base's rooms keep their draws.
    const double r = goal_ == UserGoal::Circle ? std::round(in_d(kUserGoalRadius) * 100.0) / 100.0 : base_.goal.radius;
    Scenario probe = base_;
    probe.arena_w = o->w;
    probe.arena_h = o->h;
    probe.obstacles = o->parts;
    for (int t = 0; t < 200; t++) {
        const double x = q_pos(u(std::max(x0, r), std::min(x1, o->w - r)));
        const double y = q_pos(u(std::max(y0, r), std::min(y1, o->h - r)));
        if (clearance(probe, x, y) >= r + 0.25 * d_) {
            o->goal.cx = x, o->goal.cy = y, o->goal.radius = r, o->goal.cells = goal_ == UserGoal::Base && base_.goal.cells;
            return true;
        }
    }
    return false;
}

bool UserDrawer::run(UserFamily family, Drawn *o)
{
    floor(o);
    const int along = o->w >= o->h ? 0 : 1;  // the long axis: partitions across it stand at x (0) or y (1)
    const double L = along == 0 ? o->w : o->h, S = along == 0 ? o->h : o->w;
    auto door = [&] { return std::min(in_d(kDoor), 0.6 * S); };
    auto end_of_door = [&] { return coin(kAtWall) ? (coin(0.5) ? -1 : 1) : 0; };
    // Goal boxes in (long, short) coordinates, turned into x, y.
    auto goal_lu = [&](double l0, double l1, double s0, double s1) {
        return along == 0 ? goal_in(o, l0, l1, s0, s1) : goal_in(o, s0, s1, l0, l1);
    };
    switch (family) {
    case UserFamily::Partitions: {
        const int n = 1 + static_cast<int>(u(0.0, 3.0));
        const double gap = L / (n + 1);
        if (gap < kSpacing * d_) return false;
        double last = 0;
        for (int k = 1; k <= n; k++) {
            const double at = k * gap + u(-0.25, 0.25) * gap;
            const double dw = door(), ds = door_start(0, S, dw, end_of_door());
            partition(o, along, at, 0, S, dw, ds, "a partition with a doorway");
            last = at;
        }
        o->shape = std::to_string(n) + " partition(s) across the floor";
        return goal_lu(last + 0.5 * d_, L, 0, S);
    }
    case UserFamily::SFloor: {
        // Two partitions along the long axis: three lanes joined at opposite ends.
        const double a = S / 3 + u(-0.08, 0.08) * S, b = 2 * S / 3 + u(-0.08, 0.08) * S;
        if (a < kSpacing * d_ || b - a < kSpacing * d_ || S - b < kSpacing * d_) return false;
        const double d1 = door(), d2 = door();
        const bool first_high = coin(0.5);
        partition(o, 1 - along, a, 0, L, d1, first_high ? L - d1 : 0, "the S's first partition");
        partition(o, 1 - along, b, 0, L, d2, first_high ? 0 : L - d2, "the S's second partition");
        o->shape = "an S of two partitions";
        return goal_lu(first_high ? L / 2 : 0, first_high ? L : L / 2, b + 0.5 * d_, S);
    }
    case UserFamily::UFloor: {
        // One partition from an end wall along the middle: the goal at the closed end of one arm.
        const double at = S / 2 + u(-0.1, 0.1) * S;
        if (at < kSpacing * d_ || S - at < kSpacing * d_) return false;
        const double len = u(0.6, 0.85) * L;
        const bool from_low = coin(0.5);
        partition(o, 1 - along, at, from_low ? 0 : L - len, from_low ? len : L, 0, 0, "the U's partition");
        o->shape = "a U around one partition";
        const double l0 = from_low ? 0 : L - 0.4 * len, l1 = from_low ? 0.4 * len : L;
        return coin(0.5) ? goal_lu(l0, l1, 0, at - 0.5 * d_) : goal_lu(l0, l1, at + 0.5 * d_, S);
    }
    case UserFamily::Pillars: {
        const double at = u(0.35, 0.65) * L, dw = door();
        partition(o, along, at, 0, S, dw, door_start(0, S, dw, end_of_door()), "a partition with a doorway");
        pillars(o, 3 + static_cast<int>(u(0.0, 4.0)));
        o->shape = "round pillars and bins, a partition";
        return coin(0.5) ? goal_lu(at + 0.5 * d_, L, 0, S) : goal_lu(0, at - 0.5 * d_, 0, S);
    }
    case UserFamily::Furniture: {
        furniture(o, 2 + static_cast<int>(u(0.0, 3.0)));
        pillars(o, static_cast<int>(u(0.0, 2.0)));
        if (coin(0.5)) {
            const double at = u(0.3, 0.7) * L, dw = door();
            partition(o, along, at, 0, S, dw, door_start(0, S, dw, end_of_door()), "a partition with a doorway");
        }
        o->shape = "furniture at an angle";
        return goal_lu(0, L, 0, S);
    }
    case UserFamily::AlongWalls: {
        along_walls(o, 4 + static_cast<int>(u(0.0, 4.0)));
        if (coin(0.5)) {
            const double at = u(0.3, 0.7) * L, dw = door();
            partition(o, along, at, 0, S, dw, door_start(0, S, dw, end_of_door()), "a partition with a doorway");
        }
        o->shape = "furniture along the walls";
        return !o->slots.empty() && coin(0.6) ? goal_in_a_slot(o) : goal_lu(0, L, 0, S);
    }
    }
    return false;
}

const char *const kNames[kUserFamilies] = {"partitions", "s-floor", "u-floor", "pillars", "furniture", "along-walls"};

}  // namespace

const char *user_family_name(UserFamily f)
{
    return kNames[static_cast<int>(f)];
}

bool user_family_from_name(const std::string &name, UserFamily *out)
{
    for (int k = 0; k < kUserFamilies; k++) {
        if (name == kNames[k]) {
            *out = static_cast<UserFamily>(k);
            return true;
        }
    }
    return false;
}

const char *user_goal_name(UserGoal g)
{
    return g == UserGoal::Circle ? "circle" : "base";
}

bool user_goal_from_name(const std::string &name, UserGoal *out)
{
    for (UserGoal g : {UserGoal::Base, UserGoal::Circle}) {
        if (name == user_goal_name(g)) {
            *out = g;
            return true;
        }
    }
    return false;
}

UserFamily user_family_of_index(std::uint32_t index)
{
    return static_cast<UserFamily>((index + kMixedUserFamilies - 1) % kMixedUserFamilies);
}

bool generate_user_room(std::string_view base_text, const std::string &base_label, const std::string &command,
                        std::uint32_t seed, std::uint32_t index, UserFamily family, UserGoal goal,
                        const std::string &file, Room *out, std::string *error)
{
    Scenario base;
    if (!parse_scenario(base_text, base_label, &base, error)) return false;
    std::string before0, after0;
    base_without_layout(base_text, &before0, &after0);
    const std::uint32_t rs = room_seed(room_seed(seed, index), 0x5000u + static_cast<std::uint32_t>(family));
    std::string last_problem;
    for (std::uint32_t draw = 0; draw < kMaxRoomDraws; draw++) {
        UserDrawer dr(base, goal, rs, draw);
        Drawn d;
        if (!dr.run(family, &d)) {
            last_problem = std::string("the ") + user_family_name(family) + " does not fit this draw";
            continue;
        }
        std::string before = replace_key(before0, "arena", with_comment("arena " + num(d.w) + " " + num(d.h),
                                                                        "m; a floor of the room's own size"));
        std::string after = replace_key(
            after0, "encode",
            with_comment("encode auto heading " + std::to_string(base.encoding.heading_bits) + " sensor " +
                             std::to_string(base.encoding.sensor_bits),
                         "the cells fitted to the room (docs/agent.md)"));
        if (!base.cricket.beacons.empty()) after = replace_key(after, "beacon", beacon_lines(base, d.w, d.h));
        std::string layout = "# The layout: " + d.shape + " (docs/scenarios.md, \"Rooms like users' rooms\").\n";
        for (std::size_t i = 0; i < d.parts.size(); i++) {
            const Obstacle &o = d.parts[i];
            std::string line = o.shape == Obstacle::Shape::Circle
                                   ? "obstacle circle " + num(o.cx) + " " + num(o.cy) + " " + num(o.radius)
                                   : "obstacle box " + num(o.cx) + " " + num(o.cy) + " " + num(o.w) + " " + num(o.h);
            if (o.shape == Obstacle::Shape::Box && o.angle != 0.0) {
                line += " " + std::to_string(static_cast<int>(std::lround(o.angle * 180.0 / kPi)));
            }
            layout += with_comment(line, d.what[i]);
        }
        const Goal &g = d.goal;
        layout += with_comment("goal " + num(g.cx) + " " + num(g.cy) + " " + num(g.radius) + (g.cells ? " cells" : ""),
                               g.cells ? "the cells whose centres are inside" : "reached when the centre is inside");
        char head[512];
        std::snprintf(head, sizeof head,
                      "# %s: a generated room like a user's (%s, floor %s x %s m); regenerate it rather than edit\n"
                      "# it (docs/scenarios.md, \"Rooms like users' rooms\").\n# %s: room %u, draw %u.\n"
                      "# The layout, the arena, the encoding (encode auto)%s are new: every other line is %s's.\n\n",
                      stem(file).c_str(), user_family_name(family), num(d.w).c_str(), num(d.h).c_str(),
                      command.c_str(), index, draw, base.cricket.beacons.empty() ? "" : " and the beacons",
                      base_label.c_str());
        Room room;
        room.text = head + before + "\n" + layout + after;
        if (!check_drawn_room(&room, file, &last_problem)) continue;
        if (room.path.longest < 0) {
            last_problem = std::to_string(room.path.stranded) + " start states cannot reach the goal on the state grid";
            continue;
        }
        room.obstacles = static_cast<int>(d.parts.size());
        room.draw = draw;
        room.family = user_family_name(family);
        *out = std::move(room);
        return true;
    }
    if (error != nullptr) {
        *error = file + ": no room in " + std::to_string(kMaxRoomDraws) + " draws (the last: " + last_problem + ")";
    }
    return false;
}

}  // namespace world
