// SPDX-License-Identifier: MIT
// dynaqpc: a gridworld (Sutton & Barto's Dyna maze and friends): map parser, moves, shortest paths.
#ifndef MAZE_MAZE_H
#define MAZE_MAZE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "agent/space.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Map text format, one row per line:
///   `#` blocked, `.` free, `S` a start (one or more), `G` a goal (terminal; one or more).
/// Lines end in '\n' or "\r\n"; the last line's ending is optional; empty lines at the end are
/// ignored. Every row must have the same width. Every start must reach some goal.
///
/// Limits, so that garbage can never make the parser crash, hang or overflow: at most
/// MAZE_MAX_ROWS rows, MAZE_MAX_COLS columns, MAZE_MAX_CELLS cells in all, and
/// MAZE_MAX_FILE_BYTES bytes. 16,384 cells hold Sutton & Barto's largest prioritized-sweeping
/// maze (Example 8.4: the Dyna maze refined to 6,016 states, 144 x 48 cells), and are at most
/// 15 state bits (129 x 127: 8 + 7); the "maze" agent profile (fw_config.h) has a Q row for each and its tables at
/// most half full.
#define MAZE_MAX_ROWS 256
#define MAZE_MAX_COLS 256
#define MAZE_MAX_CELLS 16384
#define MAZE_MAX_FILE_BYTES 65536u

/// The four actions, numbered as the agent sees them.
typedef enum maze_action {
    MAZE_UP = 0,     ///< row - 1
    MAZE_DOWN = 1,   ///< row + 1
    MAZE_LEFT = 2,   ///< column - 1
    MAZE_RIGHT = 3,  ///< column + 1
    MAZE_N_ACTIONS = 4
} maze_action_t;

/// What a cell holds.
typedef enum maze_cell {
    MAZE_FREE = 0,
    MAZE_WALL = 1,
    MAZE_START = 2,  ///< free, and an episode may begin here
    MAZE_GOAL = 3    ///< free and terminal
} maze_cell_t;

/// A cell's position, both counted from 0: row 0 is the file's first line, column 0 its first
/// character.
typedef struct maze_pos {
    uint8_t row;
    uint8_t col;
} maze_pos_t;

/// Distance of a cell from which no goal can be reached (a wall, or a walled-off cell).
#define MAZE_UNREACHABLE UINT16_MAX

/// A parsed map. Fixed size (about 225 KB), no pointers: copy it, keep it static or on the heap.
typedef struct maze {
    uint16_t rows;  ///< 1..MAZE_MAX_ROWS
    uint16_t cols;  ///< 1..MAZE_MAX_COLS
    uint8_t cell[MAZE_MAX_ROWS][MAZE_MAX_COLS];  ///< maze_cell_t
    /// Steps of a shortest path from each cell to the nearest goal (0 on a goal), or
    /// MAZE_UNREACHABLE.
    uint16_t dist[MAZE_MAX_ROWS][MAZE_MAX_COLS];
    uint16_t n_starts;
    uint16_t n_goals;
    maze_pos_t starts[MAZE_MAX_CELLS];  ///< in reading order
} maze_t;

/// Where and why a map was refused.
typedef struct maze_error {
    int line;           ///< 1-based line of the offending character or cell; 1 for the whole file
    int column;         ///< 1-based column (byte) on that line; 1 for the whole file
    char what[128];     ///< the reason alone, e.g. "unknown character 'x'"
    char message[512];  ///< the whole one-line report: "<file>:<line>:<column>: <what>"
} maze_error_t;

/// Parses `len` bytes of map text (any bytes: NULs, binary, no terminator needed). `file` names
/// the map in the error report (NULL: "<map>").
/// Returns 0 with *m filled in, or -1 with *err filled in (and *m unspecified).
int maze_parse(maze_t *m, const char *text, size_t len, const char *file, maze_error_t *err);

/// The map `in` at k times its resolution into *out: each cell becomes a k x k block of its kind,
/// but a start or a goal stays one cell, its block's first, the rest of the block free (Sutton &
/// Barto's Example 8.4: the Dyna maze refined to more states, one start and one goal). `file`
/// names the map in the error report. Returns 0, or -1 with *err filled in (k of 0, or a result
/// past the parser's limits) and *out unspecified. k = 1 copies the map.
int maze_refine(maze_t *out, const maze_t *in, unsigned k, const char *file, maze_error_t *err);

/// One move from `pos` (which must be a free cell). A move into a wall or off the map leaves the
/// agent where it was. Returns true when the new cell is a goal (the episode ends there).
bool maze_move(const maze_t *m, maze_pos_t pos, uint8_t action, maze_pos_t *next);

/// One environment step: maze_move() plus the reward, `goal_reward` for the step that enters a
/// goal and `step_reward` for every other step (Sutton & Barto: 0 and +1).
/// Returns true when the episode ends (a goal was reached).
bool maze_step(const maze_t *m, maze_pos_t pos, uint8_t action, float step_reward,
               float goal_reward, maze_pos_t *next, float *reward);

/// True if `pos` is a goal.
bool maze_is_goal(const maze_t *m, maze_pos_t pos);

/// Shortest path length from `pos` to the nearest goal, or MAZE_UNREACHABLE.
uint16_t maze_shortest_from(const maze_t *m, maze_pos_t pos);

/// The longest and the mean, over the starts, of their shortest paths to a goal: with one start
/// (the Dyna maze: 14) both are that start's.
uint16_t maze_shortest_max(const maze_t *m);
double maze_shortest_mean(const maze_t *m);

/// Bits of the row and column components: ceil(log2(n)), at least 1.
uint8_t maze_row_bits(const maze_t *m);
uint8_t maze_col_bits(const maze_t *m);

/// The agent's view of the maze: component 0 the row, component 1 the column, exact tiles
/// (tile_shift 0: a wall makes neighbouring cells unlike each other), nothing circular or
/// absolute, four actions.
void maze_space(const maze_t *m, agent_space_t *sp);

/// The packed agent state of a cell under maze_space(): the row in the low bits, the column
/// above them (space.h's layout: component 0 in the lowest bits).
agent_state_t maze_state(const maze_t *m, maze_pos_t pos);

#ifdef __cplusplus
}
#endif

#endif // MAZE_MAZE_H
