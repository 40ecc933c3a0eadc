// SPDX-License-Identifier: MIT
// dynaqpc world: seeded rooms drawn the way users draw their own.
//
// The generator of rooms.h draws on the base's floor and grid, with thick walls and wide doors:
// its rooms show almost no relapse, so tuning on them hides what users' rooms show. A user copies
// a shipped scenario and draws a room of any size into it: thin partitions with doorways anywhere
// along them (on the grid or not, at a wall or in the middle) from the robot's diagonal to a few
// times it, S- and U-shaped floors, round pillars and bins, furniture at an angle. These rooms do
// the same, with the base's robot, sensors, actions, rewards and learning, and `encode auto` (the
// grid fitted to the room); with Cricket, eight beacons for the new floor. Lengths scale with the
// robot's diagonal D, so the sonar robot's rooms are its size. docs/scenarios.md, "Rooms like
// users' rooms".
#ifndef WORLD_USER_ROOMS_H
#define WORLD_USER_ROOMS_H

#include <cstdint>
#include <string>
#include <string_view>

#include "world/rooms.h"

namespace world {

/// The families (docs/scenarios.md): partitions across the floor with a doorway each; an S of
/// two partitions with doorways at opposite ends; a U around one partition from an end wall;
/// round pillars and bins with a partition; furniture at an angle; furniture along the walls, as
/// rooms are furnished, some of it a little askew and some a slot's width off the wall.
enum class UserFamily { Partitions, SFloor, UFloor, Pillars, Furniture, AlongWalls };
inline constexpr int kUserFamilies = 6;
/// `--users mixed` takes the first five in turn (the rooms it drew before along-walls keep their draws).
inline constexpr int kMixedUserFamilies = 5;

/// "partitions", "s-floor", "u-floor", "pillars", "furniture", "along-walls".
const char *user_family_name(UserFamily f);
/// The family named `name`; false if none is.
bool user_family_from_name(const std::string &name, UserFamily *out);
/// The family `--users mixed` gives room `index` (1-based): each of the first kMixedUserFamilies in turn.
UserFamily user_family_of_index(std::uint32_t index);

/// The goal a room draws: the base's goal line (its radius; `cells` if the base says so), or a
/// plain circle as users draw one, reached when the robot's centre is inside, of a radius from
/// kUserGoalRadius[0] to [1] robot diagonals (the lab robot: 0.13 to 0.32 m; the sonar robot:
/// 0.31 to 0.78 m).
enum class UserGoal { Base, Circle };
inline constexpr double kUserGoalRadius[2] = {0.4, 1.0};

/// "base", "circle".
const char *user_goal_name(UserGoal g);
/// The goal kind named `name`; false if none is.
bool user_goal_from_name(const std::string &name, UserGoal *out);

/// Room `index` of `seed` in `family`, from the base scenario's text (as generate_room()). A draw
/// is refused and drawn again when its file does not parse (e.g. `encode auto` needs more than 32
/// cells), or its passages fail check_passages(), or a start cannot reach the goal on the grid
/// (longest_path()). Returns false with *error when no draw of kMaxRoomDraws passes.
bool generate_user_room(std::string_view base_text, const std::string &base_label, const std::string &command,
                        std::uint32_t seed, std::uint32_t index, UserFamily family, UserGoal goal,
                        const std::string &file, Room *out, std::string *error);

}  // namespace world

#endif  // WORLD_USER_ROOMS_H
