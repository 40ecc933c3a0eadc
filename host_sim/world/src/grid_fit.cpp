// SPDX-License-Identifier: MIT
// dynaqpc world: a state grid fitted to the room (grid_fit.h: the rule and why).
#include "world/grid_fit.h"

#include <algorithm>
#include <array>
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

}  // namespace

bool axis_aligned(const Obstacle &o)
{
    if (o.shape != Obstacle::Shape::Box) return false;
    const double quarter = 1.57079632679489661923;
    const double turns = o.angle / quarter;
    return std::fabs(turns - std::round(turns)) < 1e-6;
}

namespace {

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

namespace {

// Rule 3 on the gap [a, b], with rule 5's faces: the gap's n cells shared among the pieces its
// faces cut it into (one each, the rest one at a time to the piece with the widest cells), a face
// taken, in order, only while every cell stays as wide as the robot's diagonal: it turns in them.
void split_gap(const Scenario &s, double a, double b, double max_side, const std::vector<double> &pinch,
               std::vector<double> *edges)
{
    const int n = std::max(1, static_cast<int>(std::lround((b - a) / max_side)));
    std::vector<double> pieces = {a, b};
    std::vector<int> counts = {n};
    for (double f : pinch) {  // sorted
        if (f <= a + kFaceMerge || f >= b - kFaceMerge) continue;
        std::vector<double> p = pieces;
        p.insert(std::upper_bound(p.begin(), p.end(), f), f);
        const std::size_t m = p.size() - 1;
        if (static_cast<int>(m) > n) break;
        std::vector<int> c(m, 1);
        for (int left = n - static_cast<int>(m); left > 0; left--) {
            std::size_t widest = 0;
            for (std::size_t k = 1; k < m; k++) {
                if ((p[k + 1] - p[k]) / c[k] > (p[widest + 1] - p[widest]) / c[widest]) widest = k;
            }
            c[widest]++;
        }
        bool turns = true;
        for (std::size_t k = 0; k < m; k++) turns = turns && (p[k + 1] - p[k]) / c[k] >= 2.0 * robot_radius(s.robot);
        if (!turns) continue;
        pieces = p;
        counts = c;
    }
    for (std::size_t q = 0; q + 1 < pieces.size(); q++) {
        for (int k = 1; k < counts[q]; k++) edges->push_back(pieces[q] + (pieces[q + 1] - pieces[q]) * k / counts[q]);
        edges->push_back(pieces[q + 1]);
    }
}

bool fit_axis_with(const Scenario &s, int axis, double max_side, GoalCut goal_cut, const std::vector<double> &pinch,
                   std::vector<double> *edges, std::string *error)
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
    if (goal_cut != GoalCut::None) {
        // GoalCut::Square leaves out a face that would cut a sliver narrower than a turn off the
        // wall or a face beside it: the goal's cell reaches to them instead.
        const double turn = 2.0 * robot_radius(s.robot);
        const std::size_t room_faces = faces.size();  // the goal's own faces come after
        auto sliver = [&](double f) {
            if (f < turn || side - f < turn) return true;
            for (std::size_t i = 0; i < room_faces; i++) {
                if (std::fabs(f - faces[i]) < turn) return true;
            }
            return false;
        };
        const double g = axis == 0 ? s.goal.cx : s.goal.cy;
        for (double f : {g - s.goal.radius, g + s.goal.radius}) {
            if (goal_cut == GoalCut::Square && sliver(f)) continue;
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
    // 3. Wide gaps into equal cells (5. some cut at a pinching pillar's face instead).
    edges->assign(1, 0.0);
    for (std::size_t i = 0; i + 1 < cuts.size(); i++) split_gap(s, cuts[i], cuts[i + 1], max_side, pinch, edges);
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

// Rule 5's faces, added to pinch[axis] (kept sorted): per cell whose centre the robot stands on
// (everything farther than half its width), each round obstacle nearer than its half-diagonal +
// kPinchClearance gives the faces of its bounding square that lie inside the cell. True if any
// was new.
bool add_pinch_faces(const Scenario &s, const std::vector<double> &xe, const std::vector<double> &ye,
                     std::vector<double> pinch[2])
{
    const double reach = robot_radius(s.robot) + kPinchClearance;
    bool added = false;
    for (std::size_t i = 0; i + 1 < xe.size(); i++) {
        for (std::size_t j = 0; j + 1 < ye.size(); j++) {
            const double lo[2] = {xe[i], ye[j]}, hi[2] = {xe[i + 1], ye[j + 1]};
            const double cx = 0.5 * (lo[0] + hi[0]), cy = 0.5 * (lo[1] + hi[1]);
            if (!(clearance(s, cx, cy) > 0.5 * s.robot.width)) continue;  // no stop there
            for (const Obstacle &o : s.obstacles) {
                if (o.shape != Obstacle::Shape::Circle || !(obstacle_distance(o, cx, cy) < reach)) continue;
                for (int axis = 0; axis < 2; axis++) {
                    const double mid = axis == 0 ? o.cx : o.cy;
                    for (double f : {mid - o.radius, mid + o.radius}) {
                        std::vector<double> &p = pinch[axis];
                        if (f <= lo[axis] + kFaceMerge || f >= hi[axis] - kFaceMerge) continue;
                        if (std::find(p.begin(), p.end(), f) != p.end()) continue;
                        p.insert(std::upper_bound(p.begin(), p.end(), f), f);
                        added = true;
                    }
                }
            }
        }
    }
    return added;
}

}  // namespace

bool fit_axis(const Scenario &s, int axis, double max_side, GoalCut goal_cut, std::vector<double> *edges,
              std::string *error)
{
    return fit_axis_with(s, axis, max_side, goal_cut, {}, edges, error);
}

// Why rule 5: a centred stop a centimetre beyond a turn's reach of a bin passes or bumps by how
// the stop wobbled, and the model keeps the bump: on paper-lab-aisles that closed the only way out
// of the first aisle (13.5 % of episodes relapsed; 0.8 % without the bin). Cutting at the bin's
// faces as at a wall's adds a line of cells across the room, narrow ones beside walls among them:
// that was worse on the tuning rooms (docs/agent.md, "A grid that fits the room": 1.3 % relapses
// against 0.7 %, 432 real steps against 346). Moving a gap's equal cuts onto the face instead keeps
// its cell count and every cell a turn wide. Turned boxes are left out: their bounding faces lie
// off the box, and moving cuts onto them fixed one generated room but raised the relapses of the
// users-tune furniture rooms from 0.2 % to 2.2 %. Faces only grow (two per pillar and axis), so
// the loop ends; a grid the faces would take past kMaxGridCells keeps the fit without them.
bool fit_grid(const Scenario &s, double max_side, GoalCut goal_cut, bool centred, std::vector<double> *x_edges,
              std::vector<double> *y_edges, std::string *error)
{
    if (!fit_axis(s, 0, max_side, goal_cut, x_edges, error) ||
        !fit_axis(s, 1, max_side, goal_cut, y_edges, error)) {
        return false;
    }
    if (!centred) return true;
    std::vector<double> pinch[2];
    while (add_pinch_faces(s, *x_edges, *y_edges, pinch)) {
        std::vector<double> x, y;
        std::string ignored;
        if (!fit_axis_with(s, 0, max_side, goal_cut, pinch[0], &x, &ignored) ||
            !fit_axis_with(s, 1, max_side, goal_cut, pinch[1], &y, &ignored)) {
            break;
        }
        *x_edges = x;
        *y_edges = y;
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

namespace {

// The nearest wall or obstacle to (x, y): its distance and its line (0: the arena's wall).
double nearest(const Scenario &s, double x, double y, int *line)
{
    double d = wall_distance(s, x, y);
    *line = 0;
    for (const Obstacle &o : s.obstacles) {
        const double od = obstacle_distance(o, x, y);
        if (od < d) {
            d = od;
            *line = o.line;
        }
    }
    return d;
}

// Whether a straight step from (x0, y0) to (x1, y1) keeps `side` clear all the way (1 cm samples).
// The samples, a run of kRun at a time, ask only the walls and obstacles that come within `side`
// (and a micrometre) of the run (and of the step): a distance changes no faster than the point
// moves, so a wall or obstacle farther than that from a run's middle, less half the run's length,
// is farther than `side` from every sample of it, and the answer is clearance()'s. Why: the
// parser walks a fitted grid up to 11 times (rule 7), and asking all 256 obstacles at every
// centimetre of a 32 x 32 grid of 20 m cells took 8.5 s a walk.
bool step_clear(const Scenario &s, double x0, double y0, double x1, double y1, double side)
{
    constexpr int kRun = 50;
    const int n = std::max(1, static_cast<int>(std::ceil(std::hypot(x1 - x0, y1 - y0) / 0.01)));
    auto at = [&](int k, double *x, double *y) {
        const double f = static_cast<double>(k) / n;
        *x = x0 + f * (x1 - x0);
        *y = y0 + f * (y1 - y0);
    };
    // The obstacles near samples first to last, of those in `from`; whether the walls are far.
    auto near_run = [&](int first, int last, const std::vector<const Obstacle *> &from,
                        std::vector<const Obstacle *> *near) {
        double ax = 0, ay = 0, bx = 0, by = 0;
        at(first, &ax, &ay);
        at(last, &bx, &by);
        const double mx = 0.5 * (ax + bx), my = 0.5 * (ay + by), half = 0.5 * std::hypot(bx - ax, by - ay);
        near->clear();
        for (const Obstacle *o : from) {
            if (!(obstacle_distance(*o, mx, my) - half >= side + 1e-6)) near->push_back(o);
        }
        return wall_distance(s, mx, my) - half >= side + 1e-6;
    };
    std::vector<const Obstacle *> all, step, near;
    for (const Obstacle &o : s.obstacles) all.push_back(&o);
    near_run(0, n, all, &step);
    for (int first = 0; first <= n; first += kRun) {
        const int last = std::min(n, first + kRun - 1);
        const bool walls_far = near_run(first, last, step, &near);
        if (walls_far && near.empty()) continue;
        for (int k = first; k <= last; k++) {
            double x = 0, y = 0;
            at(k, &x, &y);
            if (!walls_far && !(wall_distance(s, x, y) >= side)) return false;
            for (const Obstacle *o : near) {
                if (obstacle_distance(*o, x, y) < side) return false;  // a NaN passes, as in clearance()
            }
        }
    }
    return true;
}

// The stops an aligned step can end at along one axis, as the firmware's stop_beyond_() places
// them: a cell at least twice `past` wide has its centre; a narrower one the two stops `past`
// inside either edge (entered from below, from above); a cell narrower than `past` inside the
// grid lies in a partition and has none (a step crosses it).
struct AxisStops {
    std::vector<double> at;    // stop positions, ascending
    std::vector<int> cell;     // the cell each lies in
    std::vector<int> up, down; // the stop a step towards +/- reaches; -1 at the wall
};

AxisStops axis_stops(const Scenario &s, int axis)
{
    AxisStops a;
    const int n = grid_cells(s, axis);
    const double past = s.actions.past;
    std::vector<int> enter_up(static_cast<std::size_t>(n), -1), enter_down(static_cast<std::size_t>(n), -1);
    for (int k = 0; k < n; k++) {
        double lo = 0, hi = 0;
        grid_span(s, axis, k, &lo, &hi);
        const double side = hi - lo;
        if (side < past && k > 0 && k + 1 < n) continue;  // stepped over
        enter_up[static_cast<std::size_t>(k)] = static_cast<int>(a.at.size());
        if (side >= 2.0 * past) {
            a.at.push_back(0.5 * (lo + hi));
            a.cell.push_back(k);
        } else {
            a.at.push_back(lo + past);
            a.cell.push_back(k);
            a.at.push_back(hi - past);
            a.cell.push_back(k);
        }
        enter_down[static_cast<std::size_t>(k)] = static_cast<int>(a.at.size()) - 1;
    }
    for (std::size_t m = 0; m < a.at.size(); m++) {
        int up = -1, down = -1;
        for (int k = a.cell[m] + 1; k < n && up < 0; k++) up = enter_up[static_cast<std::size_t>(k)];
        for (int k = a.cell[m] - 1; k >= 0 && down < 0; k--) down = enter_down[static_cast<std::size_t>(k)];
        a.up.push_back(up);
        a.down.push_back(down);
    }
    return a;
}

}  // namespace

// Why the firmware's stops and not each cell's centre: a thin partition's cell has a centre a
// turn cannot clear but no stop (steps cross it), and a doorway's cell narrower than twice
// `past` stops the robot `past` inside the edge it crossed; walking centres warned of 27 of a
// partitioned room's 102 cells for ways the robot takes.
StopWalkReport stop_walk(const Scenario &s)
{
    StopWalkReport rep;
    if (!s.actions.centred) return rep;
    const AxisStops ax = axis_stops(s, 0), ay = axis_stops(s, 1);
    const int nx = static_cast<int>(ax.at.size()), ny = static_cast<int>(ay.at.size());
    const double turn = robot_radius(s.robot), side = 0.5 * s.robot.width;
    const std::size_t nodes = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
    std::vector<TightStop> stop(nodes);
    std::vector<char> stand(nodes, 0), reached(nodes, 0);
    std::vector<std::array<int, 4>> next(nodes);
    for (int j = 0; j < ny; j++) {
        for (int i = 0; i < nx; i++) {
            const std::size_t k = static_cast<std::size_t>(j * nx + i);
            TightStop &t = stop[k];
            t.i = ax.cell[static_cast<std::size_t>(i)];
            t.j = ay.cell[static_cast<std::size_t>(j)];
            t.x = ax.at[static_cast<std::size_t>(i)];
            t.y = ay.at[static_cast<std::size_t>(j)];
            t.clearance = nearest(s, t.x, t.y, &t.line);
            const int ui = ax.up[static_cast<std::size_t>(i)], di = ax.down[static_cast<std::size_t>(i)];
            const int uj = ay.up[static_cast<std::size_t>(j)], dj = ay.down[static_cast<std::size_t>(j)];
            next[k] = {ui < 0 ? -1 : j * nx + ui, di < 0 ? -1 : j * nx + di, uj < 0 ? -1 : uj * nx + i,
                       dj < 0 ? -1 : dj * nx + i};
            stand[k] = t.clearance >= turn;
            rep.cells += stand[k];
        }
    }
    // The stops that reach a goal stop: from the goal backwards over the clear steps between stops
    // the robot can turn at (a step from a narrow cell's stop need not come back to it).
    std::vector<std::vector<int>> into(nodes);
    std::vector<int> queue;
    for (std::size_t k = 0; k < nodes; k++) {
        if (!stand[k]) continue;
        for (int m : next[k]) {
            if (m < 0 || !stand[static_cast<std::size_t>(m)]) continue;
            const TightStop &a = stop[k], &b = stop[static_cast<std::size_t>(m)];
            if (!step_clear(s, a.x, a.y, b.x, b.y, side)) continue;
            into[static_cast<std::size_t>(m)].push_back(static_cast<int>(k));
        }
        if (in_goal(s, stop[k].x, stop[k].y)) {
            reached[k] = 1;
            queue.push_back(static_cast<int>(k));
        }
    }
    for (std::size_t head = 0; head < queue.size(); head++) {
        for (int m : into[static_cast<std::size_t>(queue[head])]) {
            if (reached[static_cast<std::size_t>(m)]) continue;
            reached[static_cast<std::size_t>(m)] = 1;
            queue.push_back(m);
        }
    }
    std::vector<char> listed(nodes, 0);
    for (std::size_t k = 0; k < nodes; k++) {
        if (!stand[k] || reached[k]) continue;
        rep.stranded++;
        for (int m : next[k]) {
            if (m < 0 || listed[static_cast<std::size_t>(m)]) continue;
            const TightStop &t = stop[static_cast<std::size_t>(m)];
            if (!(t.clearance > 0.0 && t.clearance < turn)) continue;  // covered, or a stop it stands in
            listed[static_cast<std::size_t>(m)] = 1;
            rep.blocking.push_back(t);
        }
    }
    std::stable_sort(rep.blocking.begin(), rep.blocking.end(),
                     [](const TightStop &a, const TightStop &b) { return a.clearance < b.clearance; });
    return rep;
}

}  // namespace world
