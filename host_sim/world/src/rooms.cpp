// SPDX-License-Identifier: MIT
// dynaqpc world: seeded random rooms, drawn (the passage check: room_check.cpp; the families'
// and floors' names: room_names.cpp).
//
// Sizes are in units of the robot's diagonal D, so that one set of rules serves a 25 cm lab
// robot in a 4.3 x 3.2 m room and a 60 cm Pioneer in an 8 x 8 m one (both rooms are about 100-130
// D^2). The generator leaves every passage at least kGap D wide by construction: each new piece
// keeps kGap D from every other piece and from the outer walls, or touches an outer wall (walls,
// boxes pushed against a wall). check_passages() then proves the weaker promise the rooms make,
// that every start reaches the goal through passages at least D wide, on the parsed file.
#include "world/rooms.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <limits>
#include <sstream>
#include <vector>

#include "world/random.h"

#include "room_text.h"

namespace world {

using namespace room_text;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

// ---- The layout's rules (docs/scenarios.md, "Generated rooms"), lengths in robot diagonals ----
constexpr double kGap = 1.5;              // passages the generator leaves, at least
constexpr double kGoalClear = 0.5;        // obstacles keep this far from the goal region
constexpr double kWallThick[2] = {0.25, 0.4};
constexpr double kDoor[2] = {1.5, 2.5};   // a door's width
constexpr double kSpur[2] = {0.3, 0.7};   // a wall without a door: this fraction of its span
constexpr double kBoxSide[2] = {0.5, 3.0};
constexpr double kCircleR[2] = {0.3, 1.0};
constexpr double kLArm[2] = {1.5, 3.0};
constexpr double kLThick[2] = {0.3, 0.6};
constexpr int kObstacles[2] = {3, 6};     // obstacles per room, uniform
constexpr double kWallsWeight[3] = {0.1, 0.5, 0.4};  // 0, 1 or 2 interior walls
constexpr int kPlaceTries = 300;          // positions tried per piece before it is left out
constexpr int kGoalTries = 1000;

constexpr double kTouch = 1e-6;  // m: a piece this close to an outer wall touches it

// ---- Far-goal rooms (docs/scenarios.md, "Far-goal rooms"), lengths in robot diagonals ----
constexpr double kHallWidth[2] = {3.0, 5.0};   // a hall narrower than its floor: the rest is solid
constexpr double kPillarEvery[2] = {3.0, 5.0}; // along a hall
constexpr double kPillarR[2] = {0.3, 0.5};
constexpr double kButtress[2] = {0.5, 0.8};    // a pillar against a hall's wall: its depth
constexpr double kFarDoor[2] = {1.6, 2.5};     // doors and the gaps of partitions
constexpr double kPocket[2] = {1.6, 2.6};      // a cul-de-sac's inside width
constexpr double kPocketArm[2] = {2.5, 4.5};   // and depth
constexpr double kBehind[2] = {0.5, 0.9};      // its back wall's distance from the goal
constexpr double kSide = 1.6;                  // a passage beside a cul-de-sac, at least
constexpr double kLane = 1.8;                  // a serpentine lane, at least
constexpr int kMaxPartitions = 4;
constexpr double kOpenDensity[2] = {12.0, 18.0};  // D^2 of an open floor per obstacle
constexpr int kCulDeSacClutter[2] = {2, 4};



// A box's corners, counter-clockwise.
std::array<std::pair<double, double>, 4> corners(const Obstacle &o)
{
    const double c = std::cos(o.angle), s = std::sin(o.angle);
    const double lx[4] = {-o.w / 2, o.w / 2, o.w / 2, -o.w / 2};
    const double ly[4] = {-o.h / 2, -o.h / 2, o.h / 2, o.h / 2};
    std::array<std::pair<double, double>, 4> out;
    for (int i = 0; i < 4; i++) out[i] = {o.cx + c * lx[i] - s * ly[i], o.cy + s * lx[i] + c * ly[i]};
    return out;
}

// Whether two boxes overlap: no separating axis among their edges' normals.
bool boxes_overlap(const Obstacle &a, const Obstacle &b)
{
    const auto ca = corners(a), cb = corners(b);
    for (const Obstacle *o : {&a, &b}) {
        for (double ang : {o->angle, o->angle + kPi / 2}) {
            const double ux = std::cos(ang), uy = std::sin(ang);
            double amin = 1e300, amax = -1e300, bmin = 1e300, bmax = -1e300;
            for (const auto &p : ca) {
                amin = std::min(amin, p.first * ux + p.second * uy);
                amax = std::max(amax, p.first * ux + p.second * uy);
            }
            for (const auto &p : cb) {
                bmin = std::min(bmin, p.first * ux + p.second * uy);
                bmax = std::max(bmax, p.first * ux + p.second * uy);
            }
            if (amax < bmin || bmax < amin) return false;
        }
    }
    return true;
}

// A circle of radius r at (cx, cy).
Obstacle circle(double cx, double cy, double r)
{
    Obstacle c;
    c.shape = Obstacle::Shape::Circle;
    c.cx = cx;
    c.cy = cy;
    c.radius = r;
    return c;
}

// Distance between two obstacles' surfaces, exact; negative when they overlap. Two boxes apart
// are nearest at a corner of one (convex polygons), so their corners' distances to the other say
// it; overlapping boxes need not have a corner inside the other (a cross), so that is tested
// first.
double gap_between(const Obstacle &a, const Obstacle &b)
{
    using Shape = Obstacle::Shape;
    if (a.shape == Shape::Circle && b.shape == Shape::Circle) {
        return std::hypot(a.cx - b.cx, a.cy - b.cy) - a.radius - b.radius;
    }
    if (a.shape == Shape::Circle) return obstacle_distance(b, a.cx, a.cy) - a.radius;
    if (b.shape == Shape::Circle) return obstacle_distance(a, b.cx, b.cy) - b.radius;
    if (boxes_overlap(a, b)) return -1.0;
    double d = std::numeric_limits<double>::infinity();
    for (const auto &p : corners(a)) d = std::min(d, obstacle_distance(b, p.first, p.second));
    for (const auto &p : corners(b)) d = std::min(d, obstacle_distance(a, p.first, p.second));
    return d;
}

Obstacle box(double cx, double cy, double w, double h, double angle_deg = 0.0)
{
    Obstacle o;
    o.shape = Obstacle::Shape::Box;
    o.cx = q_pos(cx);
    o.cy = q_pos(cy);
    o.w = w;
    o.h = h;
    o.angle = angle_deg * kDeg;
    return o;
}

// One thing drawn: an interior wall (one or two boxes), or an obstacle (one box or circle, or the
// two boxes of an L).
struct Piece {
    std::vector<Obstacle> parts;
    std::vector<int> angle_deg;  // per part, as the file writes it
    std::string what;            // the comment on its lines
    bool may_touch_walls = false;
};

class Drawer {
public:
    Drawer(const Scenario &base, std::uint32_t seed, std::uint32_t draw)
        : base_(base), rng_(seed, draw), d_(2.0 * robot_radius(base.robot))
    {
    }

