// SPDX-License-Identifier: MIT
// dynaqpc robot application: the agent profiles' settings (maze, paper-lab, paper-sim): table
// capacities and RAM budgets, each overridable from FW_CONFIG_FILE. The library's own limits,
// shared by every profile, are fw_config.h's; robot/agent_profiles.h turns both into storage.
#ifndef ROBOT_AGENT_PROFILE_CONFIG_H
#define ROBOT_AGENT_PROFILE_CONFIG_H

#include "fw/fw_user_config.h"

// ---- Profile "maze": host gridworlds (up to 16,384 cells, 15 state bits) --------------------------
// Q is dense for every map the parser accepts (2^15 rows), and the model, queue and Dyna-Q table
// are at most half full on the largest (16,384 free cells, 65,536 pairs).
#ifndef FW_CFG_MAZE_Q_TYPE
#define FW_CFG_MAZE_Q_TYPE float
#endif
#ifndef FW_CFG_MAZE_Q_STATES
#define FW_CFG_MAZE_Q_STATES 32768
#endif
#ifndef FW_CFG_MAZE_CMAC_CELLS
#define FW_CFG_MAZE_CMAC_CELLS 131072
#endif
#ifndef FW_CFG_MAZE_PQ_CAPACITY
#define FW_CFG_MAZE_PQ_CAPACITY 32768
#endif
// The bytes every algorithm gets beside the Q store: those of Dyna-QPC's model and queue on the
// Cortex-M4 (agent_profiles.h asserts it: set it again when their tables change size; the
// host's are 80 bytes more, the planner's carry holds pointers). Algorithms that size their
// tables from it fill it (DYNAQ_RECORDS_IN): Dyna-Q 52,655 records of 40 bytes and 131,072
// index slots of 8 bytes; a table with 4 bytes more a record, 47,868.
#ifndef FW_CFG_MAZE_ALGORITHM_BYTES
#define FW_CFG_MAZE_ALGORITHM_BYTES 3154800
#endif
// Gridworlds have no percept or situation components (the relocatable model is off); the room
// is for the benchmark's grid robot, shaped like paper-lab's state.
#ifndef FW_CFG_MAZE_PLACES
#define FW_CFG_MAZE_PLACES 1024
#endif
#ifndef FW_CFG_MAZE_CLASSES
#define FW_CFG_MAZE_CLASSES 512
#endif
#ifndef FW_CFG_MAZE_POSITIONS
#define FW_CFG_MAZE_POSITIONS 64
#endif
// The exploration bonus's tried-pairs table (explore.h; 8 bytes a pair, used only by the bonus
// modes): when each state-action pair was last tried. Full, it forgets the pair tried longest ago.
#ifndef FW_CFG_MAZE_TRIED_PAIRS
#define FW_CFG_MAZE_TRIED_PAIRS 4096
#endif
// The paper's CMAC-Model and CMAC-R (`model paper`, paper_model.h) overlay the relocatable
// model and the planner's carry (agent_profiles.h asserts they fit in its bytes): cells of 17
// bytes (key, 6 weights, count) and of 15 (key, 5 weights, count).
#ifndef FW_CFG_MAZE_PAPER_FWD_CELLS
#define FW_CFG_MAZE_PAPER_FWD_CELLS 65536
#endif
#ifndef FW_CFG_MAZE_PAPER_INV_CELLS
#define FW_CFG_MAZE_PAPER_INV_CELLS 65536
#endif
#ifndef FW_CFG_MAZE_BUDGET_BYTES
#define FW_CFG_MAZE_BUDGET_BYTES (16u * 1024u * 1024u)
#endif

