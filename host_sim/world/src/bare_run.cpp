// SPDX-License-Identifier: MIT
// dynaqpc world: the bare world driven as lock-step drives it (see bare_run.h).
#include "world/bare_run.h"

#include <chrono>
#include <vector>

#include "world/cricket.h"
#include "world/motion.h"
#include "world/random.h"
#include "world/world.h"

namespace world {

double run_bare_world(const Scenario &s, long periods, std::uint32_t seed, BareRunTotals *t)
{
    World w(s, seed);
    RandomStream actions(seed, 100);
    CricketListener cricket(s, seed);
    std::vector<CricketLine> lines;
    std::vector<float> ranges(static_cast<std::size_t>(w.ray_count()));
    w.reset(w.sample_start_pose());
    long in_episode = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (long p = 0; p < periods; ++p) {
        const auto a = static_cast<Action>(static_cast<int>(actions.uniform() * 4.0));
        const WheelSpeeds v = wheel_targets_for(s, a, w.wheel_speeds());
        w.set_wheel_targets(v.left, v.right);
        w.step_period();
        w.range_readings(ranges.data());
        t->checksum += (ranges.empty() ? 0.0 : ranges[0]) + w.gyro_rate();
        if (s.gps.enabled) t->checksum += w.gps_pose().x;
        if (!s.cricket.beacons.empty()) {
            const Pose pose = w.pose();
            lines.clear();
            cricket.advance(w.time_s(), pose.x, pose.y, &lines);
            t->cricket_lines += static_cast<long>(lines.size());
        }
        if (w.bumped()) {
            ++t->bumps;
            w.clear_bump();
        }
        ++in_episode;
        if (w.in_goal() || in_episode >= static_cast<long>(s.learning.step_cap)) {
            t->goals += w.in_goal() ? 1 : 0;
            w.reset(w.sample_start_pose());
            in_episode = 0;
        }
    }
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace world