    // Draws the whole layout into `pieces` and `goal`.
    void run();
    // Draws a far-goal room of `family`; false when this draw cannot hold one (draw again).
    bool run_far(FarFamily family);

    Goal goal;
    std::vector<Piece> pieces;
    int walls = 0, obstacles = 0;

private:
    double u(double lo, double hi) { return rng_.uniform(lo, hi); }
    int below(int n) { return std::min(n - 1, static_cast<int>(rng_.uniform() * n)); }
    double in_d(const double range[2]) { return u(range[0] * d_, range[1] * d_); }

    void draw_goal();
    bool draw_wall(Piece *p);
    void draw_obstacle(Piece *p);
    bool fits(const Piece &p) const;

    // Far rooms are drawn in a frame of their own: u along the floor's longer side (a square
    // floor: either), v across it, both mirrored at random; the families put the goal at u = L.
    void set_frame();
    void to_xy(double u, double v, double *x, double *y) const;
    Obstacle box_uv(double u0, double u1, double v0, double v1) const;
    bool goal_near_uv(double u, double v, double u0, double u1, double v0, double v1);
    void goal_extent_uv(double *u0, double *u1, double *v0, double *v1) const;
    bool add_structure(Piece p, bool wall);
    bool far_hall();
    bool far_open();
    bool far_culdesac();
    bool far_serpentine();
    void add_obstacles(int n);