// ---- Profile "paper-lab": 8,192 states (x, y, heading, IR in 3, 3, 4, 3 bits) ------------------
// Q values: float (fits; see FW_CFG_SIM_Q_TYPE).
#ifndef FW_CFG_LAB_Q_TYPE
#define FW_CFG_LAB_Q_TYPE float
#endif
#ifndef FW_CFG_LAB_Q_STATES
#define FW_CFG_LAB_Q_STATES 1024
#endif
#ifndef FW_CFG_LAB_CMAC_CELLS
#define FW_CFG_LAB_CMAC_CELLS 1024
#endif
#ifndef FW_CFG_LAB_PQ_CAPACITY
#define FW_CFG_LAB_PQ_CAPACITY 128
#endif
// The bytes every algorithm gets (see the maze profile): Dyna-QPC's model and queue. Dyna-Q
// 512 records (28,672 bytes: 513 would need an index of 2,048 slots); 4 bytes more a record,
// 497 (30,060).
#ifndef FW_CFG_LAB_ALGORITHM_BYTES
#define FW_CFG_LAB_ALGORITHM_BYTES 30064
#endif
// The relocatable model (model.h): places = x, y, heading (3 + 3 + 4 bits); situations = heading
// and range code (4 + 3 bits) times 4 actions; positions = x, y.
#ifndef FW_CFG_LAB_PLACES
#define FW_CFG_LAB_PLACES 1024
#endif
#ifndef FW_CFG_LAB_CLASSES
#define FW_CFG_LAB_CLASSES 512
#endif
#ifndef FW_CFG_LAB_POSITIONS
#define FW_CFG_LAB_POSITIONS 64
#endif
// Tried pairs (explore.h): 128 pairs, 1 KB: what the 64 KiB paper-lab image (netduinoplus2)
// leaves. A lab run tries about 750 distinct pairs in 20 episodes, so a bonus mode here forgets
// most of them; the bonus measurements (docs/agent.md item 12) used a host build with
// -DFW_CFG_LAB_TRIED_PAIRS=1024, and the bonus is off by default.
#ifndef FW_CFG_LAB_TRIED_PAIRS
#define FW_CFG_LAB_TRIED_PAIRS 128
#endif
// The paper's CMACs: 1,024 x 17 + 512 x 15 = 25,088 bytes of our model's 25,456 (with the carry).
#ifndef FW_CFG_LAB_PAPER_FWD_CELLS
#define FW_CFG_LAB_PAPER_FWD_CELLS 1024
#endif
#ifndef FW_CFG_LAB_PAPER_INV_CELLS
#define FW_CFG_LAB_PAPER_INV_CELLS 512
#endif
#ifndef FW_CFG_LAB_BUDGET_BYTES
#define FW_CFG_LAB_BUDGET_BYTES (64u * 1024u)
#endif

// ---- Profile "paper-sim": 262,144 states (x, y, heading, sonar in 5, 5, 4, 4 bits) -------------
// Q values in 16 bits (value16_t, agent/value16.h): 8,192 rows in the bytes of 4,096 floats.
// A floor of 64 x 64 cells (four times paper-sim's) runs in them but visits up to 18,582
// states; it learns reliably with 16,384 rows, which do not fit beside the model in 192 KiB:
// the host runs it on paper-sim-large (below; docs/results/far-goal.md).
#ifndef FW_CFG_SIM_Q_TYPE
#define FW_CFG_SIM_Q_TYPE value16_t
#endif
#ifndef FW_CFG_SIM_Q_STATES
#define FW_CFG_SIM_Q_STATES 8192
#endif
#ifndef FW_CFG_SIM_CMAC_CELLS
#define FW_CFG_SIM_CMAC_CELLS 1024
#endif
#ifndef FW_CFG_SIM_PQ_CAPACITY
#define FW_CFG_SIM_PQ_CAPACITY 512
#endif
// The bytes every algorithm gets (see the maze profile): Dyna-QPC's model and queue. Dyna-Q
// 1,298 records (84,688 bytes); 4 bytes more a record, 1,180 (84,688); each 4,096 index slots.
#ifndef FW_CFG_SIM_ALGORITHM_BYTES
#define FW_CFG_SIM_ALGORITHM_BYTES 84720
#endif
// places = x, y, heading (5 + 5 + 4 bits); situations = heading and sonar code (4 + 4 bits)
// times 4 actions; positions = x, y.
#ifndef FW_CFG_SIM_PLACES
#define FW_CFG_SIM_PLACES 16384
#endif
#ifndef FW_CFG_SIM_CLASSES
#define FW_CFG_SIM_CLASSES 1024
#endif
#ifndef FW_CFG_SIM_POSITIONS
#define FW_CFG_SIM_POSITIONS 4096
#endif
// Tried pairs (explore.h): 128 pairs, 1 KB: what the 192 KiB paper-sim image (stm32f4-robot)
// leaves beside the 8,192 16-bit Q rows. A bonus mode that should remember more pairs needs a
// host build with a larger -DFW_CFG_SIM_TRIED_PAIRS (the pair tried longest ago is forgotten).
#ifndef FW_CFG_SIM_TRIED_PAIRS
#define FW_CFG_SIM_TRIED_PAIRS 128
#endif
// The paper's CMACs: 2,048 x 17 + 2,048 x 15 = 65,536 bytes of our model's 79,600.
#ifndef FW_CFG_SIM_PAPER_FWD_CELLS
#define FW_CFG_SIM_PAPER_FWD_CELLS 2048
#endif
#ifndef FW_CFG_SIM_PAPER_INV_CELLS
#define FW_CFG_SIM_PAPER_INV_CELLS 2048
#endif
#ifndef FW_CFG_SIM_BUDGET_BYTES
#define FW_CFG_SIM_BUDGET_BYTES (192u * 1024u)
#endif

