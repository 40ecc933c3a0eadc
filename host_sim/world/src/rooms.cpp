// SPDX-License-Identifier: MIT
// dynaqpc world: seeded random rooms and the passage check.
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
#include <cstdio>
#include <limits>
#include <vector>

#include "world/random.h"

namespace world {

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

// Positions on a 1 mm grid, sizes on 2 mm (so that a box pushed against a wall has its centre on
// the 1 mm grid too): what the file says is what was checked.
double q_pos(double v) { return std::round(v * 1000.0) / 1000.0; }
double q_size(double v) { return std::max(0.01, std::round(v * 500.0) / 500.0); }

// A room's stream: (seed, index) mixed as the train command mixes (seed, set), so that
// neighbouring seeds and indices give unrelated rooms.
std::uint32_t room_seed(std::uint32_t seed, std::uint32_t index)
{
    std::uint64_t z = (static_cast<std::uint64_t>(seed) << 32) + index + 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return static_cast<std::uint32_t>((z ^ (z >> 31)) >> 16);
}

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

// Half extents of an obstacle's axis-aligned bounding box.
void extents(const Obstacle &o, double *ex, double *ey)
{
    if (o.shape == Obstacle::Shape::Circle) {
        *ex = *ey = o.radius;
        return;
    }
    const double c = std::fabs(std::cos(o.angle)), s = std::fabs(std::sin(o.angle));
    *ex = (o.w * c + o.h * s) / 2.0;
    *ey = (o.w * s + o.h * c) / 2.0;
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

    const Scenario &base_;
    RandomStream rng_;
    double d_;  // the robot's diagonal, m
    std::vector<Obstacle> goal_region_;
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
        Obstacle c;
        c.shape = Obstacle::Shape::Circle;
        c.cx = goal.cx;
        c.cy = goal.cy;
        c.radius = r;
        goal_region_.assign(1, c);
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
    const int n_obstacles = kObstacles[0] + below(kObstacles[1] - kObstacles[0] + 1);
    for (int k = 0; k < n_obstacles; k++) {
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

// A number as the file writes it: at most 4 decimals, no trailing zeros.
std::string num(double v)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4f", v);
    std::string s = buf;
    while (!s.empty() && s.back() == '0') s.pop_back();
    if (!s.empty() && s.back() == '.') s.pop_back();
    if (s == "-0") s = "0";
    return s;
}

std::string with_comment(std::string line, const std::string &comment)
{
    if (line.size() < 36) line.resize(36, ' ');
    else line += ' ';
    return line + "# " + comment + "\n";
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

// The base file without its layout: every line but `obstacle` and `goal`, and without the
// comments and blank lines that lead up to a dropped line or to the first key (the base's
// header, which describes the base). `before` gets the lines up to and with `arena`, `after` the
// rest.
void base_without_layout(std::string_view text, std::string *before, std::string *after)
{
    std::vector<std::string_view> run;  // comments and blank lines not yet placed
    bool seen_key = false, seen_arena = false;
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view line = text.substr(pos, end - pos);
        pos = end + 1;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        std::string_view body = line.substr(0, std::min(line.size(), line.find('#')));
        const std::size_t k0 = body.find_first_not_of(" \t");
        if (k0 == std::string_view::npos) {
            run.push_back(line);
            continue;
        }
        const std::size_t k1 = body.find_first_of(" \t", k0);
        const std::string_view key = body.substr(k0, k1 == std::string_view::npos ? k1 : k1 - k0);
        const bool layout = key == "obstacle" || key == "goal";
        std::string *to = seen_arena ? after : before;
        if (!layout && seen_key) {
            for (std::string_view r : run) *to += std::string(r) + "\n";
        }
        run.clear();
        seen_key = true;
        if (!layout) *to += std::string(line) + "\n";
        if (key == "arena") seen_arena = true;
    }
}

std::string stem(const std::string &file)
{
    std::size_t slash = file.find_last_of('/');
    std::string base = slash == std::string::npos ? file : file.substr(slash + 1);
    if (base.size() > 4 && base.compare(base.size() - 4, 4, ".scn") == 0) base.resize(base.size() - 4);
    return base;
}

}  // namespace

PassageReport check_passages(const Scenario &s)
{
    PassageReport rep;
    const double step = start_grid_step(s);
    const long nx = static_cast<long>(std::ceil(s.arena_w / step - 0.5));
    const long ny = static_cast<long>(std::ceil(s.arena_h / step - 0.5));
    const double need = robot_radius(s.robot);
    enum : unsigned char { kFree = 1, kStart = 2, kReached = 4 };
    std::vector<unsigned char> cell(static_cast<std::size_t>(nx * ny), 0);
    std::vector<long> queue;
    // clear[k]: the clearance of point k where it is below `enough`, else at least `enough`. Each
    // obstacle is measured only over the points its bounding box, grown by `enough`, covers: the
    // others are farther from it.
    const double enough = need + s.start.margin + step;
    std::vector<double> clear(static_cast<std::size_t>(nx * ny));
    for (long j = 0; j < ny; j++) {
        for (long i = 0; i < nx; i++) {
            const double x = step / 2 + i * step, y = step / 2 + j * step;
            clear[static_cast<std::size_t>(j * nx + i)] = std::min({x, s.arena_w - x, y, s.arena_h - y});
        }
    }
    for (const Obstacle &o : s.obstacles) {
        double ex = 0, ey = 0;
        extents(o, &ex, &ey);
        const long i0 = std::max(0L, static_cast<long>(std::floor((o.cx - ex - enough) / step - 0.5)));
        const long i1 = std::min(nx - 1, static_cast<long>(std::ceil((o.cx + ex + enough) / step - 0.5)));
        const long j0 = std::max(0L, static_cast<long>(std::floor((o.cy - ey - enough) / step - 0.5)));
        const long j1 = std::min(ny - 1, static_cast<long>(std::ceil((o.cy + ey + enough) / step - 0.5)));
        for (long j = j0; j <= j1; j++) {
            for (long i = i0; i <= i1; i++) {
                double &c = clear[static_cast<std::size_t>(j * nx + i)];
                c = std::min(c, obstacle_distance(o, step / 2 + i * step, step / 2 + j * step));
            }
        }
    }
    for (long j = 0; j < ny; j++) {
        for (long i = 0; i < nx; i++) {
            const double x = step / 2 + i * step, y = step / 2 + j * step;
            const double cl = clear[static_cast<std::size_t>(j * nx + i)];
            unsigned char &c = cell[static_cast<std::size_t>(j * nx + i)];
            if (cl < need) continue;
            c = kFree;
            rep.free_points++;
            // The world's own rule decides a start; where the clearance is too small it cannot hold.
            if (cl >= need + s.start.margin - 1e-12 && start_position_ok(s, x, y)) {
                c |= kStart;
                rep.start_points++;
            }
            if (in_goal(s, x, y)) {
                c |= kReached;
                rep.goal_points++;
                queue.push_back(j * nx + i);
            }
        }
    }
    char buf[256];
    const double diag = 2.0 * need;
    if (rep.goal_points == 0) {
        std::snprintf(buf, sizeof buf,
                      "the robot (diagonal %.3f m) fits nowhere in the goal at (%.3f, %.3f)", diag,
                      s.goal.cx, s.goal.cy);
        rep.problem = buf;
        return rep;
    }
    for (std::size_t head = 0; head < queue.size(); head++) {
        const long k = queue[head], i = k % nx, j = k / nx;
        const long next[4] = {i > 0 ? k - 1 : -1, i + 1 < nx ? k + 1 : -1, j > 0 ? k - nx : -1,
                              j + 1 < ny ? k + nx : -1};
        for (long n : next) {
            if (n < 0) continue;
            unsigned char &c = cell[static_cast<std::size_t>(n)];
            if ((c & kFree) && !(c & kReached)) {
                c |= kReached;
                queue.push_back(n);
            }
        }
    }
    long first = -1;
    for (long k = 0; k < nx * ny; k++) {
        const unsigned char c = cell[static_cast<std::size_t>(k)];
        if ((c & kStart) && !(c & kReached)) {
            if (first < 0) first = k;
            rep.stranded_points++;
        }
    }
    if (first >= 0) {
        std::snprintf(buf, sizeof buf,
                      "%ld of %ld start points cannot reach the goal, the first at (%.3f, %.3f): "
                      "no passage at least the robot's diagonal (%.3f m) wide",
                      rep.stranded_points, rep.start_points, step / 2 + (first % nx) * step,
                      step / 2 + (first / nx) * step, diag);
        rep.problem = buf;
        return rep;
    }
    rep.ok = true;
    return rep;
}

bool generate_room(std::string_view base_text, const std::string &base_label,
                   const std::string &command, std::uint32_t seed, std::uint32_t index,
                   const std::string &file, Room *out, std::string *error)
{
    Scenario base;
    if (!parse_scenario(base_text, base_label, &base, error)) return false;
    std::string before, after;
    base_without_layout(base_text, &before, &after);
    const std::uint32_t rs = room_seed(seed, index);
    std::string last_problem;
    for (std::uint32_t draw = 0; draw < kMaxRoomDraws; draw++) {
        Drawer dr(base, rs, draw);
        dr.run();
        char head[512];
        std::snprintf(head, sizeof head,
                      "# %s: a generated room; regenerate it rather than edit it (docs/scenarios.md, "
                      "\"Generated rooms\").\n"
                      "# %s: room %u, draw %u.\n"
                      "# Only the layout is new: every other line is %s's own.\n"
                      "# Passages: at least %.1f x the robot's diagonal (%.3f m) as drawn; checked "
                      "at least the diagonal on a %.0f cm grid.\n\n",
                      stem(file).c_str(), command.c_str(), index, draw, base_label.c_str(), kGap,
                      2.0 * robot_radius(base.robot), start_grid_step(base) * 100.0);
        Room room;
        room.text = head + before + "\n" + layout_text(dr) + after;
        std::string perr;
        if (!parse_scenario(room.text, file, &room.scenario, &perr)) {
            last_problem = perr;
            continue;
        }
        room.passages = check_passages(room.scenario);
        if (!room.passages.ok) {
            last_problem = room.passages.problem;
            continue;
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
