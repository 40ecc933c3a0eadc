// SPDX-License-Identifier: MIT
// dynaqpc qemu-agent: the grid robot's arena and kinematics.
#include "gridrobot.h"

const agent_space_t gridrobot_space = {4, {3, 3, 4, 3}, {0, 0, 0, 0}, 0x4, 0x8, 4, 0xC, 0};

// Row y, bit x: obstacles around the goal at (4, 4), with a gap on the south side.
static const uint8_t blocked_[8] = {0x00, 0x00, 0x00, 0x38, 0x28, 0x20, 0x00, 0x00};
#define GOAL_X 4u
#define GOAL_Y 4u

// Headings are sixteenths of a turn; pairs of them share one of eight compass directions.
static const int8_t dx_[8] = {1, 1, 0, -1, -1, -1, 0, 1};
static const int8_t dy_[8] = {0, 1, 1, 1, 0, -1, -1, -1};

static bool free_(int x, int y)
{
    return x >= 0 && x < 8 && y >= 0 && y < 8 && !((blocked_[y] >> x) & 1u);
}

void gridrobot_reset(gridrobot_t *g, prng_t *rng)
{
    do {
        g->x = (uint8_t)prng_below(rng, 8);
        g->y = (uint8_t)prng_below(rng, 8);
    } while (!free_(g->x, g->y) || (g->x == GOAL_X && g->y == GOAL_Y));
    g->heading = (uint8_t)prng_below(rng, 16);
}

static uint32_t range_(const gridrobot_t *g)
{
    const int d = g->heading / 2;
    uint32_t n = 0;
    int x = g->x + dx_[d];
    int y = g->y + dy_[d];
    while (n < 7u && free_(x, y)) {
        n++;
        x += dx_[d];
        y += dy_[d];
    }
    return n;
}

agent_state_t gridrobot_state(const gridrobot_t *g)
{
    const uint32_t c[4] = {g->x, g->y, g->heading, range_(g)};
    return space_pack(&gridrobot_space, c);
}

bool gridrobot_step(gridrobot_t *g, uint8_t a, float *reward)
{
    const int d = g->heading / 2;
    int x = g->x;
    int y = g->y;
    switch (a) {
    case GRIDROBOT_FORWARD:
        x += dx_[d];
        y += dy_[d];
        break;
    case GRIDROBOT_BACKWARD:
        x -= dx_[d];
        y -= dy_[d];
        break;
    case GRIDROBOT_LEFT:
        g->heading = (uint8_t)((g->heading + 1u) & 15u);
        break;
    default:
        g->heading = (uint8_t)((g->heading + 15u) & 15u);
        break;
    }
    if (!free_(x, y)) {
        *reward = -100.0f;
        return false;
    }
    g->x = (uint8_t)x;
    g->y = (uint8_t)y;
    if (g->x == GOAL_X && g->y == GOAL_Y) {
        *reward = 100.0f;
        return true;
    }
    *reward = -1.0f;
    return false;
}
