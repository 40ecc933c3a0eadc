// SPDX-License-Identifier: MIT
// dynaqpc world: a state grid fitted to the room (`encode auto`).
//
// Why: with 2^bits equal cells over the arena, a partition or a doorway's edge falls wherever the
// arithmetic puts it, usually inside a cell. The cell then holds both sides of the wall, or the
// two stops of an aligned step in it (step_past_m from either edge) lie one clear of the wall and
// one touching it, and the same (state, action) passes or bumps depending on where in the cell
// the robot stands, which the state cannot show (docs/agent.md, "A grid that fits the room").
//
// The rule, per axis (x, then y, independently):
//  1. Cut at every face of every obstacle's bounding box: a wall's side, a doorway's jambs, a
//     pillar's extent. Faces within kFaceMerge of each other or of the arena's walls are one cut.
//  2. A gap narrower than the step's `past` that lies inside one obstacle's extent (a thin
//     partition) stays a cell of its own: aligned steps cross it and never stop in it, so the
//     stops on either side are `past` clear of the partition's faces. A gap that narrow in free
//     space, or exactly `past` wide in single precision anywhere (the firmware could neither
//     step over it nor stop in it), is closed: its two cuts become one at its middle (at a wall,
//     the wall's cut stays).
//  3. A gap is cut into the number of equal cells nearest its width over the cell side (at
//     least one): `encode auto cell M`, else fit_cell_side(), twice the robot's step, so the
//     lab robot's cells stay near the paper's 54 x 40 cm (cells from 2/3 to 3/2 of it; rounding
//     rather than cutting every gap below the side kept paper-lab's cell count at 63, against
//     77, and its real steps within 13 % of the paper's grid on tuning seeds). A robot that
//     turns inside that side, but with less than kTurnClearance to spare on each side of its
//     turn, gets cells of its diagonal plus that clearance on each side instead: it stops at
//     their centres (`actions stop auto`) and turns there clear of the faces.
//  Only the faces of boxes square to the arena cut: a round pillar's or a turned box's edge
//  crosses cells whatever the cuts, and cutting at its bounding box only adds cells (on the
//  tuning rooms: 92 % of sets learned against 100 % without those cuts).
//  4. At most kMaxGridCells cells per side (the firmware's ROBOT_MAX_GRID_CELLS): a room that
//     needs more is refused with the count it needs.
//  5. For a robot that stops at its cells' centres, both axes together: a cell whose centre the
//     robot stands on but whose turn (half-diagonal + kPinchClearance) reaches a round obstacle
//     has that obstacle's bounding faces inside it moved into rule 3: the gap they lie in keeps
//     its cell count, cut at the face and split evenly on either side, when every cell of the
//     gap stays as wide as the robot's diagonal (else that face is left out). Again until no
//     cell gives a new face (fit_grid()). Only there, and only round ones: cutting those faces
//     everywhere, adding them as cuts, or moving cuts onto turned boxes' faces learned worse.
//  7. (6 in docs/agent.md is the goal's square, fit_axis()'s GoalCut.) For a robot that stops at
//     its cells' centres, with no `cell M` given: when a quarter or more
//     of the stops reach no goal stop on the walk stop_walk() makes (furniture has closed off a
//     part of the room), the side is tried at kWalkSideFactors of it, nearest first, and the first
//     fit with a stop, from whose every stop the walk reaches the goal, is kept
//     (Encoding::walk_refit); if none does, the fit stays. Rules 1-5 then apply as before at that side.
#ifndef WORLD_GRID_FIT_H
#define WORLD_GRID_FIT_H

#include <string>
#include <vector>

#include "world/scenario.h"

