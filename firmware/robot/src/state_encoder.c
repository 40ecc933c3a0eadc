// SPDX-License-Identifier: MIT
// dynaqpc robot application: state encoding and action realisation.
#include "robot/state_encoder.h"

#include <math.h>

// pi in single precision, the value every port computes with.
#define ROBOT_PI 3.14159265358979f

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

// Cell of v in [0, extent) cut into 2^bits equal cells; outside values clamp to the edge cells.
static uint32_t cell_(float v, float extent, uint8_t bits)
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

agent_state_t robot_encode_state(const robot_config_t *cfg, const robot_pose_t *pose,
                                 uint32_t range_code)
{
    uint32_t comp[4];
    comp[0] = cell_(pose->x, cfg->arena_w, cfg->bits_x);
    comp[1] = cell_(pose->y, cfg->arena_h, cfg->bits_y);
    // Sector 0 is centred on +x: shift by half a sector, wrap into [0, 2 pi).
    const uint32_t sectors = 1u << cfg->bits_heading;
    const float sector = 2.0f * ROBOT_PI / (float)sectors;
    float h = fmodf(pose->heading + 0.5f * sector, 2.0f * ROBOT_PI);
    if (h < 0.0f) {
        h += 2.0f * ROBOT_PI;
    }
    uint32_t hs = h == h ? (uint32_t)(h / sector) : 0u;
    comp[2] = hs >= sectors ? sectors - 1u : hs;
    comp[3] = range_code & ((1u << cfg->bits_code) - 1u);
    agent_space_t sp;
    robot_config_space(cfg, &sp);
    return space_pack(&sp, comp);
}

bool robot_in_goal(const robot_config_t *cfg, const robot_pose_t *pose)
{
    const float dx = pose->x - cfg->goal_x;
    const float dy = pose->y - cfg->goal_y;
    return dx * dx + dy * dy <= cfg->goal_r * cfg->goal_r;
}

void robot_action_wheels(const robot_config_t *cfg, uint8_t action, float *v_left, float *v_right)
{
    const float duration = (float)cfg->action_periods * (float)cfg->period_us * 1e-6f;
    const float v = cfg->step_m / duration;
    // A turn in place: each wheel travels turn * track / 2.
    const float w = cfg->turn_rad * cfg->track_m * 0.5f / duration;
    switch (action) {
    case ROBOT_FORWARD: *v_left = v; *v_right = v; break;
    case ROBOT_BACKWARD: *v_left = -v; *v_right = -v; break;
    case ROBOT_TURN_LEFT: *v_left = -w; *v_right = w; break;
    case ROBOT_TURN_RIGHT: *v_left = w; *v_right = -w; break;
    default: *v_left = 0.0f; *v_right = 0.0f; break;
    }
}
