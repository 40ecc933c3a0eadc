// SPDX-License-Identifier: MIT
// dynaqpc world, internal: how generated rooms are written and checked (rooms.cpp, user_rooms.cpp,
// room_check.cpp).
#ifndef WORLD_ROOM_TEXT_H
#define WORLD_ROOM_TEXT_H

#include <cstdint>
#include <string>
#include <string_view>

#include "world/rooms.h"
#include "world/scenario.h"

namespace world::room_text {

/// Positions on a 1 mm grid, sizes on 2 mm: what the file says is what was checked.
double q_pos(double v);
double q_size(double v);
/// A room's stream: (seed, index) mixed so that neighbouring seeds and indices are unrelated.
std::uint32_t room_seed(std::uint32_t seed, std::uint32_t index);
/// A number as the file writes it: at most 4 decimals, no trailing zeros.
std::string num(double v);
/// `line`, padded, with `# comment` and a newline.
std::string with_comment(std::string line, const std::string &comment);
/// The base file without its `obstacle` and `goal` lines: `before` up to and with `arena`,
/// `after` the rest.
void base_without_layout(std::string_view text, std::string *before, std::string *after);
/// A file name without its folders and its `.scn`.
std::string stem(const std::string &file);
/// `text` with the first line of `key` replaced by `lines` and every later line of it dropped.
std::string replace_key(const std::string &text, const std::string &key, const std::string &lines);
/// Eight Cricket beacons for a w x h floor on the base's ceiling, ids counted on from its first.
std::string beacon_lines(const Scenario &base, double w, double h);

/// Half extents of an obstacle's axis-aligned bounding box.
void extents(const Obstacle &o, double *ex, double *ey);

/// A drawn room's text (room->text) as `file`: parsed into room->scenario, its passages checked
/// (room->passages), its longest path found (room->path). False with *problem, the first thing
/// that failed, when the text does not parse or the passages fail.
bool check_drawn_room(Room *room, const std::string &file, std::string *problem);

}  // namespace world::room_text

#endif  // WORLD_ROOM_TEXT_H
