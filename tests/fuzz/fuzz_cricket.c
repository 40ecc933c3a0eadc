// SPDX-License-Identifier: MIT
// Fuzz target: bytes on the Cricket serial line, into the listener's parser and trilateration
// (paper-lab's beacons), and every fix into the state encoder, as the control task uses them.
// Input: chunks of [length byte, time step byte, bytes...].
#include <math.h>

#include "drivers/cricket.h"
#include "fuzz.h"
#include "robot/robot_config.h"
#include "robot/robot_geometry.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const robot_config_t *cfg = &robot_config_paper_lab;
    static cricket_t ck;
    static cricket_beacon_t beacons[ROBOT_MAX_BEACONS];
    struct cricket_config cc;
    cricket_default_config(&cc);
    for (uint32_t i = 0; i < cfg->n_beacons; i++) {
        beacons[i] = (cricket_beacon_t){cfg->beacons[i].id, cfg->beacons[i].x * 1000.0f,
                                        cfg->beacons[i].y * 1000.0f, cfg->beacons[i].z * 1000.0f};
    }
    cc.beacons = beacons;
    cc.n_beacons = cfg->n_beacons;
    cc.listener_z_mm = cfg->listener_z * 1000.0f;
    if (cricket_init(&ck, &cc) != 0) {
        __builtin_trap();
    }
    fuzz_in_t in = {data, size};
    uint64_t now = 1000000u;
    while (in.left > 0u) {
        const size_t want = fuzz_u8(&in);
        now += (uint64_t)fuzz_u8(&in) * 10000u;
        const uint8_t *bytes;
        const size_t n = fuzz_take(&in, want, &bytes);
        (void)cricket_feed(&ck, bytes, n, now);
        if ((want & 7u) == 0u) {
            cricket_note_motion(&ck, now);
        }
        cricket_fix_t fix;
        if (cricket_get_fix(&ck, now, &fix) != CRICKET_FIX_LOST) {
            if (!isfinite(fix.x_mm) || !isfinite(fix.y_mm)) {
                __builtin_trap();  // a fix the controller would turn into a pose
            }
            const robot_pose_t pose = {fix.x_mm * 0.001f, fix.y_mm * 0.001f,
                                       (float)(want % 628u) * 0.01f};
            const float ranges[3] = {fix.x_mm * 0.001f, 0.2f, 100.0f};
            const agent_state_t s =
                robot_encode_state(cfg, &pose, robot_range_code(cfg, ranges, cfg->n_ranges));
            if ((s >> (cfg->bits_x + cfg->bits_y + cfg->bits_heading + cfg->bits_code)) != 0u) {
                __builtin_trap();  // outside the agent's state space
            }
            (void)robot_in_goal(cfg, &pose);
        }
    }
    return 0;
}
