// SPDX-License-Identifier: MIT
// dynaqpc robot application: the state grid, the state a pose and range readings encode, and
// the goal on that grid.
#include "robot/robot_geometry.h"

#include <math.h>

#include "fw/fw_util.h"

uint32_t robot_range_code(const robot_config_t *cfg, const float *range_m, uint32_t n)
{
    uint32_t code = 0;
    for (uint32_t bit = 0; bit < cfg->bits_code && bit < ROBOT_MAX_CODE_BITS; bit++) {
        for (uint32_t i = 0; i < n && i < ROBOT_MAX_RANGES; i++) {
            const float r = range_m[i];
            // NaN fails both comparisons: a broken reading never claims an obstacle.
            if (((cfg->rays_of_bit[bit] >> i) & 1u) && r > 0.0f && r < cfg->code_threshold_m[bit]) {
                code |= 1u << bit;
                break;
            }
        }
    }
    return code;
}

uint32_t robot_cell_of(float v, float extent, uint8_t bits)
{
    const uint32_t cells = 1u << bits;
    if (!(v > 0.0f)) {  // also NaN
        return 0;
    }
    const float c = v / extent * (float)cells;
    if (c >= (float)cells) {
        return cells - 1u;
    }
    return (uint32_t)c;
}

// The arena's side and the state bits along an axis.
static float extent_(const robot_config_t *cfg, uint32_t axis)
{
    return axis == ROBOT_AXIS_X ? cfg->arena_w : cfg->arena_h;
}

static uint8_t bits_(const robot_config_t *cfg, uint32_t axis)
{
    return axis == ROBOT_AXIS_X ? cfg->bits_x : cfg->bits_y;
}

uint32_t robot_grid_cells(const robot_config_t *cfg, uint32_t axis)
{
    const robot_grid_axis_t *g = &cfg->grid[axis & 1u];
    return g->cells != 0u ? g->cells : 1u << bits_(cfg, axis);
}

uint32_t robot_grid_cell(const robot_config_t *cfg, uint32_t axis, float v)
{
    const robot_grid_axis_t *g = &cfg->grid[axis & 1u];
    if (g->cells == 0u) {
        return robot_cell_of(v, extent_(cfg, axis), bits_(cfg, axis));
    }
    // The last edge at or below v, by bisection over at most 32 cells (NaN: cell 0).
    uint32_t lo = 0u, hi = g->cells;  // the answer lies in [lo, hi)
    if (!(v > 0.0f)) {
        return 0u;
    }
    while (hi - lo > 1u) {
        const uint32_t mid = (lo + hi) / 2u;
        if (v >= g->edge[mid]) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

void robot_grid_span(const robot_config_t *cfg, uint32_t axis, uint32_t k, float *lo, float *side)
{
    const robot_grid_axis_t *g = &cfg->grid[axis & 1u];
    if (g->cells == 0u) {
        *side = extent_(cfg, axis) / (float)(1u << bits_(cfg, axis));
        *lo = (float)k * *side;
        return;
    }
    k = k < g->cells ? k : g->cells - 1u;
    *lo = g->edge[k];
    *side = g->edge[k + 1u] - g->edge[k];
}

float robot_grid_min_side(const robot_config_t *cfg)
{
    float best = 0.0f;
    for (uint32_t axis = 0; axis < 2u; axis++) {
        const robot_grid_axis_t *g = &cfg->grid[axis];
        if (g->cells == 0u) {
            const float side = extent_(cfg, axis) / (float)(1u << bits_(cfg, axis));
            best = best == 0.0f || side < best ? side : best;
            continue;
        }
        for (uint32_t k = 0; k < g->cells; k++) {
            const float side = g->edge[k + 1u] - g->edge[k];
            if (side >= cfg->step_past_m && (best == 0.0f || side < best)) {
                best = side;
            }
        }
    }
    return best;
}

agent_state_t robot_encode_state(const robot_config_t *cfg, const robot_pose_t *pose,
                                 uint32_t range_code)
{
    uint32_t comp[4];
    comp[0] = robot_grid_cell(cfg, ROBOT_AXIS_X, pose->x);
    comp[1] = robot_grid_cell(cfg, ROBOT_AXIS_Y, pose->y);
    // Sector 0 is centred on +x: shift by half a sector, wrap into [0, 2 pi).
    const uint32_t sectors = 1u << cfg->bits_heading;
    const float sector = 2.0f * FW_PI_F / (float)sectors;
    float h = fmodf(pose->heading + 0.5f * sector, 2.0f * FW_PI_F);
    if (h < 0.0f) {
        h += 2.0f * FW_PI_F;
    }
    uint32_t hs = h == h ? (uint32_t)(h / sector) : 0u;
    comp[2] = hs >= sectors ? sectors - 1u : hs;
    comp[3] = range_code & ((1u << cfg->bits_code) - 1u);
    agent_space_t sp;
    robot_config_space(cfg, &sp);
    return space_pack(&sp, comp);
}

// The centre of the cell of v along `axis`.
static float cell_centre_(const robot_config_t *cfg, uint32_t axis, float v)
{
    const uint32_t k = robot_grid_cell(cfg, axis, v);
    if (cfg->grid[axis].cells == 0u) {
        const float side = extent_(cfg, axis) / (float)(1u << bits_(cfg, axis));
        return ((float)k + 0.5f) * side;
    }
    float lo, side;
    robot_grid_span(cfg, axis, k, &lo, &side);
    return lo + 0.5f * side;
}

bool robot_in_goal(const robot_config_t *cfg, const robot_pose_t *pose)
{
    float x = pose->x;
    float y = pose->y;
    if (cfg->goal_cells) {  // the centre of the pose's cell stands for the pose
        x = cell_centre_(cfg, ROBOT_AXIS_X, pose->x);
        y = cell_centre_(cfg, ROBOT_AXIS_Y, pose->y);
    }
    const float dx = x - cfg->goal_x;
    const float dy = y - cfg->goal_y;
    return dx * dx + dy * dy <= cfg->goal_r * cfg->goal_r;
}

void robot_config_space(const robot_config_t *c, agent_space_t *sp)
{
    *sp = (agent_space_t){0};
    sp->n_components = 4;
    sp->bits[0] = c->bits_x;
    sp->bits[1] = c->bits_y;
    sp->bits[2] = c->bits_heading;
    sp->bits[3] = c->bits_code;
    for (uint32_t k = 0; k < 4u; k++) {
        sp->tile_shift[k] = c->tile_shift[k];
    }
    sp->circular_mask = 1u << 2;  // the heading wraps
    sp->absolute_mask = 1u << 3;  // the range code is predicted, not its change
    sp->context_mask = (1u << 2) | (1u << 3);  // an action's effect depends on heading and code
    sp->n_actions = ROBOT_N_ACTIONS;
    sp->turn_step_bits = (uint8_t)robot_turn_step_bits(c);
}

uint32_t robot_turn_step_bits(const robot_config_t *c)
{
    if (!c->aligned_actions) {
        return 0u;
    }
    // An aligned turn ends on a multiple of turn_rad, and heading sector 0 is centred on 0: a
    // turn of exactly 2^g sectors reaches every 2^g-th sector and no other.
    const float sectors = c->turn_rad * (float)(1u << c->bits_heading) / (2.0f * FW_PI_F);
    for (uint32_t g = 1; g < c->bits_heading; g++) {
        const float d = sectors - (float)(1u << g);
        if (d < 1e-3f && d > -1e-3f) {
            return g;
        }
    }
    return 0u;
}
