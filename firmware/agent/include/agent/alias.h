// SPDX-License-Identifier: MIT
// dynaqpc: where the state cannot tell situations apart. A real step aliases when its outcome
// differs from what the agent's own experience of the same state and action says (another next
// state, reward or end of episode): the room made two situations different that the state
// encodes alike. The watch counts such steps per cell (the state's position components) in a
// small fixed table of the cells that disagree most, and the agent acts on the count
// (agent.h: a cell whose outcomes keep disagreeing learns from each real step more slowly).
#ifndef AGENT_ALIAS_H
#define AGENT_ALIAS_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/space.h"
#include "fw_config.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Cells the watch keeps a count for: the ones that disagree most. 8 entries of 4 bytes: a profile with room may say more.
#ifndef FW_CFG_ALIAS_CELLS
#define FW_CFG_ALIAS_CELLS 8
#endif

/// A cell's count saturates here.
#define ALIAS_COUNT_MAX 255u

/// One cell's count: `cell` is a state with every component outside the position cleared.
typedef struct alias_cell {
    agent_state_t cell;
    uint32_t count;  ///< aliasing real steps seen there (an upper bound: see alias_note())
} alias_cell_t;

typedef struct alias_watch {
    /// cell << 8 | count; a count of 0 is a free entry
    uint32_t entry[FW_CFG_ALIAS_CELLS];
    uint32_t checked;  ///< real steps whose state and action had been seen before
    uint32_t aliased;  ///< of them, those whose outcome disagreed
} alias_watch_t;

/// Prepares an empty watch.
void alias_init(alias_watch_t *w);

/// Forgets every count.
void alias_clear(alias_watch_t *w);

/// A cell is a state with every component outside its position cleared:
/// s & space_position_mask(space).

/// Notes a real step from `cell` whose pair had been seen before; `aliased`: its outcome differed.
/// Returns the cell's count after it. Space-Saving (Metwally, Agrawal & El Abbadi, 2005): a cell
/// not in the table takes a free entry or else the entry with the smallest count, inheriting
/// that count plus one, so a count is never below the cell's true count and the cells that
/// alias most keep their entries.
uint32_t alias_note(alias_watch_t *w, agent_state_t cell, bool aliased);

/// The cell's count (0 when it has no entry).
uint32_t alias_count(const alias_watch_t *w, agent_state_t cell);

/// The cells with a count, most first (ties: lower cell first); returns how many.
uint32_t alias_cells(const alias_watch_t *w, alias_cell_t out[FW_CFG_ALIAS_CELLS]);

#ifdef __cplusplus
}
#endif

#endif  // AGENT_ALIAS_H
