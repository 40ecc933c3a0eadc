// SPDX-License-Identifier: MIT
// Fuzz target: a maze map file (dynaqpc-sim maze --map), parsed and, if accepted, walked, and
// refined (--refine) as far as the limits allow.
#include "fuzz.h"
#include "maze/maze.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static maze_t m;
    maze_error_t err;
    if (maze_parse(&m, (const char *)data, size, "fuzz", &err) != 0) {
        return 0;
    }
    // An accepted map must be usable: its space valid, every start with a path, every move
    // from a free cell defined.
    agent_space_t sp;
    maze_space(&m, &sp);
    if (space_validate(&sp) != 0) {
        __builtin_trap();
    }
    for (uint32_t i = 0; i < m.n_starts; i++) {
        if (maze_shortest_from(&m, m.starts[i]) == MAZE_UNREACHABLE) {
            __builtin_trap();
        }
        maze_pos_t next;
        for (uint8_t a = 0; a < 4u; a++) {
            (void)maze_move(&m, m.starts[i], a, &next);
        }
    }
    (void)maze_shortest_mean(&m);
    // Refined k times the map is accepted or refused whole, and an accepted one has the same
    // starts, each no farther than k times its distance from a goal (the coarse path, walked
    // block by block, is one such path).
    static maze_t fine;
    for (unsigned k = 2; k <= 3u; k++) {
        if (maze_refine(&fine, &m, k, "fuzz", &err) != 0) {
            continue;
        }
        if (fine.n_starts != m.n_starts || fine.rows != m.rows * k) {
            __builtin_trap();
        }
        for (uint32_t i = 0; i < m.n_starts; i++) {
            if (maze_shortest_from(&fine, fine.starts[i]) > k * maze_shortest_from(&m, m.starts[i])) {
                __builtin_trap();
            }
        }
    }
    return 0;
}
