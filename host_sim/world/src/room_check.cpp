// SPDX-License-Identifier: MIT
// dynaqpc world: the passage check and the longest path of a room (rooms.h), on the parsed file:
// every start reaches the goal through passages at least the robot's diagonal wide, and how many
// actions the farthest start needs at best.
#include "world/rooms.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <queue>
#include <string>
#include <utility>
#include <vector>

#include "room_text.h"
#include "world/grid_fit.h"

namespace world {

using namespace room_text;

namespace {

// The passage check's grid (start_grid_step()): which points are free, may hold a start, are in
// the goal. check_passages() and longest_path() both stand on it.
enum : unsigned char { kFree = 1, kStart = 2, kGoal = 4, kReached = 8 };

struct FreeGrid {
    double step = 0;
    long nx = 0, ny = 0;
    std::vector<unsigned char> cell;  // kFree | kStart | kGoal per point, j * nx + i
    std::vector<double> clear;        // the distance to the nearest wall or obstacle, up to `enough`
    double x(long i) const { return step / 2 + i * step; }
    double y(long j) const { return step / 2 + j * step; }
};

FreeGrid free_grid(const Scenario &s, PassageReport *rep)
{
    FreeGrid g;
    g.step = start_grid_step(s);
    const double step = g.step;
    const long nx = g.nx = static_cast<long>(std::ceil(s.arena_w / step - 0.5));
    const long ny = g.ny = static_cast<long>(std::ceil(s.arena_h / step - 0.5));
    const double need = robot_radius(s.robot);
    g.cell.assign(static_cast<std::size_t>(nx * ny), 0);
    // clear[k]: the clearance of point k where it is below `enough`, else at least `enough`. Each
    // obstacle is measured only over the points its bounding box, grown by `enough`, covers: the
    // others are farther from it.
    const double enough = need + s.start.margin + step;
    std::vector<double> &clear = g.clear;
    clear.resize(static_cast<std::size_t>(nx * ny));
    for (long j = 0; j < ny; j++) {
        for (long i = 0; i < nx; i++) {
            const double x = step / 2 + i * step, y = step / 2 + j * step;
            clear[static_cast<std::size_t>(j * nx + i)] = wall_distance(s, x, y);
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
            unsigned char &c = g.cell[static_cast<std::size_t>(j * nx + i)];
            if (cl < need) continue;
            c = kFree;
            rep->free_points++;
            // The world's own rule decides a start; where the clearance is too small it cannot hold.
            if (cl >= need + s.start.margin - 1e-12 && start_position_ok(s, x, y)) {
                c |= kStart;
                rep->start_points++;
            }
            if (in_goal(s, x, y)) {
                c |= kGoal;
                rep->goal_points++;
            }
        }
    }
    return g;
}

// The 4-neighbours of point k on the passage grid (-1 past its edges).
std::array<long, 4> neighbours(const FreeGrid &g, long k)
{
    const long i = k % g.nx, j = k / g.nx;
    return {i > 0 ? k - 1 : -1, i + 1 < g.nx ? k + 1 : -1, j > 0 ? k - g.nx : -1, j + 1 < g.ny ? k + g.nx : -1};
}

// Points reached from `seeds` through points whose clearance is above `above`, marked in `in`.
void flood_above(const FreeGrid &g, const std::vector<long> &seeds, double above, std::vector<char> *in)
{
    std::vector<long> queue = seeds;
    for (long k : seeds) (*in)[static_cast<std::size_t>(k)] = 1;
    for (std::size_t head = 0; head < queue.size(); head++) {
        for (long m : neighbours(g, queue[head])) {
            if (m >= 0 && !(*in)[static_cast<std::size_t>(m)] && g.clear[static_cast<std::size_t>(m)] > above) {
                (*in)[static_cast<std::size_t>(m)] = 1;
                queue.push_back(m);
            }
        }
    }
}

// Where the way from a stranded point `from` to the goal is too narrow, and how wide it is there.
// Of all the ways, the widest is only as wide as twice its narrowest point's clearance b (a
// max-min search from the goal). The points wider than b split in two: those joined to the goal
// and those joined to `from`; the pinch is the middle of the shortest way between them through
// points as wide as b: a doorway, not a wall the way runs beside.
struct Pinch {
    long at = -1;
    double clearance = 0;
};

// Per point, the narrowest clearance of the widest way from it to the goal (a max-min search from
// the goal points; -1 where no way leads, or beyond `from` once it is reached when from >= 0).
std::vector<double> widest_ways(const FreeGrid &g, long from, std::vector<long> *goal)
{
    const long n = g.nx * g.ny;
    std::vector<double> best(static_cast<std::size_t>(n), -1.0);
    std::priority_queue<std::pair<double, long>> open;
    for (long k = 0; k < n; k++) {
        if (g.cell[static_cast<std::size_t>(k)] & kGoal) {
            goal->push_back(k);
            best[static_cast<std::size_t>(k)] = g.clear[static_cast<std::size_t>(k)];
            open.push({best[static_cast<std::size_t>(k)], k});
        }
    }
    while (!open.empty()) {
        const auto [w, k] = open.top();
        open.pop();
        if (w < best[static_cast<std::size_t>(k)]) continue;  // a wider way reached it first
        if (k == from) break;
        for (long m : neighbours(g, k)) {
            if (m < 0 || g.clear[static_cast<std::size_t>(m)] <= 0.0) continue;
            const double wm = std::min(w, g.clear[static_cast<std::size_t>(m)]);
            if (wm > best[static_cast<std::size_t>(m)]) {
                best[static_cast<std::size_t>(m)] = wm;
                open.push({wm, m});
            }
        }
    }
    return best;
}

// The pinch on the widest way from `from`, given widest_ways()' `best` (complete at least up to
// `from`) and its goal points.
Pinch pinch_on(const FreeGrid &g, const std::vector<double> &best, const std::vector<long> &goal, long from)
{
    const long n = g.nx * g.ny;
    Pinch p;
    const double b = best[static_cast<std::size_t>(from)];
    if (b <= 0.0) return p;  // walled off entirely
    std::vector<char> to_goal(static_cast<std::size_t>(n), 0), to_from(static_cast<std::size_t>(n), 0);
    flood_above(g, goal, b, &to_goal);
    flood_above(g, {from}, b, &to_from);
    std::vector<long> parent(static_cast<std::size_t>(n), -2), queue;
    for (long k = 0; k < n; k++) {
        if (to_goal[static_cast<std::size_t>(k)]) {
            parent[static_cast<std::size_t>(k)] = -1;
            queue.push_back(k);
        }
    }
    for (std::size_t head = 0; head < queue.size(); head++) {
        const long k = queue[head];
        if (to_from[static_cast<std::size_t>(k)]) {
            std::vector<long> way;  // the points between the two sides
            for (long q = parent[static_cast<std::size_t>(k)]; q >= 0 && !to_goal[static_cast<std::size_t>(q)];
                 q = parent[static_cast<std::size_t>(q)]) {
                way.push_back(q);
            }
            p.at = way.empty() ? k : way[way.size() / 2];
            p.clearance = b;
            return p;
        }
        for (long m : neighbours(g, k)) {
            if (m >= 0 && parent[static_cast<std::size_t>(m)] == -2 && g.clear[static_cast<std::size_t>(m)] >= b) {
                parent[static_cast<std::size_t>(m)] = k;
                queue.push_back(m);
            }
        }
    }
    return p;
}

Pinch widest_way_pinch(const FreeGrid &g, long from)
{
    std::vector<long> goal;
    const std::vector<double> best = widest_ways(g, from, &goal);
    return pinch_on(g, best, goal, from);
}

using PlaceLinks = std::vector<std::array<std::vector<long>, 4>>;

// The actions from every (place, heading) to the goal at best, -1 where none leads there. Every
// move has its reverse (forward / backward along the same heading, left / right), so the
// distances from the goal are the distances to it.
std::vector<long> distances_from_goal(const PlaceLinks &next, const std::vector<unsigned char> &flags)
{
    const long places = static_cast<long>(next.size());
    std::vector<long> dist(static_cast<std::size_t>(places * 4), -1);
    std::vector<long> queue;
    for (long p = 0; p < places; p++) {
        if (!(flags[static_cast<std::size_t>(p)] & kGoal)) continue;
        for (int h = 0; h < 4; h++) {
            dist[static_cast<std::size_t>(p * 4 + h)] = 0;
            queue.push_back(p * 4 + h);
        }
    }
    for (std::size_t head = 0; head < queue.size(); head++) {
        const long st = queue[head], p = st / 4, d = dist[static_cast<std::size_t>(st)];
        const int h = static_cast<int>(st % 4);
        auto visit = [&](long to) {
            if (dist[static_cast<std::size_t>(to)] < 0) {
                dist[static_cast<std::size_t>(to)] = d + 1;
                queue.push_back(to);
            }
        };
        visit(p * 4 + (h + 1) % 4);
        visit(p * 4 + (h + 3) % 4);
        for (long q : next[static_cast<std::size_t>(p)][h]) visit(q * 4 + h);
        for (long q : next[static_cast<std::size_t>(p)][(h + 2) % 4]) visit(q * 4 + h);
    }
    return dist;
}

// The start (place, heading) pairs' fewest actions `dist` into `rep`: how many, how many reach no
// goal, how many need d actions, the longest (-1 when some reach none).
void count_starts(const std::vector<long> &dist, const std::vector<unsigned char> &flags, PathReport *rep)
{
    long longest = 0;
    for (std::size_t p = 0; p < flags.size(); p++) {
        if (!(flags[p] & kStart)) continue;
        for (std::size_t h = 0; h < 4; h++) {
            rep->start_states++;
            const long d = dist[p * 4 + h];
            if (d < 0) {
                rep->stranded++;
                continue;
            }
            longest = std::max(longest, d);
            if (rep->by_actions.size() <= static_cast<std::size_t>(d)) rep->by_actions.resize(static_cast<std::size_t>(d) + 1);
            rep->by_actions[static_cast<std::size_t>(d)]++;
        }
    }
    rep->longest = rep->stranded > 0 || rep->start_states == 0 ? -1 : longest;
}

// Where a cut-off start's widest way narrows, as check_passages() says it. The grid measures a
// width up to about a step under the true one (its points miss a doorway's middle by up to half a
// step), so a door a little wider than the diagonal may be refused: the width is given with as
// many decimals as tell it from the diagonal, and what width the check is sure to pass.
std::string pinch_text(const FreeGrid &g, const Pinch &p, double diag)
{
    if (p.at < 0) return "; walls close it off from the goal";
    const double width = 2.0 * p.clearance;  // below diag: a free point clears the robot's radius
    int digits = 3;
    char w[32], d[32];
    for (;; digits++) {
        std::snprintf(w, sizeof w, "%.*f", digits, width);
        std::snprintf(d, sizeof d, "%.*f", digits, diag);
        if (std::strcmp(w, d) != 0 || digits == 6) break;
    }
    const std::string under = digits > 3 ? std::string(" (under the diagonal's ") + d + " m)" : "";
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "; the widest way from there narrows to %s m%s at (%.3f, %.3f) on that grid, which reads a "
                  "width up to a step short: leave about %.3f m (the diagonal and a step) or more",
                  w, under.c_str(), g.x(p.at % g.nx), g.y(p.at / g.nx), std::ceil((diag + g.step) * 1000.0) / 1000.0);
    return buf;
}

}  // namespace

