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
//     space is closed: its two cuts become one at its middle.
//  3. A gap wider than the largest cell side is cut into equal cells no wider than it. The
//     largest side is `encode auto cell M`, else fit_cell_side(): twice the robot's step, so a
//     step crosses about half a cell's width and the lab robot's cells stay near the paper's
//     54 x 40 cm.
//  4. At most kMaxGridCells cells per side (the firmware's ROBOT_MAX_GRID_CELLS): a room that
//     needs more is refused with the count it needs.
#ifndef WORLD_GRID_FIT_H
#define WORLD_GRID_FIT_H

#include <string>
#include <vector>

#include "world/scenario.h"

namespace world {

/// Most cells along one side of a fitted grid (the firmware's ROBOT_MAX_GRID_CELLS).
inline constexpr int kMaxGridCells = 32;
/// Obstacle faces closer than this (m) to each other or to a wall are one cut.
inline constexpr double kFaceMerge = 0.02;

/// The largest cell side a fitted grid uses when the file gives none: twice the robot's step.
double fit_cell_side(const Scenario &s);

/// The edges of the cells along `axis` (0: x, 1: y) fitted to `s`'s obstacles, from 0 to the
/// arena's side, with cells at most `max_side` wide. False with *error (one line) when the side
/// needs more than kMaxGridCells cells.
bool fit_axis(const Scenario &s, int axis, double max_side, std::vector<double> *edges, std::string *error);

}  // namespace world

#endif  // WORLD_GRID_FIT_H
