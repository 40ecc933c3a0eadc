// SPDX-License-Identifier: MIT
// dynaqpc world: the Cricket v2 listener model.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "world/cricket.h"

namespace world {

CricketListener::CricketListener(const Scenario &scenario, std::uint32_t seed, double start_s)
    : spec_(scenario.cricket), beacons_(scenario.cricket.beacons), start_s_(start_s),
      now_s_(start_s), rng_(seed, 5)
{
    // Beacons were switched on long before: each one's first transmission falls anywhere within
    // one interval from the start, and its "previous" one an interval before that.
    for (std::size_t i = 0; i < beacons_.size(); ++i) {
        double first = start_s + rng_.uniform() * interval();
        next_s_.push_back(first);
        prev_s_.push_back(first - interval());
    }
}

void CricketListener::advance(double t_s, double x, double y, std::vector<CricketLine> *out)
{
    if (t_s <= now_s_) return;
    now_s_ = t_s;
    for (;;) {
        // The beacon that transmits next (the lowest index on a tie: deterministic).
        std::size_t b = beacons_.size();
        for (std::size_t i = 0; i < beacons_.size(); ++i) {
            if (next_s_[i] <= t_s && (b == beacons_.size() || next_s_[i] < next_s_[b])) b = i;
        }
        if (b == beacons_.size()) return;
        const Beacon &bc = beacons_[b];
        const double when = next_s_[b];
        const double dz = bc.z - spec_.listener_height;
        const double truth = std::sqrt((bc.x - x) * (bc.x - x) + (bc.y - y) * (bc.y - y) + dz * dz);
        // A missed transmission or a reflection (drawn only when the scenario asks for them, so
        // that a listener without them draws as before).
        const bool missed = spec_.dropout > 0.0 && rng_.uniform() < spec_.dropout;
        double detour = 0.0;
        if (spec_.outlier > 0.0 && rng_.uniform() < spec_.outlier) {
            detour = spec_.outlier_max * (1.0 - rng_.uniform());  // in (0, outlier_max]
        }
        if (missed) {
            prev_s_[b] = when;
            next_s_[b] = when + interval();
            continue;
        }
        const double range = std::max(0.0, truth + detour + spec_.noise_sd * rng_.normal());
        const long db = std::lround(range * 100.0);
        const long dr = std::lround(range / spec_.speed_of_sound * 1e6);
        const long tm = std::lround((when - prev_s_[b]) * 1000.0);
        const long ts = std::lround((when - start_s_) * 1000.0);
        char buf[160];
        std::snprintf(buf, sizeof buf, "VR=2.0,ID=%s,SP=%s,DB=%ld,DR=%ld,TM=%ld,TS=%ld\r\n",
                      bc.id.c_str(), spec_.space.c_str(), db, dr, tm, ts);
        CricketLine line;
        line.time_s = when;
        line.beacon = static_cast<int>(b);
        line.range_m = range;
        line.true_range_m = truth;
        line.text = buf;
        out->push_back(std::move(line));
        prev_s_[b] = when;
        next_s_[b] = when + interval();
    }
}

}  // namespace world
