// SPDX-License-Identifier: MIT
// dynaqpc: the aliasing watch (alias.h). The table is small and touched once per real step, so
// each operation scans it: no index to keep, and nothing to save (a reboot starts counting
// again; the counts steer learning rates, they hold no knowledge of the room).
#include "agent/alias.h"

#include <stddef.h>

#include "fw/fw_base.h"

// Cells are states, at most SPACE_MAX_STATE_BITS bits, so a cell and an 8-bit count share a word.
FW_STATIC_ASSERT(SPACE_MAX_STATE_BITS <= 24, alias_cells_fit_beside_a_count);
FW_STATIC_ASSERT(FW_CFG_ALIAS_CELLS >= 1, alias_watch_has_an_entry);

#define CELL_(e) ((e) >> 8)
#define COUNT_(e) ((e) & 0xFFu)

void alias_init(alias_watch_t *w)
{
    FW_ASSERT(w != NULL);
    alias_clear(w);
}

void alias_clear(alias_watch_t *w)
{
    for (uint32_t i = 0; i < FW_CFG_ALIAS_CELLS; i++) {
        w->entry[i] = 0;
    }
    w->checked = 0;
    w->aliased = 0;
}

static int32_t find_(const alias_watch_t *w, agent_state_t cell)
{
    for (uint32_t i = 0; i < FW_CFG_ALIAS_CELLS; i++) {
        if (COUNT_(w->entry[i]) != 0u && CELL_(w->entry[i]) == cell) {
            return (int32_t)i;
        }
    }
    return -1;
}

uint32_t alias_note(alias_watch_t *w, agent_state_t cell, bool aliased)
{
    w->checked++;
    int32_t i = find_(w, cell);
    if (!aliased) {
        return i < 0 ? 0u : COUNT_(w->entry[i]);
    }
    w->aliased++;
    uint32_t count;
    if (i >= 0) {
        count = COUNT_(w->entry[i]);
    } else {
        // A free entry (count 0) is the smallest; else the smallest count, the first of equals.
        i = 0;
        for (uint32_t k = 1; k < FW_CFG_ALIAS_CELLS; k++) {
            if (COUNT_(w->entry[k]) < COUNT_(w->entry[i])) {
                i = (int32_t)k;
            }
        }
        count = COUNT_(w->entry[i]);
    }
    if (count < ALIAS_COUNT_MAX) {
        count++;
    }
    w->entry[i] = (uint32_t)cell << 8 | count;
    return count;
}

uint32_t alias_count(const alias_watch_t *w, agent_state_t cell)
{
    const int32_t i = find_(w, cell);
    return i < 0 ? 0u : COUNT_(w->entry[i]);
}

uint32_t alias_cells(const alias_watch_t *w, alias_cell_t out[FW_CFG_ALIAS_CELLS])
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < FW_CFG_ALIAS_CELLS; i++) {
        if (COUNT_(w->entry[i]) == 0u) {
            continue;
        }
        // Insertion into the sorted prefix: most first, then lower cell first.
        const alias_cell_t c = {CELL_(w->entry[i]), COUNT_(w->entry[i])};
        uint32_t k = n++;
        while (k > 0u && (out[k - 1u].count < c.count ||
                          (out[k - 1u].count == c.count && out[k - 1u].cell > c.cell))) {
            out[k] = out[k - 1u];
            k--;
        }
        out[k] = c;
    }
    return n;
}
