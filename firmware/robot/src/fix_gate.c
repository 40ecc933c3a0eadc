// SPDX-License-Identifier: MIT
// dynaqpc robot application: the position fixes the robot may believe (contract in fix_gate.h).
//
// Why dead reckoning, and a reference that moves only with believed fixes: the rule before the
// gate ("a fix farther from the last one than 0.30 m plus 1.5 m/s times the time: the robot was
// moved") let any fix through after a step's 1-2 s (its reach was 2-3 m), made a wrong one the
// reference, and then called the next good fix a jump: on the realistic robot's tuning rooms
// that was every trust loss. A reach of the travel's length around the last fix still let fixes
// 0.4-1 m off through after a step (the step's own length); the travel's direction rules them
// out. Between two fixes the robot can drive, back off and turn, so dead reckoning follows each
// MOTOR_STATUS's travel along the heading of its moment, not the heading at the fix.
#include "robot/fix_gate.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "fw/fw_assert.h"

void fix_gate_init(fix_gate_t *gate)
{
    FW_ASSERT(gate != NULL);
    memset(gate, 0, sizeof *gate);
}

void fix_gate_forget(fix_gate_t *gate)
{
    FW_ASSERT(gate != NULL);
    gate->have_ref = false;
    gate->have_suspect = false;
}

static float sq_(float v)
{
    return v * v;
}

static void take_(fix_gate_t *gate, const fix_gate_in_t *in)
{
    gate->have_ref = true;
    gate->dr_x = in->x_m;
    gate->dr_y = in->y_m;
    gate->travel_m = 0.0f;
    gate->blind = false;
    gate->have_suspect = false;
}

void fix_gate_travel(fix_gate_t *gate, float ds_m, float heading_rad, bool heading_known)
{
    FW_ASSERT(gate != NULL);
    if (heading_known) {
        gate->dr_x += ds_m * cosf(heading_rad);
        gate->dr_y += ds_m * sinf(heading_rad);
    } else {
        gate->blind = true;
    }
    gate->travel_m += ds_m < 0.0f ? -ds_m : ds_m;
}

fix_gate_verdict_t fix_gate_check(fix_gate_t *gate, const fix_gate_in_t *in)
{
    FW_ASSERT(gate != NULL && in != NULL && in->arena_w > 0.0f && in->arena_h > 0.0f);
    if (!(in->x_m >= 0.0f && in->x_m <= in->arena_w && in->y_m >= 0.0f && in->y_m <= in->arena_h)) {
        gate->refused_outside += gate->refused_outside < UINT16_MAX;
        return FIX_GATE_REFUSE;
    }
    const float reach =
        FIX_GATE_JUMP_M + (gate->blind ? 1.0f + FIX_GATE_SLIP : FIX_GATE_SLIP) * gate->travel_m;
    const float d2 = sq_(in->x_m - gate->dr_x) + sq_(in->y_m - gate->dr_y);
    if (!gate->have_ref || d2 <= sq_(reach)) {
        // A different fix (new ranges) close to dead reckoning corroborates; the same fix solved
        // again from the same ranges (no travel) does not.
        const bool same = gate->have_ref && in->x_m == gate->dr_x && in->y_m == gate->dr_y;
        const bool agrees =
            gate->have_ref && d2 <= sq_(FIX_GATE_AGREE_M + FIX_GATE_SLIP * gate->travel_m);
        const bool corroborated = same ? gate->corroborated : agrees;
        take_(gate, in);
        gate->corroborated = corroborated;
        return FIX_GATE_ACCEPT;
    }
    const bool agrees =
        gate->have_suspect &&
        sq_(in->x_m - gate->suspect_x) + sq_(in->y_m - gate->suspect_y) <= sq_(FIX_GATE_JUMP_M);
    if (!agrees) {
        gate->refused_jump += gate->refused_jump < UINT16_MAX;
        gate->have_suspect = true;
        gate->suspect_x = in->x_m;
        gate->suspect_y = in->y_m;
        gate->suspect_since_us = (uint32_t)in->now_us;
        return FIX_GATE_REFUSE;
    }
    // The same fix again (the same ranges, solved again the next period) is no new evidence.
    const bool same = in->x_m == gate->suspect_x && in->y_m == gate->suspect_y;
    if (same || (uint32_t)in->now_us - gate->suspect_since_us < FIX_GATE_CONFIRM_US) {
        return FIX_GATE_REFUSE;
    }
    const bool carried = gate->travel_m < FIX_GATE_JUMP_M && gate->corroborated;
    take_(gate, in);
    gate->corroborated = false;
    if (carried) {
        return FIX_GATE_MOVED;
    }
    gate->drifts += gate->drifts < UINT16_MAX;
    return FIX_GATE_DRIFTED;
}