// ---- Profile "paper-sim-large": paper-sim on floors of up to 64 x 64 cells (16 x 16 m) ----------
// paper-sim's tables with twice its Q rows: 16,384 16-bit rows, which the 16 x 16 m floor needs
// to learn (docs/results/far-goal.md: 8,192 rows hold about half the states it visits). The host
// picks it for paper-sim states of more than 18 bits (host_sim/src/agent_pick.cpp); 192 KiB
// (paper-sim) stays the default profile. Dyna-QPC's tables are paper-sim's (the same model and
// queue), so it learns as it would on paper-sim's profile with a Q store twice as large. Its
// image is the STM32F427's dynaqpc-fw-paper-sim-large (docs/porting.md, "robot-f42x").
#ifndef FW_CFG_SIM_LARGE_Q_TYPE
#define FW_CFG_SIM_LARGE_Q_TYPE value16_t
#endif
#ifndef FW_CFG_SIM_LARGE_Q_STATES
#define FW_CFG_SIM_LARGE_Q_STATES 16384
#endif
#ifndef FW_CFG_SIM_LARGE_CMAC_CELLS
#define FW_CFG_SIM_LARGE_CMAC_CELLS FW_CFG_SIM_CMAC_CELLS
#endif
#ifndef FW_CFG_SIM_LARGE_PQ_CAPACITY
#define FW_CFG_SIM_LARGE_PQ_CAPACITY FW_CFG_SIM_PQ_CAPACITY
#endif
// The overlay's bytes on the MCU (agent_profiles.h asserts it): Dyna-QPC's model and queue
// without the percept map, which is storage of its own here. So Dyna-Q's table on this profile
// is smaller than on paper-sim's (51,956 bytes against 84,720).
#ifndef FW_CFG_SIM_LARGE_ALGORITHM_BYTES
#define FW_CFG_SIM_LARGE_ALGORITHM_BYTES 51956
#endif
#ifndef FW_CFG_SIM_LARGE_PLACES
#define FW_CFG_SIM_LARGE_PLACES FW_CFG_SIM_PLACES
#endif
#ifndef FW_CFG_SIM_LARGE_CLASSES
#define FW_CFG_SIM_LARGE_CLASSES FW_CFG_SIM_CLASSES
#endif
#ifndef FW_CFG_SIM_LARGE_POSITIONS
#define FW_CFG_SIM_LARGE_POSITIONS FW_CFG_SIM_POSITIONS
#endif
// Tried pairs (explore.h, the bonus modes only, off by default): 32, a quarter of paper-sim's,
// which leaves the STM32F427 image's SRAM room for the stack and its scenario.
#ifndef FW_CFG_SIM_LARGE_TRIED_PAIRS
#define FW_CFG_SIM_LARGE_TRIED_PAIRS 32
#endif
// The paper's CMACs: 1,024 x 17 + 1,024 x 15 = 32,768 bytes, within our model's bytes in the
// overlay, which holds no percept map here (agent_profiles.h).
#ifndef FW_CFG_SIM_LARGE_PAPER_FWD_CELLS
#define FW_CFG_SIM_LARGE_PAPER_FWD_CELLS 1024
#endif
#ifndef FW_CFG_SIM_LARGE_PAPER_INV_CELLS
#define FW_CFG_SIM_LARGE_PAPER_INV_CELLS 1024
#endif
// Its Q store keeps 16-bit keys (qstore_init16: the same table as 32-bit keys for 16,384 rows
// and states of up to 20 bits, qstore.h): 16,384 rows take 160 KiB, and the agent (storage
// and agent_t) 252,364 bytes on the MCU, within the STM32F427's 256 KiB of SRAM and CCM (with
// 32-bit keys, 285,896 would not be). The budget is the board's whole RAM.
#ifndef FW_CFG_SIM_LARGE_BUDGET_BYTES
#define FW_CFG_SIM_LARGE_BUDGET_BYTES (256u * 1024u)
#endif

#endif // ROBOT_AGENT_PROFILE_CONFIG_H