    const Scenario &base_;
    RandomStream rng_;
    double d_;  // the robot's diagonal, m
    std::vector<Obstacle> goal_region_;
    bool swap_ = false, flip_u_ = false, flip_v_ = false;
    double L_ = 0, S_ = 0;  // the frame's long and short sides, m
};

void Drawer::draw_goal()
{
    const double w = base_.arena_w, h = base_.arena_h;
    goal = base_.goal;
    if (!base_.goal.cells) {  // a circle of the base's radius, off the walls by a diagonal
        const double r = base_.goal.radius;
        const double m = std::min({r + d_, w / 2, h / 2});
        goal.cx = q_pos(u(m, w - m));
        goal.cy = q_pos(u(m, h - m));
        goal_region_.assign(1, circle(goal.cx, goal.cy, r));
        return;
    }
    // Two neighbouring cells of the state grid, like the base's: a circle through the midpoint
    // of their centres, a tenth of the smaller cell side larger than needed, holds their two
    // centres and no other.
    const int nx = 1 << base_.encoding.x_bits, ny = 1 << base_.encoding.y_bits;
    const double cw = w / nx, ch = h / ny;
    for (int t = 0; t < kGoalTries; t++) {
        const bool along_x = nx > 1 && (ny == 1 || u(0, 1) < 0.5);
        const int i = below(along_x ? nx - 1 : nx), j = below(along_x ? ny : ny - 1);
        goal.cx = std::round((along_x ? (i + 1) * cw : (i + 0.5) * cw) * 1e4) / 1e4;
        goal.cy = std::round((along_x ? (j + 0.5) * ch : (j + 1) * ch) * 1e4) / 1e4;
        goal.radius = std::round(((along_x ? cw : ch) / 2 + 0.1 * std::min(cw, ch)) * 1e4) / 1e4;
        if (goal.cx - goal.radius >= 0 && goal.cx + goal.radius <= w && goal.cy - goal.radius >= 0 &&
            goal.cy + goal.radius <= h) {
            break;
        }
    }
    Scenario s = base_;
    s.goal = goal;
    goal_region_.clear();
    for (const CellBox &c : goal_cells(s)) {
        goal_region_.push_back(box((c.x0 + c.x1) / 2, (c.y0 + c.y1) / 2, c.x1 - c.x0, c.y1 - c.y0));
    }
}

// An axis-aligned wall from an outer wall: across the room with a door, or part way (a spur).
bool Drawer::draw_wall(Piece *p)
{
    const bool vertical = u(0, 1) < 0.5;  // runs along y, at x = c
    const double span = vertical ? base_.arena_h : base_.arena_w;
    const double across = vertical ? base_.arena_w : base_.arena_h;
    const double t = q_size(in_d(kWallThick));
    const double lo = kGap * d_ + t / 2, hi = across - kGap * d_ - t / 2;
    if (hi <= lo) return false;
    const double c = q_pos(u(lo, hi));
    std::vector<std::pair<double, double>> segs;  // along the span
    if (u(0, 1) < 0.6) {
        const double door = q_size(in_d(kDoor));
        if (door >= span - kGap * d_) return false;
        double a = q_pos(u(0, span - door));
        if (a < 0.5 * d_) a = 0;                         // no stub shorter than half a diagonal
        if (span - (a + door) < 0.5 * d_) a = span - door;
        if (a > 0) segs.emplace_back(0.0, a);
        if (a + door < span) segs.emplace_back(a + door, span);
        p->what = "wall with a door";
    } else {
        const double len = q_size(u(kSpur[0], kSpur[1]) * span);
        if (span - len < kGap * d_) return false;  // its free end leaves a passage
        if (u(0, 1) < 0.5) {
            segs.emplace_back(0.0, len);
        } else {
            segs.emplace_back(span - len, span);
        }
        p->what = "wall";
    }
    for (const auto &sg : segs) {
        const double mid = (sg.first + sg.second) / 2, len = sg.second - sg.first;
        p->parts.push_back(vertical ? box(c, mid, t, len) : box(mid, c, len, t));
        p->angle_deg.push_back(0);
    }
    p->may_touch_walls = true;
    return true;
}

void Drawer::draw_obstacle(Piece *p)
{
    const double w = base_.arena_w, h = base_.arena_h;
    switch (below(4)) {
    case 0: {  // an axis-aligned box, pushed against a wall sometimes
        const double bw = q_size(in_d(kBoxSide)), bh = q_size(in_d(kBoxSide));
        double cx = u(0, w), cy = u(0, h);
        if (u(0, 1) < 0.3) {
            switch (below(4)) {
            case 0: cx = bw / 2; break;
            case 1: cx = w - bw / 2; break;
            case 2: cy = bh / 2; break;
            default: cy = h - bh / 2; break;
            }
            p->may_touch_walls = true;
            p->what = "box against the wall";
        } else {
            p->what = "box";
        }
        p->parts.push_back(box(cx, cy, bw, bh));
        p->angle_deg.push_back(0);
        break;
    }
    case 1: {  // a box turned by 10-80 degrees either way
        const double bw = q_size(in_d(kBoxSide)), bh = q_size(in_d(kBoxSide));
        const int a = (10 + below(71)) * (u(0, 1) < 0.5 ? -1 : 1);
        p->parts.push_back(box(u(0, w), u(0, h), bw, bh, a));
        p->angle_deg.push_back(a);
        p->what = "turned box";
        break;
    }
    case 2: {
        Obstacle o;
        o.shape = Obstacle::Shape::Circle;
        o.cx = q_pos(u(0, w));
        o.cy = q_pos(u(0, h));
        o.radius = q_size(in_d(kCircleR));
        p->parts.push_back(o);
        p->angle_deg.push_back(0);
        p->what = "circle";
        break;
    }
    default: {  // an L: two arms of one thickness from a shared corner, square-on half the time
        const double la = q_size(in_d(kLArm)), lb = q_size(in_d(kLArm)), t = q_size(in_d(kLThick));
        const int a = u(0, 1) < 0.5 ? 90 * below(4) : below(360);
        const double ux = std::cos(a * kDeg), uy = std::sin(a * kDeg);  // arm a's direction
        const double vx = -uy, vy = ux;                                 // arm b's
        const double x0 = u(0, w), y0 = u(0, h);                        // the corner
        const int fa = a > 180 ? a - 360 : a;                           // the file's -360..360
        p->parts.push_back(box(x0 + ux * la / 2 + vx * t / 2, y0 + uy * la / 2 + vy * t / 2, la, t, fa));
        p->parts.push_back(box(x0 + ux * t / 2 + vx * lb / 2, y0 + uy * t / 2 + vy * lb / 2, t, lb, fa));
        p->angle_deg.push_back(fa);
        p->angle_deg.push_back(fa);
        p->what = "L-shape";
        break;
    }
    }
}

// Inside the arena; kGap D from the outer walls unless touching one where that is allowed; off the
// goal region by kGoalClear D; kGap D from every piece placed before.
bool Drawer::fits(const Piece &p) const
{
    const double gap = kGap * d_;
    for (const Obstacle &o : p.parts) {
        double ex = 0, ey = 0;
        extents(o, &ex, &ey);
        const double side[4] = {o.cx - ex, base_.arena_w - o.cx - ex, o.cy - ey, base_.arena_h - o.cy - ey};
        for (double s : side) {
            if (s < -kTouch) return false;
            if (s < gap && !(p.may_touch_walls && s <= kTouch)) return false;
        }
        for (const Obstacle &g : goal_region_) {
            if (gap_between(o, g) < kGoalClear * d_) return false;
        }
        for (const Piece &q : pieces) {
            for (const Obstacle &other : q.parts) {
                if (gap_between(o, other) < gap) return false;
            }
        }
    }
    return true;
}

void Drawer::run()
{
    draw_goal();
    const double pick = u(0, 1);
    const int n_walls = pick < kWallsWeight[0] ? 0 : pick < kWallsWeight[0] + kWallsWeight[1] ? 1 : 2;
    for (int k = 0; k < n_walls; k++) {
        for (int t = 0; t < kPlaceTries; t++) {
            Piece p;
            if (draw_wall(&p) && fits(p)) {
                pieces.push_back(p);
                walls++;
                break;
            }
        }
    }
    add_obstacles(kObstacles[0] + below(kObstacles[1] - kObstacles[0] + 1));
}

// ---- Far-goal rooms --------------------------------------------------------------------------

void Drawer::set_frame()
{
    const double w = base_.arena_w, h = base_.arena_h;
    swap_ = w < h || (w == h && u(0, 1) < 0.5);
    L_ = swap_ ? h : w;
    S_ = swap_ ? w : h;
    flip_u_ = u(0, 1) < 0.5;
    flip_v_ = u(0, 1) < 0.5;
}

void Drawer::to_xy(double uu, double vv, double *x, double *y) const
{
    if (flip_u_) uu = L_ - uu;
    if (flip_v_) vv = S_ - vv;
    *x = swap_ ? vv : uu;
    *y = swap_ ? uu : vv;
}

// An axis-aligned box over [u0, u1] x [v0, v1]; one that reaches an outer wall touches it exactly.
Obstacle Drawer::box_uv(double u0, double u1, double v0, double v1) const
{
    const double lu = q_size(u1 - u0), lv = q_size(v1 - v0);
    const double uc = u0 <= kTouch ? lu / 2 : u1 >= L_ - kTouch ? L_ - lu / 2 : (u0 + u1) / 2;
    const double vc = v0 <= kTouch ? lv / 2 : v1 >= S_ - kTouch ? S_ - lv / 2 : (v0 + v1) / 2;
    double x = 0, y = 0;
    to_xy(uc, vc, &x, &y);
    return swap_ ? box(x, y, lv, lu) : box(x, y, lu, lv);
}

// The goal nearest (u, v) whose region lies within [u0, u1] x [v0, v1] of the frame: the base's
// circle, its centre at least r + D/2 off the walls (the robot's centre gets in); or the pair of
// neighbouring state cells whose midpoint is nearest (either orientation; ties go to one drawn at
// random) and whose circle lies inside the arena. False when no goal fits the bounds.
bool Drawer::goal_near_uv(double uu, double vv, double u0, double u1, double v0, double v1)
{
    const double w = base_.arena_w, h = base_.arena_h;
    goal = base_.goal;
    goal_region_.clear();
    if (!base_.goal.cells) {
        const double r = base_.goal.radius;
        const double lo_u = std::max(u0 + r, std::min(r + d_ / 2, L_ / 2));
        const double hi_u = std::min(u1 - r, L_ - std::min(r + d_ / 2, L_ / 2));
        const double lo_v = std::max(v0 + r, std::min(r + d_ / 2, S_ / 2));
        const double hi_v = std::min(v1 - r, S_ - std::min(r + d_ / 2, S_ / 2));
        if (lo_u > hi_u || lo_v > hi_v) return false;
        double x = 0, y = 0;
        to_xy(std::clamp(uu, lo_u, hi_u), std::clamp(vv, lo_v, hi_v), &x, &y);
        goal.cx = q_pos(x);
        goal.cy = q_pos(y);
        goal_region_.assign(1, circle(goal.cx, goal.cy, r));
        return true;
    }
    double tx = 0, ty = 0;
    to_xy(uu, vv, &tx, &ty);
    const int nx = 1 << base_.encoding.x_bits, ny = 1 << base_.encoding.y_bits;
    const double cw = w / nx, ch = h / ny;
    const bool prefer_x = u(0, 1) < 0.5;
    double best = std::numeric_limits<double>::infinity();
    for (int along = 0; along < 2; along++) {
        const bool along_x = (along == 0) == prefer_x;
        for (int j = 0; j < (along_x ? ny : ny - 1); j++) {
            for (int i = 0; i < (along_x ? nx - 1 : nx); i++) {
                const double cx = std::round((along_x ? (i + 1) * cw : (i + 0.5) * cw) * 1e4) / 1e4;
                const double cy = std::round((along_x ? (j + 0.5) * ch : (j + 1) * ch) * 1e4) / 1e4;
                const double r = std::round(((along_x ? cw : ch) / 2 + 0.1 * std::min(cw, ch)) * 1e4) / 1e4;
                const double dist = std::hypot(cx - tx, cy - ty);
                if (cx - r < 0 || cx + r > w || cy - r < 0 || cy + r > h || !(dist < best - 1e-9)) continue;
                // The two cells, in the frame.
                double ru[2], rv[2];
                for (int c = 0; c < 2; c++) {
                    const double x = c == 0 ? i * cw : (i + (along_x ? 2 : 1)) * cw;
                    const double y = c == 0 ? j * ch : (j + (along_x ? 1 : 2)) * ch;
                    ru[c] = flip_u_ ? L_ - (swap_ ? y : x) : (swap_ ? y : x);
                    rv[c] = flip_v_ ? S_ - (swap_ ? x : y) : (swap_ ? x : y);
                }
                if (std::min(ru[0], ru[1]) < u0 - 1e-9 || std::max(ru[0], ru[1]) > u1 + 1e-9 ||
                    std::min(rv[0], rv[1]) < v0 - 1e-9 || std::max(rv[0], rv[1]) > v1 + 1e-9) {
                    continue;
                }
                best = dist;
                goal.cx = cx;
                goal.cy = cy;
                goal.radius = r;
            }
        }
    }
    if (!std::isfinite(best)) return false;
    Scenario s = base_;
    s.goal = goal;
    for (const CellBox &c : goal_cells(s)) {
        goal_region_.push_back(box((c.x0 + c.x1) / 2, (c.y0 + c.y1) / 2, c.x1 - c.x0, c.y1 - c.y0));
    }
    return true;
}

// The goal region's extent in the frame.
void Drawer::goal_extent_uv(double *u0, double *u1, double *v0, double *v1) const
{
    *u0 = *v0 = std::numeric_limits<double>::infinity();
    *u1 = *v1 = -std::numeric_limits<double>::infinity();
    for (const Obstacle &g : goal_region_) {
        double ex = 0, ey = 0;
        extents(g, &ex, &ey);
        for (double x : {g.cx - ex, g.cx + ex}) {
            for (double y : {g.cy - ey, g.cy + ey}) {
                double uu = swap_ ? y : x, vv = swap_ ? x : y;
                if (flip_u_) uu = L_ - uu;
                if (flip_v_) vv = S_ - vv;
                *u0 = std::min(*u0, uu);
                *u1 = std::max(*u1, uu);
                *v0 = std::min(*v0, vv);
                *v1 = std::max(*v1, vv);
            }
        }
    }
}

// A piece the family places by its own rule (its spacing is built in, not drawn and tried): kept
// only if it stays kGoalClear D off the goal.
bool Drawer::add_structure(Piece p, bool wall)
{
    for (const Obstacle &o : p.parts) {
        for (const Obstacle &g : goal_region_) {
            if (gap_between(o, g) < kGoalClear * d_) return false;
        }
    }
    p.angle_deg.assign(p.parts.size(), 0);
    p.may_touch_walls = true;
    pieces.push_back(std::move(p));
    (wall ? walls : obstacles)++;
    return true;
}

void Drawer::add_obstacles(int n)
{
    for (int k = 0; k < n; k++) {
        for (int t = 0; t < kPlaceTries; t++) {
            Piece p;
            draw_obstacle(&p);
            if (fits(p)) {
                pieces.push_back(p);
                obstacles++;
                break;
            }
        }
    }
}

// A hall along the floor, the goal at its far end: as wide as the floor where that is under
// 6.5 D, or 3-5 D with the rest of the floor solid, bending at the end across the floor when the floor is less than twice as
// long as wide (an L: along one wall, then along the end wall); a wall across it with a door;
// pillars every 3-5 D along its first leg, in the middle where 1.5 D passes either side, else
// against the outer wall.
bool Drawer::far_hall()
{
    double hw = q_size(in_d(kHallWidth));
    const bool block = S_ >= (kHallWidth[1] + kGap) * d_;  // a floor not already a hall
    if (!block) hw = S_;
    const bool bend = block && L_ < 2 * S_;
    const double leg = bend ? q_size(in_d(kHallWidth)) : 0;  // the second leg's width, along u
    const double clear = kGoalClear * d_;
    if (bend) {
        if (!goal_near_uv(L_, S_, L_ - leg + clear, L_, hw + clear, S_)) return false;
    } else if (!goal_near_uv(L_, hw / 2, 0, L_, 0, block ? hw - clear : S_)) {
        return false;
    }
    if (block) {
        Piece p;
        p.parts.push_back(box_uv(0, L_ - leg, hw, S_));
        p.what = "the floor beside the hall, solid";
        if (!add_structure(p, true)) return false;
    }
    const double first = L_ - leg;  // the first leg's length
    const double t = q_size(in_d(kWallThick)), door = q_size(in_d(kFarDoor));
    const double uc = u(0.35, 0.65) * first;
    if (door < hw - 0.5 * d_) {
        double a = u(0, hw - door);
        if (a < 0.5 * d_) a = 0;
        if (hw - (a + door) < 0.5 * d_) a = hw - door;
        Piece p;
        if (a > 0) p.parts.push_back(box_uv(uc - t / 2, uc + t / 2, 0, a));
        if (a + door < hw) p.parts.push_back(box_uv(uc - t / 2, uc + t / 2, a + door, hw));
        p.what = "wall across the hall, with a door";
        if (!add_structure(p, true)) return false;
    }
    for (double at = kGap * d_ + in_d(kPillarEvery) / 2; at < first - kGap * d_; at += in_d(kPillarEvery)) {
        Piece p;
        double x = 0, y = 0;
        to_xy(at, hw / 2, &x, &y);
        Obstacle c;
        c.shape = Obstacle::Shape::Circle;
        c.cx = q_pos(x);
        c.cy = q_pos(y);
        c.radius = q_size(in_d(kPillarR));
        p.parts.push_back(c);
        p.angle_deg.push_back(0);
        p.what = "pillar";
        if (!fits(p)) {
            const double side = q_size(in_d(kButtress)), len = q_size(in_d(kButtress));
            p.parts.assign(1, box_uv(at - len / 2, at + len / 2, 0, side));
            p.what = "pillar against the wall";
            p.may_touch_walls = true;
        }
        if (fits(p)) {
            pieces.push_back(p);
            obstacles++;
        }
    }
    return true;
}

// An open floor with the goal in a corner: desks, pillars and L-shapes as the ordinary rooms
// draw them, one per 12-18 D^2 of floor.
bool Drawer::far_open()
{
    if (!goal_near_uv(L_, S_, 0, L_, 0, S_)) return false;
    const double area = L_ * S_ / (d_ * d_);
    add_obstacles(static_cast<int>(std::lround(area / u(kOpenDensity[0], kOpenDensity[1]))));
    return true;
}

// The goal behind a cul-de-sac whose mouth faces the rest of the floor: a back wall between the
// goal and the floor, two arms toward the floor (one of them the floor's side wall when the
// pocket comes near it), 1.6 D at least beside it; then 2-4 obstacles.
bool Drawer::far_culdesac()
{
    const double t = q_size(in_d(kWallThick));
    if (!goal_near_uv(L_, u(0.25, 0.75) * S_, 0, L_, 0, S_)) return false;
    double gu0 = 0, gu1 = 0, gv0 = 0, gv1 = 0;
    goal_extent_uv(&gu0, &gu1, &gv0, &gv1);
    const double pw = std::max(in_d(kPocket), gv1 - gv0 + 0.4 * d_);
    const double vc = (gv0 + gv1) / 2;
    double ov0 = vc - pw / 2 - t, ov1 = vc + pw / 2 + t;
    const bool attach0 = ov0 < kSide * d_, attach1 = S_ - ov1 < kSide * d_;
    if (attach0 && attach1) return false;  // the goal would be walled in
    if (attach0) ov0 = 0;
    if (attach1) ov1 = S_;
    const double bu1 = gu0 - in_d(kBehind), bu0 = bu1 - t;
    const double arm = std::min(in_d(kPocketArm), bu0 - kSide * d_);
    if (arm < kGap * d_) return false;
    Piece p;
    p.parts.push_back(box_uv(bu0, bu1, ov0, ov1));
    if (!attach0) p.parts.push_back(box_uv(bu0 - arm, bu0, ov0, ov0 + t));
    if (!attach1) p.parts.push_back(box_uv(bu0 - arm, bu0, ov1 - t, ov1));
    p.what = "cul-de-sac";
    if (!add_structure(p, true)) return false;
    add_obstacles(kCulDeSacClutter[0] + below(kCulDeSacClutter[1] - kCulDeSacClutter[0] + 1));
    return true;
}

// 1-4 partitions along the floor, each open at one end (1.6-2.5 D), the ends alternating, lanes
// at least 1.8 D wide: the goal at the far end of the last lane. Where no goal fits in a lane
// (paper-lab's goal cells in a lane of a narrow hall), or the floor is too narrow for a lane
// each side, 2-6 baffles across the floor instead, open at alternating sides: the goal beyond
// the last.
bool Drawer::far_serpentine()
{
    const double t = q_size(in_d(kWallThick));
    const int most = std::min(kMaxPartitions, static_cast<int>(std::floor((S_ - kLane * d_) / (kLane * d_ + t))));
    if (most >= 1) {
        const int k = 1 + below(most);
        const double lane = (S_ - k * t) / (k + 1);
        bool high = u(0, 1) < 0.5;  // the first partition's gap at u = L
        for (int j = 1; j <= k; j++, high = !high) {
            const double v0 = j * lane + (j - 1) * t, gap = q_size(in_d(kFarDoor));
            Piece p;
            p.parts.push_back(high ? box_uv(0, L_ - gap, v0, v0 + t) : box_uv(gap, L_, v0, v0 + t));
            p.what = "partition";
            p.angle_deg.assign(1, 0);
            p.may_touch_walls = true;
            pieces.push_back(p);
            walls++;
        }
        // The last lane is entered through the last partition's gap, which is at u = L when
        // `high` (flipped once more after it) is false: the goal is at the lane's other end.
        if (goal_near_uv(high ? L_ : 0, S_ - lane / 2, 0, L_, S_ - lane + kGoalClear * d_, S_)) return true;
        pieces.clear();
        walls = 0;
    }
    const int baffles = std::min(6, static_cast<int>(std::floor((L_ - kLane * d_) / (kLane * d_ + t))));
    if (baffles < 2) return false;
    const int k = 2 + below(baffles - 1);
    const double bay = (L_ - k * t) / (k + 1);
    bool high = u(0, 1) < 0.5;  // the first baffle's gap at v = S
    for (int j = 1; j <= k; j++, high = !high) {
        const double u0 = j * bay + (j - 1) * t, gap = q_size(in_d(kFarDoor));
        if (S_ - gap < d_) return false;
        Piece p;
        p.parts.push_back(high ? box_uv(u0, u0 + t, 0, S_ - gap) : box_uv(u0, u0 + t, gap, S_));
        p.what = "baffle";
        p.angle_deg.assign(1, 0);
        p.may_touch_walls = true;
        pieces.push_back(p);
        walls++;
    }
    return goal_near_uv(L_, high ? S_ : 0, L_ - bay + kGoalClear * d_, L_, 0, S_);
}

bool Drawer::run_far(FarFamily family)
{
    set_frame();
    switch (family) {
    case FarFamily::Hall: return far_hall();
    case FarFamily::Open: return far_open();
    case FarFamily::CulDeSac: return far_culdesac();
    case FarFamily::Serpentine: return far_serpentine();
    }
    return false;
}



std::string layout_text(const Drawer &dr)
{
    std::string out = "# The layout, drawn at random (docs/scenarios.md, \"Generated rooms\").\n";
    for (const Piece &p : dr.pieces) {
        for (std::size_t i = 0; i < p.parts.size(); i++) {
            const Obstacle &o = p.parts[i];
            std::string line;
            if (o.shape == Obstacle::Shape::Circle) {
                line = "obstacle circle " + num(o.cx) + " " + num(o.cy) + " " + num(o.radius);
            } else {
                line = "obstacle box " + num(o.cx) + " " + num(o.cy) + " " + num(o.w) + " " + num(o.h);
                if (p.angle_deg[i] != 0) line += " " + std::to_string(p.angle_deg[i]);
            }
            std::string what = p.what;
            if (p.parts.size() > 1) {
                what += " (" + std::to_string(i + 1) + " of " + std::to_string(p.parts.size()) + ")";
            }
            out += with_comment(line, what);
        }
    }
    const Goal &g = dr.goal;
    std::string line = "goal " + num(g.cx) + " " + num(g.cy) + " " + num(g.radius);
    if (g.cells) {
        out += with_comment(line + " cells", "the cells whose centres are inside");
    } else {
        out += with_comment(line, "reached when the robot's centre is inside");
    }
    return out;
}



}  // namespace

