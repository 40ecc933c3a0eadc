// SPDX-License-Identifier: MIT
// dynaqpc-sim: the lock-step runner.
//
// Time advances in physics steps (16 ms). At each step: the devices put their due frames on the
// in-process bus and the Cricket listener its serial lines (a frame due between two steps at its
// own time, the firmware's clock set to it); the firmware runs (sched_step) until it waits; what
// it sent is taken off the bus (the motor controller obeys MOTOR_CMD, the supervisor watches
// TLM_EPISODE); then the world moves one step. The firmware sees exactly the frames and bytes a
// robot's controller would.
#include "lockstep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "agent_pick.h"
#include "devices.h"
#include "drivers/telemetry.h"
#include "dynaqpc_can.h"
#include "hal/hal_time.h"
#include "hal_host/hal_host.h"
#include "robot/robot_app.h"
#include "robot/pose_trust.h"
#include "robot/robot_motion.h"
#include "supervisor.h"
#include "world/scenario.h"
#include "world/world.h"

namespace dynaqpc {

namespace {

constexpr std::uint32_t kCpuHz = 168000000u;

}  // namespace

struct Lockstep::Impl {
    robot_config_t cfg;
    LockstepOptions opt;
    world::World world;
    Devices devices;
    agent_t *agent = nullptr;
    const agent_storage_t *storage = nullptr;
    std::uint64_t t_us = 0;
    std::uint64_t dt_us = 0;
    std::uint64_t max_lead_us = 0;  // the most the firmware's clock ran past the next tick
    std::uint8_t tool_ctr = 0;
    bool restored = false;
    std::function<void(const TrajectoryPoint &)> sink;
    std::vector<hal_can_frame_t> frames;
    std::string serial;
    // The episode in progress, as the supervisor sees it on the bus.
    bool episode_over = false;
    std::uint32_t episode_steps = 0;        // TLM_LEARN frames (steps taken) in the episode
    std::uint32_t episode_fixes[4] = {0};  // TLM_POSE frames in the episode, by tlm_fix_state
    tlm_episode_t episode{};
    std::uint64_t episode_start_us = 0, episode_end_us = 0;
    TrajectoryPoint point;
    bool point_has_action = false;
    PoseCheck pose_check;  // the firmware's pose against the world's, over the set

    Impl(const world::Scenario &sc, const robot_config_t &c, const LockstepOptions &o)
        : cfg(c), opt(o), world(sc, o.seed), devices(world, o.seed)
    {
        cfg.name = world.scenario().name.c_str();
        // Aligned turns keep the robot on the quarter-turn grid; fixed turns keep it on multiples
        // of the turn where its start settles there (robot_settles()). Other turns have no grid.
        if (sc.actions.aligned != 0 || robot_settles(&cfg)) pose_check.set_heading_grid(sc.actions.turn);
        dt_us = static_cast<std::uint64_t>(std::llround(sc.timing.physics_dt * 1e6));
        hal_host_reset();
        hal_host_time_set_mode(HAL_HOST_CLOCK_LOCKSTEP);
        hal_host_cpu_set_hz(kCpuHz);
        if (hal_host_flash_configure(FW_CFG_HOST_FLASH_SECTOR_SIZE, FW_CFG_HOST_FLASH_SECTOR_COUNT,
                                     FW_CFG_HOST_FLASH_WRITE_ALIGN) != 0) {
            throw std::runtime_error("host flash: cannot configure 4 x 128 KB");
        }
        if (!opt.flash_file.empty()) {
            const int err = opt.flash_read_only ? hal_host_flash_load_file(opt.flash_file.c_str())
                                                : hal_host_flash_attach_file(opt.flash_file.c_str());
            if (err != 0) {
                throw std::runtime_error(opt.flash_file + ": not a flash image of this firmware (size) or unreadable");
            }
        }
        robot_app_options_t ao = host_app_options(cfg, opt.seed);
        agent = ao.agent;
        storage = ao.storage;
        ao.evaluate = opt.evaluate;
        ao.auto_start = false;
        if (cfg.planning == 0) {
            ao.plan_cycles = opt.plan_update_cycles;
            ao.plan_budget_us = opt.plan_update_cycles / (kCpuHz / 1000000u) + 1u;
        }
        const int err = robot_app_init(&ao);
        if (err != 0) {
            throw std::runtime_error("firmware: robot_app_init failed (" + std::to_string(err) + ")");
        }
        robot_app_stats_t st;
        robot_app_get_stats(&st);
        restored = st.restore_result == 0;
    }

    ~Impl()
    {
        hal_host_flash_detach_file();
    }

    void deliver(const hal_can_frame_t &f)
    {
        (void)hal_host_can_deliver(&f);  // filtered frames are not for the firmware
    }

