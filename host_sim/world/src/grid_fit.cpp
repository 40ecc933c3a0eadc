// SPDX-License-Identifier: MIT
// dynaqpc world: a state grid fitted to the room (grid_fit.h: the rule and why).
#include "world/grid_fit.h"

#include <algorithm>
#include <cmath>

namespace world {

namespace {

// The obstacle's extent along `axis`: its bounding box's [lo, hi].
void extent(const Obstacle &o, int axis, double *lo, double *hi)
{
    double half = o.radius;
    if (o.shape == Obstacle::Shape::Box) {
        const double c = std::fabs(std::cos(o.angle)), sn = std::fabs(std::sin(o.angle));
        half = axis == 0 ? (o.w * c + o.h * sn) / 2.0 : (o.w * sn + o.h * c) / 2.0;
    }
    const double mid = axis == 0 ? o.cx : o.cy;
    *lo = mid - half;
    *hi = mid + half;
}

// A box turned by a multiple of 90 degrees: its faces are straight lines of the grid's kind.
bool axis_aligned(const Obstacle &o)
{
    if (o.shape != Obstacle::Shape::Box) return false;
    const double quarter = 1.57079632679489661923;
    const double turns = o.angle / quarter;
    return std::fabs(turns - std::round(turns)) < 1e-6;
}

// Whether [a, b] lies inside one obstacle's extent along `axis`.
bool inside_an_obstacle(const Scenario &s, int axis, double a, double b)
{
    for (const Obstacle &o : s.obstacles) {
        double lo = 0.0, hi = 0.0;
        extent(o, axis, &lo, &hi);
        if (lo <= a + 1e-9 && b <= hi + 1e-9) return true;
    }
    return false;
}

// `encode auto cell M`, else twice the step: the side a turn is judged against and widened from.
double unwidened_cell_side(const Scenario &s)
{
    return s.encoding.max_cell > 0.0 ? s.encoding.max_cell : 2.0 * s.actions.step;
}

}  // namespace

bool turns_inside_cells(const Scenario &s)
{
    return 2.0 * robot_radius(s.robot) < unwidened_cell_side(s);
}

// Why widen: a turn at a cell's centre sweeps the robot's corners round a circle of its
// half-diagonal, so a cell only just wider than the diagonal leaves millimetres to a face, and
// every wobble of a real stop bumps. A 0.34 x 0.28 m base (0.44 m across its corners) in the lab
// robot's 0.5 m cells relapsed in 3.1 % of the episodes after learning on the tuning rooms, and in
// 1.1 % in 0.6 m cells. A robot that cannot turn inside twice its step (the sonar robot) keeps
// those cells and its `past` stops: widening them to its turn would make steps of a metre.
double fit_cell_side(const Scenario &s)
{
    const double side = unwidened_cell_side(s);
    if (s.encoding.max_cell > 0.0 || !turns_inside_cells(s)) return side;
    return std::max(side, 2.0 * robot_radius(s.robot) + 2.0 * kTurnClearance);
}

bool fit_axis(const Scenario &s, int axis, double max_side, bool goal_square, std::vector<double> *edges,
              std::string *error)
{
    const double side = axis == 0 ? s.arena_w : s.arena_h;
    // 1. The faces, sorted; near ones merged, none next to a wall.
    std::vector<double> faces;
    for (const Obstacle &o : s.obstacles) {
        if (!axis_aligned(o)) continue;  // a round or turned face crosses cells whatever the cuts
        double lo = 0.0, hi = 0.0;
        extent(o, axis, &lo, &hi);
        for (double f : {lo, hi}) {
            if (f > kFaceMerge && f < side - kFaceMerge) faces.push_back(f);
        }
    }
    if (goal_square) {
        const double g = axis == 0 ? s.goal.cx : s.goal.cy;
        for (double f : {g - s.goal.radius, g + s.goal.radius}) {
            if (f > kFaceMerge && f < side - kFaceMerge) faces.push_back(f);
        }
    }
    std::sort(faces.begin(), faces.end());
    std::vector<double> cuts = {0.0};
    for (double f : faces) {
        if (f - cuts.back() >= kFaceMerge) cuts.push_back(f);
    }
    if (side - cuts.back() < kFaceMerge) cuts.pop_back();
    cuts.push_back(side);
    // 2. Gaps narrower than `past`: a thin obstacle keeps its own cell; free space closes it. A
    //    gap exactly `past` wide in the firmware's single precision is closed too, inside an
    //    obstacle or not: the firmware would neither step over it nor stop `past` inside it, and
    //    refuses the grid (a 0.16 m box against the wall with paper-lab's `past 0.16`).
    const double past = s.actions.past;
    for (bool changed = true; changed;) {
        changed = false;
        for (std::size_t i = 0; i + 1 < cuts.size(); i++) {
            const double a = cuts[i], b = cuts[i + 1];
            const bool as_wide_as_past = static_cast<float>(b) - static_cast<float>(a) == static_cast<float>(past);
            const bool keeps_its_cell = b - a >= past || inside_an_obstacle(s, axis, a, b);
            if (keeps_its_cell && !as_wide_as_past) continue;
            if (i == 0) {
                cuts.erase(cuts.begin() + 1);  // next to the wall: the wall's cut stays
            } else if (i + 2 == cuts.size()) {
                cuts.erase(cuts.begin() + static_cast<long>(i));
            } else {
                cuts[i] = 0.5 * (a + b);
                cuts.erase(cuts.begin() + static_cast<long>(i) + 1);
            }
            changed = true;
            break;
        }
    }
    // 3. Wide gaps into equal cells.
    edges->assign(1, 0.0);
    for (std::size_t i = 0; i + 1 < cuts.size(); i++) {
        const double a = cuts[i], b = cuts[i + 1];
        const int n = std::max(1, static_cast<int>(std::lround((b - a) / max_side)));
        for (int k = 1; k < n; k++) edges->push_back(a + (b - a) * k / n);
        edges->push_back(b);
    }
    edges->back() = side;
    // 4. The firmware's bound.
    const int cells = static_cast<int>(edges->size()) - 1;
    if (cells > kMaxGridCells) {
        *error = std::string("encode auto: the room needs ") + std::to_string(cells) + " cells along " +
                 (axis == 0 ? "x" : "y") + ", more than " + std::to_string(kMaxGridCells) +
                 " (a larger 'cell', or fewer obstacles)";
        return false;
    }
    return true;
}

int faces_inside_cells(const Scenario &s)
{
    if (s.encoding.fitted) return 0;
    int n = 0;
    for (const Obstacle &o : s.obstacles) {
        if (!axis_aligned(o)) continue;
        for (int axis = 0; axis < 2; axis++) {
            const double side = axis == 0 ? s.arena_w : s.arena_h;
            const double cell = side / (1 << (axis == 0 ? s.encoding.x_bits : s.encoding.y_bits));
            double lo = 0.0, hi = 0.0;
            extent(o, axis, &lo, &hi);
            for (double f : {lo, hi}) {
                if (f <= kFaceMerge || f >= side - kFaceMerge) continue;
                const double in = f - std::floor(f / cell) * cell;
                n += std::min(in, cell - in) > s.actions.past;
            }
        }
    }
    return n;
}

}  // namespace world
