// SPDX-License-Identifier: MIT
// dynaqpc world: a Cricket v2 listener on the robot, hearing the scenario's ceiling beacons.
//
// Each beacon transmits at its own random intervals, uniform in [cricket.min_interval,
// cricket.max_interval] (668-1332 ms as the real ones), first within one interval of the start.
// The listener hears one beacon per transmission and prints one line per range, in the Cricket v2
// default output format (fields in their fixed order, "\r\n" ending):
//
//   VR=2.0,ID=<beacon id>,SP=<space>,DB=<cm>,DR=<us>,TM=<ms>,TS=<ms>
//
//   DB  3-D distance from listener to beacon, whole cm (rounded), with the scenario's noise
//   DR  the ultrasound's time of flight for that distance at speed_of_sound, whole us (rounded)
//   TM  ms since this beacon's previous transmission (our choice: the meaning of the real field
//       is not checked; parsers should not rely on it)
//   TS  the listener's clock, ms since the listener's start (time of reception)
//
// Random draws come from the PRNG seeded with `seed` (a stream of its own, apart from World's).
#ifndef WORLD_CRICKET_H
#define WORLD_CRICKET_H

#include <cstdint>
#include <string>
#include <vector>

#include "world/random.h"
#include "world/scenario.h"

namespace world {

struct CricketLine {
    double time_s = 0.0;    ///< when the listener received it (the beacon's transmission time)
    int beacon = 0;         ///< index into scenario.cricket.beacons
    double range_m = 0.0;   ///< the noisy 3-D range the line reports
    double true_range_m = 0.0;
    std::string text;       ///< the whole line, "\r\n" included
};

class CricketListener {
public:
    /// `start_s` is the listener's time zero (TS counts from it).
    CricketListener(const Scenario &scenario, std::uint32_t seed, double start_s = 0.0);

    /// Appends to *out, in time order, one line per beacon transmission in (last time, t_s],
    /// ranged from the listener at (x, y, listener_height). Call it as time advances (e.g. every
    /// physics step or control period) with the robot's current position; t_s never goes back
    /// (an earlier t_s emits nothing).
    void advance(double t_s, double x, double y, std::vector<CricketLine> *out);

    int beacon_count() const { return static_cast<int>(beacons_.size()); }

private:
    CricketSpec spec_;
    std::vector<Beacon> beacons_;
    std::vector<double> next_s_;  // next transmission time of each beacon
    std::vector<double> prev_s_;  // previous transmission time of each beacon
    double start_s_;
    double now_s_;
    RandomStream rng_;

    double interval() { return rng_.uniform(spec_.min_interval, spec_.max_interval); }
};

}  // namespace world

#endif  // WORLD_CRICKET_H