    void take_tx()
    {
        hal_can_frame_t f;
        while (hal_host_can_take_tx(&f)) {
            devices.receive(f, t_us);
            pose_check.on_frame(f, world.pose());
            tlm_pose_t pose;
            if (f.id == DYNAQPC_CAN_TLM_POSE_FRAME_ID && tlm_decode_pose(&f, &pose) == 0) {
                episode_fixes[std::min<unsigned>(pose.fix_state, TLM_FIX_LOST)]++;
            }
            if (f.id == DYNAQPC_CAN_TLM_LEARN_FRAME_ID) episode_steps++;
            if (f.id == DYNAQPC_CAN_TLM_EPISODE_FRAME_ID) {
                if (tlm_decode_episode(&f, &episode) == 0) {
                    episode_over = true;
                    episode_end_us = t_us;
                }
            } else if (f.id == DYNAQPC_CAN_TLM_LEARN_FRAME_ID && sink) {
                tlm_learn_t l;
                if (tlm_decode_learn(&f, &l) == 0) {
                    point.action = l.action;
                    point.reward = l.reward;
                    point.step = l.step;
                    point_has_action = true;
                }
            }
        }
    }

    // The firmware runs until it waits for a time after now, or until its clock reaches `until`.
    // Idle planning never runs out of work while it has time, and on a robot the next sensor
    // frame interrupts it; here that frame is delivered when the firmware stops, so it must not
    // plan past it: a firmware clock ahead of the world stamps the next frames late and compresses
    // their spacing (the gyro's integration broke when idle planning ran up to 350 ms ahead). A
    // pass is bounded (at most FW_CFG_SCHED_IDLE_STEPS_PER_PASS planning steps), so the lead stays
    // under one pass; the largest past a physics step is counted in max_lead_us. The pass bound
    // only guards against a firmware bug spinning the simulator.
    void run_firmware(std::uint64_t until_us)
    {
        for (int pass = 0; pass < 100000; pass++) {
            robot_app_step();
            take_tx();
            if (hal_host_wait_deadline() > hal_time_us() || hal_time_us() >= until_us) {
                break;
            }
        }
    }

    // One physics step of the whole system. The devices' frames come at their own cycles (16 ms,
    // 48 ms, ...): one due between this step and the next is delivered at its time, the world as
    // it stands at this step (a physics step that divides every cycle, such as 16 ms, has none).
    void tick()
    {
        const std::uint64_t next_tick_us = t_us + dt_us;
        for (std::uint64_t at = t_us;;) {
            frames.clear();
            serial.clear();
            devices.emit(at, &frames, &serial);
            if (at > hal_time_us()) {
                (void)hal_host_time_set_us(at);
            }
            for (const hal_can_frame_t &f : frames) {
                deliver(f);
            }
            if (!serial.empty()) {
                (void)hal_host_uart_feed(reinterpret_cast<const std::uint8_t *>(serial.data()), serial.size());
            }
            const std::uint64_t until = std::min(devices.next_due_us(), next_tick_us);
            run_firmware(until);
            if (until == next_tick_us) break;
            at = until;
        }
        if (hal_time_us() > next_tick_us) {
            max_lead_us = std::max<std::uint64_t>(max_lead_us, hal_time_us() - next_tick_us);
        }
        if (sink && t_us % cfg.period_us == 0) {
            const world::Pose p = world.pose();
            point.time_s = static_cast<double>(t_us - episode_start_us) * 1e-6;
            point.x = p.x;
            point.y = p.y;
            point.heading = p.heading;
            point.in_goal = world.in_goal();
            if (!point_has_action) point.action = -1;
            sink(point);
            point = TrajectoryPoint{};
            point_has_action = false;
        }
        world.step();
        t_us += dt_us;
        point.bump = point.bump || world.bumped();
        devices.check_timeouts(t_us);
    }

    EpisodeRow run_episode()
    {
        const auto wall0 = std::chrono::steady_clock::now();
        const std::uint64_t updates0 = agent_updates(agent);
        const world::Pose start = world.sample_start_pose();
        world.reset(start);
        // The operator puts the robot down and starts the episode.
        const hal_can_frame_t f = start_episode_frame(cfg, start, &tool_ctr);
        if (t_us > hal_time_us()) (void)hal_host_time_set_us(t_us);
        deliver(f);
        episode_over = false;
        episode_steps = 0;
        std::fill(std::begin(episode_fixes), std::end(episode_fixes), 0u);
        episode_start_us = t_us;
        const std::uint64_t limit_us = episode_limit_us(cfg);
        while (!episode_over) {
            tick();
            if (t_us - episode_start_us > limit_us) {
                // A robot without a fresh position fix waits for one and takes no step: the step
                // cap is not what failed (rooms --check refuses beacons in a line).
                if (episode_steps == 0) {
                    throw std::runtime_error(
                        "the firmware took no step in the episode's " +
                        std::to_string((t_us - episode_start_us) / 1000000u) +
                        " s of robot time: it waits for a fresh position fix (of its control periods' fixes " +
                        std::to_string(episode_fixes[TLM_FIX_FRESH]) + " fresh, " +
                        std::to_string(episode_fixes[TLM_FIX_STALE]) + " stale, " +
                        std::to_string(episode_fixes[TLM_FIX_MOVING]) + " moving, " +
                        std::to_string(episode_fixes[TLM_FIX_LOST]) +
                        " none); check the pose source: dynaqpc-sim rooms --check, docs/scenarios.md (" + counters() +
                        ")");
                }
                throw std::runtime_error("the firmware did not end the episode within its step cap (" +
                                         counters() + ")");
            }
        }
        EpisodeRow row;
        row.episode = episode.episode;
        row.steps = episode.steps;
        row.reward = episode.total_reward;
        row.reached_goal = episode.reached_goal;
        row.bumps = episode.bumps;
        row.robot_time_s = static_cast<double>(episode_end_us - episode_start_us) * 1e-6;
        row.updates = agent_updates(agent) - updates0;
        row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
        return row;
    }