namespace {

// The base's lines for a far room on a w x h floor: its arena and encoding (and beacons) new.
void far_base_lines(const Scenario &base, double w, double h, int xb, int yb, std::string *before,
                    std::string *after)
{
    if (w == base.arena_w && h == base.arena_h) return;
    const double cw = base.arena_w / (1 << base.encoding.x_bits), ch = base.arena_h / (1 << base.encoding.y_bits);
    *before = replace_key(*before, "arena",
                          with_comment("arena " + num(w) + " " + num(h),
                                       "m; a floor other than the base's " + num(base.arena_w) + " x " +
                                           num(base.arena_h) + " m"));
    const int bits = xb + yb + base.encoding.heading_bits + base.encoding.sensor_bits;
    char states[64];
    std::snprintf(states, sizeof states, "%d bits; %d x %d cells of %s x %s m, as the base's", bits, 1 << xb,
                  1 << yb, num(cw).c_str(), num(ch).c_str());
    *after = replace_key(*after, "encode",
                         with_comment("encode x " + std::to_string(xb) + " y " + std::to_string(yb) + " heading " +
                                          std::to_string(base.encoding.heading_bits) + " sensor " +
                                          std::to_string(base.encoding.sensor_bits),
                                      states));
    if (!base.cricket.beacons.empty()) *after = replace_key(*after, "beacon", beacon_lines(base, w, h));
}

// The comment lines at the head of a drawn room's file: what made it and what was checked.
std::string room_head(const Scenario &base, const Scenario &floor, const RoomSpec &spec,
                      const std::string &base_label, const std::string &command, const std::string &file,
                      std::uint32_t index, std::uint32_t draw)
{
    char head[640];
    if (!spec.far) {
        std::snprintf(head, sizeof head,
                      "# %s: a generated room; regenerate it rather than edit it (docs/scenarios.md, "
                      "\"Generated rooms\").\n"
                      "# %s: room %u, draw %u.\n"
                      "# Only the layout is new: every other line is %s's own.\n"
                      "# Passages: at least %.1f x the robot's diagonal (%.3f m) as drawn; checked "
                      "at least the diagonal on a %.0f cm grid.\n\n",
                      stem(file).c_str(), command.c_str(), index, draw, base_label.c_str(), kGap,
                      2.0 * robot_radius(base.robot), start_grid_step(base) * 100.0);
    } else {
        std::snprintf(head, sizeof head,
                      "# %s: a generated far-goal room (%s, floor %s x %s m); regenerate it rather "
                      "than edit it\n# (docs/scenarios.md, \"Far-goal rooms\").\n"
                      "# %s: room %u, draw %u.\n"
                      "# Only the layout%s new: every other line is %s's own.\n"
                      "# Passages: at least the robot's diagonal (%.3f m), checked on a %.0f cm grid.\n",
                      stem(file).c_str(), far_family_name(spec.family), num(floor.arena_w).c_str(),
                      num(floor.arena_h).c_str(), command.c_str(), index, draw,
                      floor.arena_w == base.arena_w && floor.arena_h == base.arena_h
                          ? " is"
                          : base.cricket.beacons.empty() ? ", the arena and the encoding are"
                                                         : ", the arena, the encoding and the beacons are",
                      base_label.c_str(), 2.0 * robot_radius(base.robot), start_grid_step(floor) * 100.0);
    }
    return head;
}

}  // namespace

