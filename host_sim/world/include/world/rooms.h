// SPDX-License-Identifier: MIT
// dynaqpc world: seeded random rooms for a robot, and the passage check every room must pass.
//
// A room is a base scenario (paper-lab, paper-sim) with its layout drawn anew: interior walls
// (thin boxes, a door gap in some), obstacles of several shapes (boxes, rotated boxes, circles,
// L-shapes of two boxes) and a goal. Everything else of the base file (arena, robot, sensors,
// beacons or GPS, timing, encoding, actions, rewards, learning) is copied verbatim. Why the
// arena keeps its size, the size ranges and how rooms are used: docs/scenarios.md, "Generated
// rooms".
//
// A far-goal room (RoomSpec::far) is drawn from one of four families built so that the goal is
// far from most starts (a hall, an open floor with the goal in a corner, a goal behind a
// cul-de-sac, serpentine partitions), on the base's floor or a larger one: its arena, its
// encoding (the base's cells, more x/y bits) and, with Cricket, its beacons are then new too.
// Every room reports its longest shortest path from a start, in actions (longest_path()).
#ifndef WORLD_ROOMS_H
#define WORLD_ROOMS_H

#include <algorithm>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

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

/// Starts whose every way to the goal narrows below the robot's diagonal + 2 kPinchClearance
/// (`limit`, 0.40 m for the lab robot) beside an obstacle at an angle or a round one: `behind` of
/// the `starts` (points of the passage check's grid), and the narrowest such pinch, `width` m at
/// (x, y) beside the obstacle on `line`. The grid's stops pass such a slot by centimetres
/// (docs/scenarios.md, "Leave the robot room on its way to the goal"). Slots between walls and
/// boxes square to the arena are left out: the fitted grid centres a column of stops on them.
/// `rooms --check` and `train` warn when `behind` is kSlotWarnShare of `starts` or more.
struct SlotReport {
    long starts = 0, behind = 0;
    double limit = 0, width = 0, x = 0, y = 0;
    int line = 0;
};
SlotReport tight_slot(const Scenario &s);
/// One start point in this many behind a slot warns: a region, not a corner's few points.
inline constexpr long kSlotWarnShare = 100;
inline bool slot_warns(const SlotReport &r) { return r.behind > 0 && r.behind * kSlotWarnShare >= r.starts; }

/// What longest_path() found.
struct PathReport {
    /// The most actions any start needs to reach the goal at best (the longest of the shortest
    /// paths over every start place and heading); -1 when some start cannot reach it on the
    /// state grid (then `stranded` says how many (place, heading) pairs).
    long longest = -1;
    long places = 0;         ///< nodes: the free points of one state cell that join inside it
    long start_states = 0;   ///< (place, heading) pairs holding a start point
    long stranded = 0;       ///< start pairs with no path to the goal
    int nx = 0, ny = 0;      ///< the state grid (the encoding's x and y bits over the arena)
    /// by_actions[d]: the start pairs whose fewest actions to the goal are d (d up to `longest`).
    std::vector<long> by_actions;
    /// The start pairs that need more than n actions at best.
    long beyond(long n) const
    {
        long k = 0;
        for (std::size_t d = static_cast<std::size_t>(std::max(0L, n + 1)); d < by_actions.size(); d++) k += by_actions[d];
        return k;
    }
};

/// The longest shortest path from a start to the goal, in the robot's aligned actions: forward
/// or backward one state cell along the heading, a 90-degree turn left or right, each one
/// action. Computed on the passage check's free points (check_passages(): the robot's
/// circumscribed circle fits) grouped by state cell: a *place* is the free points of one cell
/// joined through each other inside that cell (a thin wall through a cell makes two places), two
/// places of neighbouring cells join where a free point of one neighbours a free point of the
/// other. A breadth-first search over (place, heading), heading one of the four axis
/// directions, from every place holding a goal point (in_goal()), gives each start place's
/// fewest actions at its worst heading; `longest` is the largest over places holding a start
/// point (start_position_ok()). Meaningful for `actions aligned 1 turn_deg 90` scenarios (the
/// shipped ones and every generated room); exact up to the state grid: a step may need the
/// robot to shift sideways within its cell, which aligned actions do not do.
PathReport longest_path(const Scenario &s);

/// The families of far-goal rooms (docs/scenarios.md, "Far-goal rooms").
enum class FarFamily { Hall, Open, CulDeSac, Serpentine };
inline constexpr int kFarFamilies = 4;

/// "hall", "open", "culdesac", "serpentine".
const char *far_family_name(FarFamily f);
/// The family named `name` (as far_family_name() spells it); false if none is.
bool far_family_from_name(const std::string &name, FarFamily *out);
/// The family `--far mixed` gives room `index` (1-based): hall, open, culdesac, serpentine, hall...
FarFamily far_family_of_index(std::uint32_t index);

/// What to draw. Default: an ordinary room on the base's floor (the rooms of tune/ and eval/).
struct RoomSpec {
    bool far = false;
    FarFamily family = FarFamily::Hall;
    /// The floor, m; 0 x 0: the base's arena. Each side must be the base's times 2^k, k in
    /// -2..2, so that the state cells keep the base's size (floor_check()).
    double floor_w = 0.0, floor_h = 0.0;
};

/// Whether `spec`'s floor suits `base`: each side the base's arena side times 2^k (k in -2..2;
/// within 1e-6 relative), its bits (the base's plus k) within 1..16 and the encoding within 32
/// bits. Sets *x_bits, *y_bits (may be null). False with *error = one line naming what is wrong.
bool floor_check(const Scenario &base, double w, double h, int *x_bits, int *y_bits, std::string *error);

/// A floor as file names and commands write it: "16x4", "8.6x3.2".
std::string floor_name(double w, double h);

/// A room's file name: <prefix>-<seed>-<index as 001>.scn, and for a far room
/// <prefix>-<family>-<floor w>x<floor h>-<seed>-<index>.scn (the floor in m as the file writes
/// numbers: 16x4, 8.6x3.2).
std::string room_file_name(const std::string &prefix, const RoomSpec &spec, double floor_w, double floor_h,
                           std::uint32_t seed, std::uint32_t index);

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
    PathReport path;            ///< longest_path() on it
    std::string family;         ///< far rooms: far_family_name(); "" otherwise
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

/// As above, drawing what `spec` asks. Ordinary rooms (spec.far false) are exactly the rooms of
/// the overload above. A far room's draw also fails when longest_path() finds a stranded start
/// or a longest path shorter than the base scenario's own (on the base's floor): every far room
/// has its goal farther than the base's. Its text carries `# longest_path_actions N`.
/// Each (family, floor) draws from its own stream of (seed, index).
bool generate_room(std::string_view base_text, const std::string &base_label,
                   const std::string &command, std::uint32_t seed, std::uint32_t index,
                   const RoomSpec &spec, const std::string &file, Room *out, std::string *error);

}  // namespace world

#endif  // WORLD_ROOMS_H