PassageReport check_passages(const Scenario &s)
{
    PassageReport rep;
    FreeGrid g = free_grid(s, &rep);
    const long nx = g.nx, ny = g.ny;
    const double need = robot_radius(s.robot);
    std::vector<unsigned char> &cell = g.cell;
    std::vector<long> queue;
    for (long k = 0; k < nx * ny; k++) {
        if (cell[static_cast<std::size_t>(k)] & kGoal) {
            cell[static_cast<std::size_t>(k)] |= kReached;
            queue.push_back(k);
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
        for (long n : neighbours(g, queue[head])) {
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
                      "no passage the check's %.3f m grid finds at least the robot's diagonal (%.3f m) wide",
                      rep.stranded_points, rep.start_points, g.x(first % nx), g.y(first / nx), g.step, diag);
        rep.problem = buf + pinch_text(g, widest_way_pinch(g, first), diag);
        return rep;
    }
    rep.ok = true;
    return rep;
}

PathReport longest_path(const Scenario &s)
{
    PathReport rep;
    PassageReport counts;
    const FreeGrid g = free_grid(s, &counts);
    const long nx = g.nx, ny = g.ny, n = nx * ny;
    const int cx = rep.nx = grid_cells(s, 0), cy = rep.ny = grid_cells(s, 1);
    const double cw = s.arena_w / cx, ch = s.arena_h / cy;
    auto cell_of = [&](long k) {
        if (s.encoding.fitted) return grid_cell(s, 1, g.y(k / nx)) * cx + grid_cell(s, 0, g.x(k % nx));
        const int i = std::min(cx - 1, static_cast<int>(g.x(k % nx) / cw));
        const int j = std::min(cy - 1, static_cast<int>(g.y(k / nx) / ch));
        return j * cx + i;
    };
    // Places: free points joined to their four neighbours within one state cell.
    std::vector<long> place(static_cast<std::size_t>(n), -1);
    std::vector<int> place_cell;
    std::vector<long> queue;
    for (long k0 = 0; k0 < n; k0++) {
        if (!(g.cell[static_cast<std::size_t>(k0)] & kFree) || place[static_cast<std::size_t>(k0)] >= 0) continue;
        const long id = static_cast<long>(place_cell.size());
        const int c = cell_of(k0);
        place_cell.push_back(c);
        queue.assign(1, k0);
        place[static_cast<std::size_t>(k0)] = id;
        for (std::size_t head = 0; head < queue.size(); head++) {
            const long k = queue[head], i = k % nx, j = k / nx;
            const long next[4] = {i > 0 ? k - 1 : -1, i + 1 < nx ? k + 1 : -1, j > 0 ? k - nx : -1,
                                  j + 1 < ny ? k + nx : -1};
            for (long m : next) {
                if (m < 0 || !(g.cell[static_cast<std::size_t>(m)] & kFree) ||
                    place[static_cast<std::size_t>(m)] >= 0 || cell_of(m) != c) {
                    continue;
                }
                place[static_cast<std::size_t>(m)] = id;
                queue.push_back(m);
            }
        }
    }
    const long places = rep.places = static_cast<long>(place_cell.size());
    // next[p][h]: the places one cell away along heading h (0 +x, 1 +y, 2 -x, 3 -y) that p joins.
    PlaceLinks next(static_cast<std::size_t>(places));
    std::vector<unsigned char> flags(static_cast<std::size_t>(places), 0);
    for (long k = 0; k < n; k++) {
        const unsigned char c = g.cell[static_cast<std::size_t>(k)];
        if (!(c & kFree)) continue;
        const long p = place[static_cast<std::size_t>(k)];
        flags[static_cast<std::size_t>(p)] |= c;
        const long i = k % nx, j = k / nx;
        const long right = i + 1 < nx ? k + 1 : -1, up = j + 1 < ny ? k + nx : -1;
        for (int d = 0; d < 2; d++) {
            const long m = d == 0 ? right : up;
            if (m < 0 || !(g.cell[static_cast<std::size_t>(m)] & kFree)) continue;
            const long q = place[static_cast<std::size_t>(m)];
            if (place_cell[static_cast<std::size_t>(q)] == place_cell[static_cast<std::size_t>(p)]) continue;
            next[static_cast<std::size_t>(p)][d].push_back(q);      // +x or +y
            next[static_cast<std::size_t>(q)][d + 2].push_back(p);  // -x or -y
        }
    }
    for (auto &per_heading : next) {
        for (std::vector<long> &v : per_heading) {
            std::sort(v.begin(), v.end());
            v.erase(std::unique(v.begin(), v.end()), v.end());
        }
    }
    count_starts(distances_from_goal(next, flags), flags, &rep);
    return rep;
}

// Why: a way to the goal narrower than a turn with kTurnClearance each side, past an obstacle at
// an angle or a round one, is one the grid's stops (square to the arena, cut only at square faces)
// pass by centimetres: rooms a new user drew relapsed there without a warning
// (docs/results/users-rooms.md, "Eight rooms a second new user drew").
SlotReport tight_slot(const Scenario &s)
{
    SlotReport rep;
    PassageReport counts;
    const FreeGrid g = free_grid(s, &counts);
    std::vector<long> goal;
    const std::vector<double> best = widest_ways(g, -1, &goal);
    const double limit = robot_radius(s.robot) + kPinchClearance;
    std::map<double, std::pair<long, long>> by_width;  // a bottleneck's clearance: its starts, one of them
    for (long k = 0; k < g.nx * g.ny; k++) {
        if (!(g.cell[static_cast<std::size_t>(k)] & kStart)) continue;
        rep.starts++;
        const double b = best[static_cast<std::size_t>(k)];
        if (b > 0.0 && b < limit) {  // behind a slot
            auto &e = by_width[b];
            if (e.first++ == 0) e.second = k;
        }
    }
    rep.limit = 2.0 * limit;
    for (const auto &[b, e] : by_width) {
        const Pinch p = pinch_on(g, best, goal, e.second);  // one search serves every start
        if (p.at < 0) continue;
        const double x = g.x(p.at % g.nx), y = g.y(p.at / g.nx);
        // The obstacles that make the pinch: those within a grid step of its clearance.
        for (const Obstacle &o : s.obstacles) {
            if (axis_aligned(o) || !(obstacle_distance(o, x, y) < b + g.step)) continue;
            if (rep.behind == 0 || 2.0 * b < rep.width) {
                rep.width = 2.0 * b;
                rep.x = x;
                rep.y = y;
                rep.line = o.line;
            }
            rep.behind += e.first;
            break;
        }
    }
    return rep;
}

}  // namespace world