bool generate_room(std::string_view base_text, const std::string &base_label,
                   const std::string &command, std::uint32_t seed, std::uint32_t index,
                   const std::string &file, Room *out, std::string *error)
{
    return generate_room(base_text, base_label, command, seed, index, RoomSpec{}, file, out, error);
}

bool generate_room(std::string_view base_text, const std::string &base_label,
                   const std::string &command, std::uint32_t seed, std::uint32_t index,
                   const RoomSpec &spec, const std::string &file, Room *out, std::string *error)
{
    Scenario base;
    if (!parse_scenario(base_text, base_label, &base, error)) return false;
    std::string before, after;
    base_without_layout(base_text, &before, &after);
    std::uint32_t rs = room_seed(seed, index);
    Scenario floor = base;  // what the Drawer draws on
    long far_than = 0;      // a far room's longest path must reach this
    if (spec.far) {
        const double w = spec.floor_w > 0 ? spec.floor_w : base.arena_w;
        const double h = spec.floor_h > 0 ? spec.floor_h : base.arena_h;
        std::string ferr;
        if (!floor_check(base, w, h, &floor.encoding.x_bits, &floor.encoding.y_bits, &ferr)) {
            if (error != nullptr) *error = "floor " + ferr;
            return false;
        }
        floor.arena_w = w;
        floor.arena_h = h;
        far_base_lines(base, w, h, floor.encoding.x_bits, floor.encoding.y_bits, &before, &after);
        const std::uint32_t tag = 0x100u + static_cast<std::uint32_t>(spec.family) * 0x1000u +
                                  static_cast<std::uint32_t>(floor.encoding.x_bits * 32 + floor.encoding.y_bits);
        rs = room_seed(rs, tag);
        far_than = longest_path(base).longest;
    }
    std::string last_problem;
    for (std::uint32_t draw = 0; draw < kMaxRoomDraws; draw++) {
        Drawer dr(floor, rs, draw);
        if (!spec.far) {
            dr.run();
        } else if (!dr.run_far(spec.family)) {
            last_problem = std::string("the ") + far_family_name(spec.family) + " does not fit this draw";
            continue;
        }
        const std::string head = room_head(base, floor, spec, base_label, command, file, index, draw);
        Room room;
        const std::string body = before + "\n" + layout_text(dr) + after;
        room.text = head + std::string(spec.far ? "\n" : "") + body;
        if (!check_drawn_room(&room, file, &last_problem)) continue;
        if (spec.far) {
            if (room.path.longest <= far_than) {
                last_problem = room.path.longest < 0
                                   ? std::to_string(room.path.stranded) + " start states cannot reach the goal on the state grid"
                                   : "longest path " + std::to_string(room.path.longest) +
                                         " actions, not farther than the base's " + std::to_string(far_than);
                continue;
            }
            room.text = head + ("# longest_path_actions " + std::to_string(room.path.longest)) +
                        ": the most actions a start needs to reach the goal at best (docs/scenarios.md).\n\n" + body;
            if (!parse_scenario(room.text, file, &room.scenario, &last_problem)) continue;
            room.family = far_family_name(spec.family);
        }
        room.walls = dr.walls;
        room.obstacles = dr.obstacles;
        room.draw = draw;
        *out = std::move(room);
        return true;
    }
    if (error != nullptr) {
        *error = file + ": no room in " + std::to_string(kMaxRoomDraws) + " draws (the last: " + last_problem + ")";
    }
    return false;
}

}  // namespace world
