// SPDX-License-Identifier: MIT
// dynaqpc world: distances in the arena (scenario validation and start poses) and the sensor code.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "world/scenario.h"

namespace world {

double robot_radius(const RobotSpec &robot)
{
    return 0.5 * std::hypot(robot.length, robot.width);
}

double obstacle_distance(const Obstacle &o, double x, double y)
{
    double dx = x - o.cx, dy = y - o.cy;
    if (o.shape == Obstacle::Shape::Circle) {
        return std::hypot(dx, dy) - o.radius;
    }
    // Into the box's own frame, then the signed distance to an axis-aligned box.
    double c = std::cos(o.angle), s = std::sin(o.angle);
    double lx = std::fabs(c * dx + s * dy) - o.w / 2.0;
    double ly = std::fabs(-s * dx + c * dy) - o.h / 2.0;
    double outside = std::hypot(std::max(lx, 0.0), std::max(ly, 0.0));
    return outside + std::min(std::max(lx, ly), 0.0);
}

double wall_distance(const Scenario &s, double x, double y)
{
    return std::min(std::min(x, s.arena_w - x), std::min(y, s.arena_h - y));
}

double clearance(const Scenario &s, double x, double y)
{
    double d = wall_distance(s, x, y);
    for (const Obstacle &o : s.obstacles) {
        d = std::min(d, obstacle_distance(o, x, y));
    }
    return d;
}

namespace {

// clearance(s, x, y) >= need, stopping at the first wall or obstacle nearer than `need`: the same
// answer (a NaN distance is passed over by std::min there, and by `<` here), for much less work
// where the parser's search for room asks up to a million points of a crowded arena.
bool clear_by(const Scenario &s, double x, double y, double need)
{
    if (!(wall_distance(s, x, y) >= need)) return false;
    for (const Obstacle &o : s.obstacles) {
        if (obstacle_distance(o, x, y) < need) return false;
    }
    return true;
}

// The centre of the state-grid cell holding v: `extent` cut into 2^bits cells, clamped to the
// edge cells as the firmware's state encoder does.
double cell_centre(double v, double extent, int bits)
{
    const double cells = std::ldexp(1.0, bits);
    const double c = std::floor(std::clamp(v / extent * cells, 0.0, cells - 1.0));
    return (c + 0.5) * extent / cells;
}

// The same on the grid along `axis`, fitted or not.
double cell_centre(const Scenario &s, int axis, double v)
{
    if (!s.encoding.fitted) {
        return axis == 0 ? cell_centre(v, s.arena_w, s.encoding.x_bits) : cell_centre(v, s.arena_h, s.encoding.y_bits);
    }
    double lo = 0.0, hi = 0.0;
    grid_span(s, axis, grid_cell(s, axis, v), &lo, &hi);
    return 0.5 * (lo + hi);
}

}  // namespace

namespace {

// Calls f(cell, distance of its centre from the goal's) for every cell of the state grid under the
// goal circle's bounding box: the only cells whose centres can be inside it (or on it). At most
// 64 x 64 for a valid scenario (the parser's bound), and nothing is allocated: start sampling
// asks about up to a million points.
template <typename F>
void for_cells_under_goal(const Scenario &s, F f)
{
    if (s.encoding.fitted) {  // at most 32 x 32 cells: all of them
        const Goal &g = s.goal;
        for (int j = 0; j < grid_cells(s, 1); j++) {
            for (int i = 0; i < grid_cells(s, 0); i++) {
                CellBox c{};
                grid_span(s, 0, i, &c.x0, &c.x1);
                grid_span(s, 1, j, &c.y0, &c.y1);
                f(c, std::hypot(0.5 * (c.x0 + c.x1) - g.cx, 0.5 * (c.y0 + c.y1) - g.cy));
            }
        }
        return;
    }
    const double nx = std::ldexp(1.0, s.encoding.x_bits);
    const double ny = std::ldexp(1.0, s.encoding.y_bits);
    const double cw = s.arena_w / nx, ch = s.arena_h / ny;
    const Goal &g = s.goal;
    const double i0 = std::max(0.0, std::floor((g.cx - g.radius) / cw));
    const double i1 = std::min(nx - 1.0, std::floor((g.cx + g.radius) / cw));
    const double j0 = std::max(0.0, std::floor((g.cy - g.radius) / ch));
    const double j1 = std::min(ny - 1.0, std::floor((g.cy + g.radius) / ch));
    for (double j = j0; j <= j1; j += 1.0) {
        for (double i = i0; i <= i1; i += 1.0) {
            const CellBox c = {i * cw, j * ch, (i + 1.0) * cw, (j + 1.0) * ch};
            f(c, std::hypot((i + 0.5) * cw - g.cx, (j + 0.5) * ch - g.cy));
        }
    }
}

}  // namespace

std::vector<CellBox> goal_cells(const Scenario &s)
{
    std::vector<CellBox> out;
    for_cells_under_goal(s, [&](const CellBox &c, double d) {
        if (d <= s.goal.radius) out.push_back(c);
    });
    return out;
}

double goal_cells_distance(const Scenario &s, double x, double y)
{
    double best = std::numeric_limits<double>::infinity();
    for_cells_under_goal(s, [&](const CellBox &c, double d) {
        if (d > s.goal.radius) return;
        const double dx = std::max({c.x0 - x, 0.0, x - c.x1});
        const double dy = std::max({c.y0 - y, 0.0, y - c.y1});
        best = std::min(best, std::hypot(dx, dy));
    });
    return best;
}

double goal_cell_centre_margin(const Scenario &s)
{
    double margin = std::numeric_limits<double>::infinity();
    for_cells_under_goal(s, [&](const CellBox &, double d) {
        margin = std::min(margin, std::abs(d - s.goal.radius));
    });
    return margin;
}

int grid_cells(const Scenario &s, int axis)
{
    const Encoding &e = s.encoding;
    if (e.fitted) return static_cast<int>((axis == 0 ? e.x_edges : e.y_edges).size()) - 1;
    return 1 << (axis == 0 ? e.x_bits : e.y_bits);
}

int grid_cell(const Scenario &s, int axis, double v)
{
    const Encoding &e = s.encoding;
    const int n = grid_cells(s, axis);
    if (!e.fitted) {
        const double extent = axis == 0 ? s.arena_w : s.arena_h;
        return static_cast<int>(std::floor(std::clamp(v / extent * n, 0.0, n - 1.0)));
    }
    const std::vector<double> &edges = axis == 0 ? e.x_edges : e.y_edges;
    if (!(v > 0.0)) return 0;
    const auto it = std::upper_bound(edges.begin() + 1, edges.end() - 1, v);
    return static_cast<int>(it - (edges.begin() + 1));
}

void grid_span(const Scenario &s, int axis, int k, double *lo, double *hi)
{
    const Encoding &e = s.encoding;
    if (!e.fitted) {
        const double side = (axis == 0 ? s.arena_w : s.arena_h) / grid_cells(s, axis);
        *lo = k * side;
        *hi = (k + 1) * side;
        return;
    }
    const std::vector<double> &edges = axis == 0 ? e.x_edges : e.y_edges;
    *lo = edges[static_cast<std::size_t>(k)];
    *hi = edges[static_cast<std::size_t>(k) + 1];
}

double grid_max_side(const Scenario &s, int axis)
{
    double best = 0.0;
    for (int k = 0; k < grid_cells(s, axis); k++) {
        double lo = 0.0, hi = 0.0;
        grid_span(s, axis, k, &lo, &hi);
        best = std::max(best, hi - lo);
    }
    return best;
}

bool in_goal(const Scenario &s, double x, double y)
{
    if (s.goal.cells) {
        x = cell_centre(s, 0, x);
        y = cell_centre(s, 1, y);
    }
    return std::hypot(x - s.goal.cx, y - s.goal.cy) <= s.goal.radius;
}

bool start_position_ok(const Scenario &s, double x, double y)
{
    const double m = s.start.margin;
    double need = robot_radius(s.robot) + m;
    const double to_goal = std::hypot(x - s.goal.cx, y - s.goal.cy);
    if (to_goal <= s.goal.radius + m) {
        return false;
    }
    // Walls and obstacles first: a point too near one needs nothing else (the parser's search for
    // room asks up to a million points of a file that has none, each cheap only this way).
    if (!clear_by(s, x, y, need)) {
        return false;
    }
    if (s.goal.cells) {
        // A goal cell has its centre in the circle, so none is nearer than this: most points
        // are decided without the walk over up to 64 x 64 cells (that walk for each point kept
        // a bad file busy for 21 s).
        const double cw = grid_max_side(s, 0), ch = grid_max_side(s, 1);
        const double nearest = to_goal - s.goal.radius - 0.5 * std::hypot(cw, ch);
        if (nearest <= m && goal_cells_distance(s, x, y) <= m) {
            return false;
        }
    }
    return true;
}

double start_grid_step(const Scenario &s)
{
    return std::max(0.02, std::max(s.arena_w, s.arena_h) / 1000.0);
}

std::uint32_t sensor_code(const Scenario &s, const float *ranges)
{
    std::uint32_t code = 0;
    for (std::size_t b = 0; b < s.code_bits.size(); ++b) {
        const CodeBit &bit = s.code_bits[b];
        for (int r : bit.rays) {
            if (ranges[r] < bit.threshold) {
                code |= 1u << b;
                break;
            }
        }
    }
    return code;
}

std::vector<ConstantCodeBit> constant_code_bits(const Scenario &s)
{
    std::vector<ConstantCodeBit> out;
    const float lo = static_cast<float>(s.ranger.min_range), hi = static_cast<float>(s.ranger.max_range);
    for (std::size_t b = 0; b < s.code_bits.size(); ++b) {
        const float t = static_cast<float>(s.code_bits[b].threshold);
        if (hi < t || t <= lo) out.push_back({static_cast<int>(b), s.code_bits[b].line, hi < t});
    }
    return out;
}

std::string constant_code_bit_warning(const Scenario &s, const ConstantCodeBit &c)
{
    char buf[320];
    const double t = s.code_bits[static_cast<std::size_t>(c.bit)].threshold;
    std::snprintf(buf, sizeof buf,
                  "code_bit %g (bit %d) is %s set: its rays read %g to %g m (the ranger's min and max), %s "
                  "%g, so it tells the robot nothing; give a threshold above %g and up to %g m",
                  t, c.bit, c.always ? "always" : "never", s.ranger.min_range,
                  s.ranger.max_range, c.always ? "all below" : "none below", t, s.ranger.min_range,
                  s.ranger.max_range);
    return buf;
}

}  // namespace world
