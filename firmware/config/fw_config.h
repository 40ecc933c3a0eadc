// SPDX-License-Identifier: MIT
// dynaqpc: the library's compile-time limits, shared by every profile. Replace with
// -DFW_CONFIG_FILE="my_config.h".
//
// Every table in the firmware is a static array whose size is set by these limits or by an
// application profile's settings, which live next to the application
// (robot/agent_profile_config.h). The agent profiles (robot/agent_profiles.h) turn them into
// storage types and check each profile's total against its RAM budget at compile time;
// `dynaqpc-mem` and the cross build's size report print the figures.
#ifndef FW_CONFIG_H
#define FW_CONFIG_H

#include "fw/fw_user_config.h"

// ---- Shape limits shared by every profile ------------------------------------------------------

/// Actions per state. The paper's robot has four: forward, backward, turn left, turn right.
#ifndef FW_CFG_MAX_ACTIONS
#define FW_CFG_MAX_ACTIONS 4
#endif
/// Components of a state (x, y, heading, range sensor).
#ifndef FW_CFG_MAX_COMPONENTS
#define FW_CFG_MAX_COMPONENTS 4
#endif
/// CMAC tilings. The paper uses 16 (its parameter c in Fig. 7).
#ifndef FW_CFG_MAX_TILINGS
#define FW_CFG_MAX_TILINGS 16
#endif
/// Linear-probe limit of every open-addressing table: a lookup or insert never looks at more
/// slots than this, so its cost is bounded whatever the load.
#ifndef FW_CFG_MAX_PROBE
#define FW_CFG_MAX_PROBE 16
#endif

/// The episode's last real steps the controller remembers (5 bytes each in robot_ctrl_t): a state
/// met for the third time within them takes the best action taken least often there
/// (controller.c, leave_loop_()). Chosen on paper-lab's tuning seeds, replaying frozen tables:
/// windows of 6, 12, 20 and 32 steps left 11, 9, 5 and 0 of 1,440 replays short of the goal
/// (docs/agent.md, departure 14).
#ifndef FW_CFG_LOOP_WINDOW
#define FW_CFG_LOOP_WINDOW 32
#endif

// ---- The host's extras ---------------------------------------------------------------------------

/// Dyna-QPC's planner keeps the predecessors of this many states, and the predictions of their
/// popped actions (a table of 352 bytes an entry on the host, outside every profile's storage),
/// until the model next changes, and finds them there instead of asking the model again
/// (dyna_qpc.c): the same planning, faster. 0 (the MCU's images): no table. The host's builds set
/// it (firmware/CMakeLists.txt), where the simulator spends most of its time in the planner:
/// 16,384 (5.8 MB) leave paper-sim-real 42 % fewer searches than 1,024 did (72,457 in 5
/// episodes, half of them of a state another had pushed out), nearly all of them the first of a
/// state since the model changed.
#ifndef FW_CFG_PLAN_CACHE_ENTRIES
#define FW_CFG_PLAN_CACHE_ENTRIES 0
#endif

/// 1: the Q store reads its 16-bit values (agent/value16.h) by one float multiplication, which
/// gives value16_to_float()'s floats exactly (checked for every value16 by the unit tests) where
/// the FPU reads subnormal operands as they are: the host's (firmware/CMakeLists.txt), where the
/// planner reads about ten values an update. 0 (the MCU's images): value16_to_float(), which
/// needs no subnormal float.
#ifndef FW_CFG_VALUE16_BY_SCALING
#define FW_CFG_VALUE16_BY_SCALING 0
#endif

#endif // FW_CONFIG_H
