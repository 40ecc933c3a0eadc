// SPDX-License-Identifier: MIT
// dynaqpc world: seeded random rooms for a robot, and the passage check every room must pass.
//
// A room is a base scenario (paper-lab, paper-sim) with its layout drawn anew: interior walls
// (thin boxes, a door gap in some), obstacles of several shapes (boxes, rotated boxes, circles,
// L-shapes of two boxes) and a goal. Everything else of the base file (arena, robot, sensors,
// beacons or GPS, timing, encoding, actions, rewards, learning) is copied verbatim. Why the
// arena keeps its size, the size ranges and how rooms are used: docs/scenarios.md, "Generated
// rooms".
#ifndef WORLD_ROOMS_H
#define WORLD_ROOMS_H

#include <cstdint>
#include <string>
#include <string_view>

#include "world/scenario.h"

namespace world {

/// What check_passages() found. The counts are points of its grid (start_grid_step()).
struct PassageReport {
    bool ok = false;
    std::string problem;       ///< when !ok: one line saying where and why
    long free_points = 0;      ///< where the robot's circumscribed circle fits
    long start_points = 0;     ///< where a start pose may be drawn (start_position_ok())
    long goal_points = 0;      ///< free points in the goal (in_goal())
    long stranded_points = 0;  ///< start points that cannot reach a goal point
};

/// Whether the goal can be reached from every start the world may draw, through passages at least
/// the robot's diagonal wide. On the start grid (start_grid_step(), 2 cm), a point is free when
/// the robot's circumscribed circle fits there (clearance() >= robot_radius()): a passage
/// narrower than the diagonal has no free point across it. Free points join their four
/// neighbours; ok when some free point is in the goal and every start point is joined to one.
/// Conservative: a passage only a little wider than the diagonal (its free band narrower than a
/// grid step) may count as closed.
PassageReport check_passages(const Scenario &s);

/// Limits of the generator: how often a room is drawn again before giving up.
inline constexpr std::uint32_t kMaxRoomDraws = 1000;

/// A generated room.
struct Room {
    std::string text;           ///< the scenario file, ready to write
    Scenario scenario;          ///< `text` as parse_scenario() read it
    int walls = 0;              ///< interior walls drawn (a wall with a door counts once)
    int obstacles = 0;          ///< obstacles drawn (an L-shape counts once)
    std::uint32_t draw = 0;     ///< which draw passed (0: the first); earlier ones were refused
    PassageReport passages;     ///< check_passages() on it
};

/// Room `index` of `seed`, from the base scenario's text `base_text`. `base_label` names the base
/// in the room's header comment (e.g. "host_sim/scenarios/paper-lab.scn"), `command` is the
/// command line to quote there, `file` the room's file name (its stem becomes the scenario's
/// name; parse errors name it). The same arguments give the same text on the same binary and
/// libm; a room depends on (seed, index) only, not on how many rooms are made.
///
/// Each draw uses its own stream of the project's PRNG (RandomStream(mix(seed, index), draw)):
/// a draw whose text parse_scenario() refuses or whose passages fail check_passages() is
/// replaced by the next, at most kMaxRoomDraws times.
/// Returns false with *error = one line when the base does not parse or no draw passes.
bool generate_room(std::string_view base_text, const std::string &base_label,
                   const std::string &command, std::uint32_t seed, std::uint32_t index,
                   const std::string &file, Room *out, std::string *error);

}  // namespace world

#endif  // WORLD_ROOMS_H
