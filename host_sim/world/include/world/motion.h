// SPDX-License-Identifier: MIT
// dynaqpc world: the robot's four actions as wheel speed targets for one control period.
#ifndef WORLD_MOTION_H
#define WORLD_MOTION_H

#include "world/scenario.h"
#include "world/world.h"

namespace world {

/// The paper's four actions. Numbering is ours; the firmware may number its own.
enum class Action { Forward = 0, Backward = 1, TurnLeft = 2, TurnRight = 3 };

/// How far each wheel must travel for one action: forward/backward +-actions.step on both;
/// turn left (counter-clockwise) -turn*track/2 on the left wheel and +turn*track/2 on the right;
/// turn right the opposite.
WheelSpeeds action_wheel_travel(const Scenario &s, Action a);

/// Constant wheel targets that, held for one control period (timing.substeps physics steps), make
/// each wheel travel what `target_travel` asks, given the wheels' speeds now (`current`, e.g.
/// World::wheel_speeds(); {0, 0} from rest) and the controller's slew limit robot.max_accel.
/// Exact for the controller as World models it (discrete slew per physics step), free driving;
/// a contact stops the robot short. A travel that needs more than robot.max_speed gets
/// +-max_speed (and falls short). Because heading change = (travel_r - travel_l) / track exactly,
/// a turn turns by actions.turn whatever the speeds it starts from.
WheelSpeeds wheel_targets_for_travel(const Scenario &s, WheelSpeeds target_travel,
                                     WheelSpeeds current);

/// wheel_targets_for_travel(s, action_wheel_travel(s, a), current).
WheelSpeeds wheel_targets_for(const Scenario &s, Action a, WheelSpeeds current);

}  // namespace world

#endif  // WORLD_MOTION_H