namespace world {

/// A box turned by a multiple of 90 degrees: its faces are straight lines of the grid's kind
/// (only those faces cut a fitted grid).
bool axis_aligned(const Obstacle &o);

/// Most cells along one side of a fitted grid (the firmware's ROBOT_MAX_GRID_CELLS).
inline constexpr int kMaxGridCells = 32;
/// Obstacle faces closer than this (m) to each other or to a wall are one cut.
inline constexpr double kFaceMerge = 0.02;
/// Whether the robot turns inside a fitted cell: its diagonal is shorter than `encode auto cell
/// M`, else than twice its step. Such a robot stops at its cells' centres (`actions stop auto`).
bool turns_inside_cells(const Scenario &s);

/// What a robot that turns at a cell's centre keeps between its turning circle and the cell's
/// faces, on each side (m). Measured on the users-tune rooms with a 0.34 x 0.28 m base
/// (docs/agent.md, "A robot larger than the lab robot"): 0.08 relapsed least of 0.055, 0.08 and
/// 0.13. The lab robot's cells of twice its step already give it 0.09: it keeps them.
inline constexpr double kTurnClearance = 0.08;

/// The largest cell side of a fitted grid: `encode auto cell M`; else twice the robot's step,
/// widened for a robot that turns inside it to its diagonal + 2 kTurnClearance.
double fit_cell_side(const Scenario &s);

/// Whether the fit cuts at the goal circle's bounding square: not at all; at its faces that leave
/// no sliver narrower than the robot's diagonal to a wall or a face (the goal's cell then reaches
/// to them: a 0.2 m row a turn cannot clear beside a wall relapsed in a hand-drawn zig-zag room);
/// or at all four.
enum class GoalCut { None, Square, WholeSquare };

/// The edges of the cells along `axis` (0: x, 1: y) fitted to `s`'s obstacles, from 0 to the
/// arena's side, with cells about `max_side` wide. With a `goal_cut`, the goal circle's bounding
/// square cuts too, so that a cell is centred on the goal: the parser asks for it only when no
/// step could otherwise end in the goal (a `goal ... cells` with no cell a step stops in, or a
/// plain circle holding no centre of a robot that stops at centres; cutting it always learned
/// worse on the tuning rooms: 96 % of sets against 100 %). False with *error (one line) when the side needs more
/// than kMaxGridCells cells.
bool fit_axis(const Scenario &s, int axis, double max_side, GoalCut goal_cut, std::vector<double> *edges,
              std::string *error);

/// How far beyond a turn (the robot's half-diagonal) a round obstacle must be from a cell's centre
/// for rule 5 to leave the cell alone (m): the aisles' bin lay 0.01 m beyond the turn.
inline constexpr double kPinchClearance = 0.04;

/// Rule 7: the share of stranded stops that refits (one in kWalkStrandedShare), and the cell
/// sides tried, as factors of fit_cell_side(), nearest first. Tuned on 15 generated rooms that
/// warn (docs/agent.md, "When furniture closes the grid's way").
inline constexpr long kWalkStrandedShare = 4;
inline constexpr double kWalkSideFactors[] = {0.95, 1.05, 0.9, 1.1, 0.85, 1.15, 0.8, 1.2, 0.75, 1.25};

/// Both axes fitted (fit_axis(), rules 1-4) and, for a robot whose stops are `centred`, rule 5
/// until it adds no face; a fit rule 5 would take past kMaxGridCells keeps the grid before. False
/// with *error (one line) as fit_axis().
bool fit_grid(const Scenario &s, double max_side, GoalCut goal_cut, bool centred, std::vector<double> *x_edges,
              std::vector<double> *y_edges, std::string *error);

/// How many faces of boxes square to the arena lie inside a cell of an equal grid (`encode x y`),
/// farther than `past` from its edges: where steps beside a wall pass or bump by where in the cell
/// the robot stands. 0 for a fitted grid. Loading a file warns when this is not 0.
int faces_inside_cells(const Scenario &s);

/// A stop a turn cannot clear: it lies outside every wall and obstacle but nearer one than the
/// robot's half-diagonal.
struct TightStop {
    int i = 0, j = 0;      ///< the cell it lies in
    double x = 0, y = 0;   ///< where the robot stops (m)
    double clearance = 0;  ///< to the nearest wall or obstacle there (m)
    int line = 0;          ///< that obstacle's line in the file; 0 for the arena's wall
};

/// The walk a robot that stops at its cells' centres (`actions.centred`) can make: from stop to
/// the stop an aligned step reaches, as the firmware places them (a cell twice `past` wide: its
/// centre; a narrower one: `past` inside the edge crossed; a partition's cell narrower than
/// `past`: stepped over), where both stops clear a turn (the robot's half-diagonal) and the step
/// between them keeps its half-width clear. `stranded` counts the stops it can stand at that
/// reach no goal stop that way, out of `cells` (stops, for the name's history); `blocking` holds
/// the tight stops (outside every obstacle but within a turn of one) they step into, nearest
/// first: where a user's furniture closes the grid's way (the den of
/// docs/results/users-rooms.md). Empty for any other robot.
struct StopWalkReport {
    long cells = 0, stranded = 0;  ///< stops
    std::vector<TightStop> blocking;
};
StopWalkReport stop_walk(const Scenario &s);

}  // namespace world

#endif  // WORLD_GRID_FIT_H