    std::string counters() const
    {
        robot_app_stats_t st;
        robot_app_get_stats(&st);
        sched_stats_t ss;
        sched_get_stats(robot_app_sched(), &ss);
        std::ostringstream o;
        agent_counter_t counters[AGENT_MAX_COUNTERS];
        const uint32_t n = agent_counters(agent, counters);
        for (uint32_t i = 0; i < n; i++) {
            o << (i ? " " : "") << counters[i].name << "=" << counters[i].value;
            if (counters[i].capacity != 0u) {
                o << "/" << counters[i].capacity;
            }
        }
        o << " frames_rx=" << st.frames_rx << " frames_bad=" << st.frames_bad
          << " tx_dropped=" << st.frames_tx_dropped << " saves=" << st.saves << " save_errors=" << st.save_errors
          << " plan_per_period=" << ss.idle_steps_last_period << " misses=" << ss.task[0].misses
          << " trust_losses=" << st.trust_losses << " trust_lost_gyro_gap=" << st.trust_losses_by[POSE_TRUST_WHY_GYRO_GAP]
          << " trust_lost_fix_jump=" << st.trust_losses_by[POSE_TRUST_WHY_FIX_JUMP] << " trust_lost_stall=" << st.trust_losses_by[POSE_TRUST_WHY_STALL]
          << " episodes_interrupted=" << st.episodes_interrupted
          << " fixes_outside=" << robot_app_fix_gate()->refused_outside
          << " fix_jumps_refused=" << robot_app_fix_gate()->refused_jump
          << " fix_drifts=" << robot_app_fix_gate()->drifts
          << " events_dropped=" << ss.events_dropped << " safe_stops=" << robot_app_ctrl()->safe_stops
          << " loops_left=" << robot_app_ctrl()->loop_escapes
          << " clock_lead_max_us=" << max_lead_us << " " << pose_check.summary() << aliasing_cells();
        return o.str();
    }

    // The cells the aliasing watch counts (alias.h), most first: " aliasing=x,y:count;...", or
    // nothing when none aliased.
    std::string aliasing_cells() const
    {
        struct Cells {
            agent_space_t space;
            std::ostringstream out;
            static int take(void *data, const agent_fact_t *fact)
            {
                auto &c = *static_cast<Cells *>(data);
                if (fact->kind != AGENT_FACT_ALIAS) return 0;
                uint32_t comp[FW_CFG_MAX_COMPONENTS] = {0};
                space_unpack(&c.space, fact->u.alias.cell, comp);
                c.out << (c.out.tellp() == 0 ? " aliasing=" : ";") << comp[0] << "," << comp[1] << ":"
                      << fact->u.alias.count;
                return 0;
            }
        } cells;
        robot_config_space(&cfg, &cells.space);
        (void)agent_walk(agent, AGENT_FACT_ALIAS, Cells::take, &cells);
        return cells.out.str();
    }
};

Lockstep::Lockstep(const world::Scenario &scenario, const robot_config_t &cfg, const LockstepOptions &opt)
    : impl_(std::make_unique<Impl>(scenario, cfg, opt))
{
}

Lockstep::~Lockstep() = default;

EpisodeRow Lockstep::run_episode()
{
    return impl_->run_episode();
}

void Lockstep::change_layout(const world::Scenario &changed)
{
    const std::string problem = world::layout_change_problem(impl_->world.scenario(), changed);
    if (!problem.empty()) throw std::invalid_argument("change_layout: " + problem);
    impl_->world.set_obstacles(changed.obstacles);
}

void Lockstep::set_trajectory_sink(std::function<void(const TrajectoryPoint &)> sink)
{
    impl_->sink = std::move(sink);
}

bool Lockstep::restored() const
{
    return impl_->restored;
}

agent_t *Lockstep::agent() const
{
    return impl_->agent;
}

std::string Lockstep::counters() const
{
    return impl_->counters();
}

// Set k of an experiment seeded with s: a splitmix-style mix, so neighbouring seeds and sets
// give unrelated streams, and a set's results do not depend on --jobs.
std::uint32_t plan_cycles_of(agent_kind_t kind)
{
    agent_info_t info;
    return agent_kind_info(kind, &info) == FW_OK ? info.plan_cycles : kDefaultPlanCycles;
}

std::uint32_t set_seed(std::uint32_t seed, std::uint32_t set)
{
    std::uint64_t z = (static_cast<std::uint64_t>(seed) << 32) + set + 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return static_cast<std::uint32_t>((z ^ (z >> 31)) >> 16);
}

}  // namespace dynaqpc
