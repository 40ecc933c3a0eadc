// SPDX-License-Identifier: MIT
// dynaqpc-sim speed: how fast lock-step runs the firmware against how fast the bare world runs,
// measured in the same process, round after round, so that the host's load weighs on both alike.
//
// A round: one set of `--episodes` episodes in lock-step (the firmware, its devices on the
// in-process bus, the world), timed; then the bare world alone for as many control periods as the
// set simulated, each as a lock-step period drives it (wheel targets of a random action, the
// physics substeps, every ray, the gyro, the GPS or the Cricket listener, bump and goal checks).
// Both as simulated seconds per wall second; the ratio is the firmware's share of the cost: 1 would
// be a firmware that costs nothing, 0.5 one that costs what the world does.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "commands.h"
#include "lockstep.h"
#include "options.h"
#include "scenario_bridge.h"
#include "world/bare_run.h"
#include "world/scenario.h"

namespace dynaqpc {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0)
{
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

}  // namespace

int cmd_speed(const std::string &program, const std::vector<std::string> &args)
{
    std::string scenario = "paper-lab-real", agent = "dyna-qpc";
    std::uint32_t planning = 0, episodes = 60, rounds = 3, seed = 9001;
    Options o("speed", "lock-step's speed against the bare world's, measured in the same run");
    o.add_string("--scenario", "S", "paper-lab-real (default), paper-sim-real, any shipped name or a file",
                 &scenario);
    o.add_choice("--agent", "NAME", agent_kind_list() + " (default dyna-qpc)", &agent, agent_kind_names());
    o.add_uint("--planning", "N", "planning updates per real step (default: the scenario's, idle time)",
               &planning, 0, 1000000);
    o.add_uint("--episodes", "E", "episodes of the lock-step set in each round (default 60: mostly a learnt robot, as in use)", &episodes, 1,
               100000);
    o.add_uint("--rounds", "R", "rounds, each a lock-step set then the bare world (default 3; medians)",
               &rounds, 1, 100);
    o.add_uint("--seed", "S", "seed: round k runs set k of `train --seed S` (default 9001)", &seed, 0,
               UINT32_MAX);
    if (o.parse_or_usage(args, program)) {
        std::cout << "\nPrints one line a round and a summary:\n"
                     "  speed: scenario=S lockstep_x=L world_x=W ratio=L/W (medians of the rounds)\n"
                     "where L and W are simulated seconds per wall second of lock-step (firmware + devices +\n"
                     "world) and of the bare world over as many control periods; the target is ratio >= 0.5.\n";
        return kExitOk;
    }
    const ScenarioBundle sb = load_scenario(scenario);
    robot_config_t cfg = sb.robot;
    apply_overrides(o, {&agent, &planning}, &cfg);
    const double period_s = sb.world->timing.control_period;
    std::vector<double> lock_x, world_x, ratio;
    world::BareRunTotals bare;  // its checksum, printed, keeps the readings from being optimised away
    for (std::uint32_t r = 1; r <= rounds; r++) {
        LockstepOptions lo;
        lo.seed = set_seed(seed, r);
        if (cfg.planning == 0) lo.plan_update_cycles = plan_cycles_of(cfg.agent);
        double robot_s = 0.0;
        double lock_wall = 0.0;
        {
            Lockstep sim(*sb.world, cfg, lo);
            const Clock::time_point t0 = Clock::now();
            for (std::uint32_t e = 0; e < episodes; e++) robot_s += sim.run_episode().robot_time_s;
            lock_wall = seconds_since(t0);
        }
        const long periods = std::max(1L, static_cast<long>(robot_s / period_s + 0.5));
        const double world_wall = world::run_bare_world(*sb.world, periods, lo.seed, &bare);
        const double lx = robot_s / lock_wall;
        const double wx = static_cast<double>(periods) * period_s / world_wall;
        lock_x.push_back(lx);
        world_x.push_back(wx);
        ratio.push_back(lx / wx);
        std::printf("round %u: periods=%ld lockstep_wall_s=%.3f world_wall_s=%.3f lockstep_x=%.0f world_x=%.0f "
                    "ratio=%.2f\n",
                    r, periods, lock_wall, world_wall, lx, wx, lx / wx);
        std::fflush(stdout);
    }
    std::printf("speed: scenario=%s agent=%s planning=%u lockstep_x=%.0f world_x=%.0f ratio=%.2f (target >= 0.5; "
                "checksum %.6g)\n",
                sb.name.c_str(), agent.c_str(), cfg.planning, median(lock_x), median(world_x), median(ratio),
                bare.checksum);
    return kExitOk;
}

}  // namespace dynaqpc
