// SPDX-License-Identifier: MIT
// dynaqpc qemu-agent: a small kinematic robot on a grid, shaped like the paper-lab state (8,192 states).
#ifndef GRIDROBOT_H
#define GRIDROBOT_H

#include <stdbool.h>
#include <stdint.h>

#include "fw/fw_prng.h"
#include "agent/space.h"

#ifdef __cplusplus
extern "C" {
#endif

/// An 8 x 8 arena with obstacles ringing a goal in the middle, the paper's layout in miniature.
/// The robot has a cell (x, y), one of 16 headings, and one range sensor reading the free cells
/// ahead (0..7). Actions: 0 forward, 1 backward, 2 turn left, 3 turn right. A move into an
/// obstacle or a wall leaves the robot where it was (a bump, -100); the goal gives +100 and ends
/// the episode; every other step costs -1. No I/O, no allocation: it runs on the MCU too.
typedef struct gridrobot {
    uint8_t x, y, heading;
} gridrobot_t;

enum { GRIDROBOT_FORWARD = 0, GRIDROBOT_BACKWARD, GRIDROBOT_LEFT, GRIDROBOT_RIGHT };

/// x, y (3 bits each), heading (4 bits, circular), range (3 bits, a value); exact tiles and the
/// heading and range as the relocatable model's situation, as the shipped robot profiles have.
extern const agent_space_t gridrobot_space;

/// Places the robot on a random free cell with a random heading.
void gridrobot_reset(gridrobot_t *g, prng_t *rng);

/// The robot's state for the agent.
agent_state_t gridrobot_state(const gridrobot_t *g);

/// Takes action a; sets *reward; returns true when the goal is reached.
bool gridrobot_step(gridrobot_t *g, uint8_t a, float *reward);

#ifdef __cplusplus
}
#endif

#endif // GRIDROBOT_H
