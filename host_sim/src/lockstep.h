// SPDX-License-Identifier: MIT
// dynaqpc-sim: the lock-step runner — the real firmware application, through the host port,
// driving the simulated robot in virtual time.
#ifndef DYNAQPC_SIM_LOCKSTEP_H
#define DYNAQPC_SIM_LOCKSTEP_H

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "agent/agent.h"
#include "robot/robot_config.h"

namespace world {
struct Scenario;
}

namespace dynaqpc {

/// MCU cycles per planning update when neither the algorithm nor `--plan-cycles` says (the
/// algorithms each give their own: agent_info_t.plan_cycles, `dynaqpc-sim agents`).
constexpr std::uint32_t kDefaultPlanCycles = 4213;

/// The seed of set `set` (1, 2, ...) of an experiment seeded with `seed`: the world's, the
/// devices' and the firmware's seed of that set (`train --seed S`, `devices --seed S --set K`).
std::uint32_t set_seed(std::uint32_t seed, std::uint32_t set);

/// The cycles per planning update charged to `kind` in idle time: the algorithm's own Cortex-M4
/// measurement (agent_info_t.plan_cycles). Same CPU time for every agent: a cheaper update buys
/// more.
std::uint32_t plan_cycles_of(agent_kind_t kind);

/// One finished episode, as the train CSV reports it.
struct EpisodeRow {
    std::uint32_t episode = 0;
    std::uint32_t steps = 0;
    double reward = 0.0;
    bool reached_goal = false;
    std::uint32_t bumps = 0;
    double robot_time_s = 0.0;  ///< simulated time the episode took
    std::uint64_t updates = 0;  ///< Q updates, real plus planning, during the episode
    double wall_s = 0.0;        ///< host time spent on it
};

/// One control period of the robot, for trajectory logs.
struct TrajectoryPoint {
    std::uint32_t step = 0;     ///< real steps so far in the episode
    double time_s = 0.0;        ///< since the episode started
    double x = 0.0, y = 0.0, heading = 0.0;  ///< the simulated robot's true pose
    int action = -1;            ///< the action chosen in this period, -1 if none
    double reward = 0.0;        ///< reward of the step that ended in this period
    bool bump = false;
    bool in_goal = false;
};

struct LockstepOptions {
    std::uint32_t seed = 1;
    /// Flash image file of the firmware ("" = RAM only). The firmware saves what it learned there
    /// at episode ends and restores it at boot, as on the robot.
    std::string flash_file;
    /// Boot from flash_file but never write it: the firmware's saves change a copy in RAM
    /// (dynaqpc-sim run --learn).
    bool flash_read_only = false;
    /// Replay greedily without learning (dynaqpc-sim run without --learn).
    bool evaluate = false;
    /// Modelled MCU cycles per planning update, for idle-time planning (robot_config planning 0,
    /// the shipped scenarios' default).
    std::uint32_t plan_update_cycles = kDefaultPlanCycles;
};

/// The simulated robot, its devices on an in-process bus, the firmware application on the host
/// port, and a supervisor that places the robot at a random start and starts each episode with a
/// TOOL_CMD frame, as an operator would. One per process: the firmware is a singleton.
class Lockstep {
public:
    Lockstep(const world::Scenario &scenario, const robot_config_t &cfg, const LockstepOptions &opt);
    ~Lockstep();
    Lockstep(const Lockstep &) = delete;
    Lockstep &operator=(const Lockstep &) = delete;

    /// Places the robot at a random start pose and runs one episode to the goal or the step cap.
    EpisodeRow run_episode();

    /// The room changes (train/run --change-at K --changed FILE): from the next episode on, the
    /// world's obstacles are `changed`'s. The firmware is not told. `changed` must be a change of
    /// the scenario this runner was built with (world::layout_change_problem() says "").
    void change_layout(const world::Scenario &changed);

    /// Called every control period while set.
    void set_trajectory_sink(std::function<void(const TrajectoryPoint &)> sink);

    /// Whether the firmware restored what it learned from the flash file at boot.
    bool restored() const;

    /// The firmware's agent, for reading what it holds (dynaqpc-sim learned); owned by the firmware.
    agent_t *agent() const;

    /// Firmware counters for reports: Q rows dropped, planning updates per period, misses.
    std::string counters() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace dynaqpc

#endif  // DYNAQPC_SIM_LOCKSTEP_H
