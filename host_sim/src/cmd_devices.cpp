// SPDX-License-Identifier: MIT
// dynaqpc-sim devices: the simulated robot's devices in real time on the virtual CAN bus, for a
// firmware in another process (dynaqpc-fw, or a robot's controller bridged to the bus).
//
// One thread. World time advances in physics steps (the scenario's physics_dt); step k is due at
// wall time k * dt / speed after the start. At each step the devices' due frames go on the bus
// (paced by vcan: UDP has no flow control; a frame due between two steps at its own time) and the
// Cricket listener's lines into the pty; until the next step is due the bus is read: MOTOR_CMD
// drives the wheels, and the supervisor watches the firmware's telemetry. A step that falls
// behind its wall time (a busy host) runs at once, so world time keeps up with the firmware's
// clock; such steps are counted (late_steps).
#include <poll.h>
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bus_link.h"
#include "commands.h"
#include "devices.h"
#include "lockstep.h"
#include "drivers/telemetry.h"
#include "dynaqpc_can.h"
#include "options.h"
#include "pty.h"
#include "scenario_bridge.h"
#include "supervisor.h"
#include "world/scenario.h"
#include "world/world.h"

namespace dynaqpc {

namespace {

using Clock = std::chrono::steady_clock;

// After the last step, frames still in flight from the firmware are counted for this long.
constexpr int kDrainMs = 500;
// The supervisor repeats START_EPISODE when the firmware still reports itself idle this long
// (robot time) after it was sent: a firmware that booted after the command, or a lost frame.
constexpr std::uint64_t kStartRetryUs = 1500000;
// A START refused as BUSY (a firmware that booted after a cut and has not yet seen its wheels
// stand: docs/can-protocol.md "Reboots") is sent again this much later, with the heading then.
constexpr std::uint64_t kStartBusyRetryUs = 100000;
// A safe stop the firmware does not leave by itself within this much world time: the operator
// puts the robot down at a new start and starts again (as one would pick up a stuck robot).
constexpr std::uint64_t kSafeStopRestartUs = 10000000;
// FW_STATUS comes every second: three missed ones and the firmware counts as silent.
constexpr std::uint64_t kStatusSilenceUs = 3000000;

std::atomic<bool> g_stop{false};

extern "C" void on_devices_signal(int)
{
    g_stop.store(true);
}

struct DevicesSettings {
    std::string scenario;
    double speed = 1.0;
    std::uint32_t seed = 1;
    std::uint32_t set = 0;
    double duration = 0.0;
    bool supervise = false;
    std::uint32_t episodes = 0;
    bool wait_firmware = false;
};

// A frame only the firmware sends: its status (every second, first 1 ms after boot) or its pose.
bool from_firmware(const hal_can_frame_t &f)
{
    return f.id == DYNAQPC_CAN_TLM_POSE_FRAME_ID || f.id == DYNAQPC_CAN_FW_STATUS_FRAME_ID;
}

// The operator: puts the robot down at a random start, starts an episode with TOOL_CMD, waits for
// the firmware's TLM_EPISODE, and again.
class Supervisor {
public:
    Supervisor(world::World &world, const robot_config_t &cfg, BusLink &bus) : world_(world), cfg_(cfg), bus_(bus) {}

    /// A frame from the firmware, at world time t_us. Returns true when an episode ended.
    bool on_frame(const hal_can_frame_t &f, std::uint64_t t_us)
    {
        if (!fw_seen_ && from_firmware(f)) {
            fw_seen_ = true;
        }
        if (running_) {
            check_.on_frame(f, world_.pose());
            if (first_after_boot_ && f.id == DYNAQPC_CAN_TLM_LEARN_FRAME_ID && check_.last_learned()) {
                // The reboot target (docs/reliability.md): the heading of the first step learned.
                std::printf("supervisor: first learned step after boot %u: head_err_deg=%.1f\n", boot_,
                            check_.last_heading_err_deg());
                std::fflush(stdout);
                first_after_boot_ = false;
            }
        }
        if (f.id == DYNAQPC_CAN_FW_STATUS_FRAME_ID) {
            tlm_status_t st;
            if (tlm_decode_status(&f, &st) == 0) {
                fw_idle_ = st.mode == TLM_MODE_IDLE;
                if (have_boot_ && st.boot_count != boot_) {
                    // A new boot: the episode it cut comes as an interrupted TLM_EPISODE (the
                    // firmware's flash journal); a retried start sends the robot's heading now.
                    reboots_++;
                    first_after_boot_ = true;
                    std::printf("supervisor: the firmware rebooted (boot %u, reset cause %u, pose %s)\n", st.boot_count,
                                st.reset_cause, st.pose_trusted ? "trusted" : "not trusted");
                    std::fflush(stdout);
                    sent_us_ = t_us;  // give its report a moment before a retry
                }
                have_boot_ = true;
                boot_ = st.boot_count;
                last_status_us_ = t_us;
                if (silent_) {
                    std::printf("supervisor: the firmware is heard again\n");
                    silent_ = false;
                }
                last_errors_ = st.errors;
                const bool safe = st.mode == TLM_MODE_SAFE_STOP;
                if (safe && !fw_safe_) {
                    safe_stops_++;
                    safe_since_us_ = t_us;
                    std::printf("supervisor: safe stop in episode %u (errors 0x%02x)\n", done_ + 1, st.errors);
                    std::fflush(stdout);
                }
                fw_safe_ = safe;
            }
        } else if (f.id == DYNAQPC_CAN_TOOL_ACK_FRAME_ID) {
            tlm_ack_t a;
            if (tlm_decode_ack(&f, &a) == 0 && a.command == TLM_CMD_START_EPISODE) {
                awaiting_ack_ = false;
                // Refused until the wheels stand (BUSY) or a silent device is back (DEVICE_SILENT;
                // FW_STATUS's errors say which): sent again.
                const bool refused = a.result == TLM_ACK_REFUSED;
                const bool silent = refused && a.reason == TLM_WHY_DEVICE_SILENT;
                if (silent && !device_silent_) {
                    std::printf("supervisor: the firmware refused the start: a device is silent (errors 0x%02x)\n",
                                last_errors_);
                    std::fflush(stdout);
                }
                device_silent_ = silent;
                busy_ = silent || (refused && a.reason == TLM_WHY_BUSY);
                if (busy_) busy_us_ = t_us;
            }
        } else if (f.id == DYNAQPC_CAN_TLM_LEARN_FRAME_ID) {
            awaiting_ack_ = false;  // an episode runs: the start was taken
        } else if (f.id == DYNAQPC_CAN_TLM_EPISODE_FRAME_ID && running_) {
            tlm_episode_t e;
            if (tlm_decode_episode(&f, &e) != 0) return false;
            if (awaiting_ack_ && e.interrupted) {
                // The episode our START cut (an --auto-start one, or one before a reboot): the
                // firmware reports it before it answers the START; ours has yet to run.
                std::printf("supervisor: the start cut the firmware's episode %u (%u steps)\n", e.episode, e.steps);
                std::fflush(stdout);
                cut_++;
                return false;
            }
            running_ = false;
            done_++;
            const double wall = std::chrono::duration<double>(Clock::now() - wall_start_).count();
            std::printf("episode=%u steps=%u reward=%d reached_goal=%d bumps=%u interrupted=%d robot_time_s=%.3f "
                        "wall_s=%.3f start=%.3f,%.3f,%.1f %s\n",
                        e.episode, e.steps, e.total_reward, e.reached_goal ? 1 : 0, e.bumps, e.interrupted ? 1 : 0,
                        static_cast<double>(t_us - start_us_) * 1e-6, wall, start_pose_.x, start_pose_.y,
                        start_pose_.heading * 57.29577951308232, check_.summary().c_str());
            std::fflush(stdout);
            return true;
        }
        return false;
    }

    /// Once per physics step, before the world moves.
    void poll(std::uint64_t t_us)
    {
        if (!fw_seen_) return;
        if (!silent_ && last_status_us_ != 0 && t_us - last_status_us_ > kStatusSilenceUs) {
            std::printf("supervisor: the firmware is silent (no FW_STATUS for %.1f s)\n", kStatusSilenceUs * 1e-6);
            std::fflush(stdout);
            silent_ = true;
        }
        if (running_ && fw_safe_ && t_us - safe_since_us_ > kSafeStopRestartUs) {
            std::printf("supervisor: safe stop held %.0f s: a new start\n", kSafeStopRestartUs * 1e-6);
            std::fflush(stdout);
            restarts_++;
            fw_safe_ = false;
            start(t_us);
            return;
        }
        if (!running_) {
            start(t_us);
        } else if (busy_ && t_us - busy_us_ >= kStartBusyRetryUs) {
            busy_ = false;
            send_start();
            sent_us_ = t_us;
            busy_retries_++;
        } else if (fw_idle_ && t_us - sent_us_ > kStartRetryUs) {
            send_start();
            sent_us_ = t_us;
            retries_++;
        } else if (t_us - start_us_ > episode_limit_us(cfg_)) {
            throw std::runtime_error("the firmware did not end episode " + std::to_string(done_ + 1) +
                                     " within its step cap");
        }
    }

    std::uint32_t episodes_done() const { return done_; }
    std::uint32_t start_retries() const { return retries_; }
    std::uint32_t start_busy_retries() const { return busy_retries_; }
    std::uint32_t safe_stops() const { return safe_stops_; }
    std::uint32_t safe_stop_restarts() const { return restarts_; }
    std::uint32_t reboots() const { return reboots_; }
    std::uint32_t episodes_cut_by_start() const { return cut_; }

private:
    void start(std::uint64_t t_us)
    {
        start_pose_ = world_.sample_start_pose();
        world_.reset(start_pose_);
        check_.reset();
        send_start();
        running_ = true;
        fw_idle_ = false;  // until a status says so after the command
        busy_ = false;
        start_us_ = sent_us_ = t_us;
        wall_start_ = Clock::now();
    }

    void send_start()
    {
        awaiting_ack_ = true;
        // The robot's heading now, as the operator measures it (a retry after a reboot finds the
        // robot where it drove to, not at the start).
        (void)bus_.send(start_episode_frame(cfg_, world_.pose(), &counter_));
    }

    world::World &world_;
    const robot_config_t &cfg_;
    BusLink &bus_;
    world::Pose start_pose_{};
    PoseCheck check_;
    bool fw_seen_ = false, fw_idle_ = false, running_ = false, fw_safe_ = false, silent_ = false;
    std::uint64_t start_us_ = 0, sent_us_ = 0, safe_since_us_ = 0, last_status_us_ = 0;
    std::uint32_t safe_stops_ = 0, restarts_ = 0;
    Clock::time_point wall_start_;
    std::uint8_t counter_ = 0;
    std::uint32_t done_ = 0, retries_ = 0;
    bool have_boot_ = false;
    bool first_after_boot_ = false;  // a reboot seen, no step learned since
    bool awaiting_ack_ = false;  // a START_EPISODE sent and not answered yet
    bool busy_ = false;          // the last START was refused as BUSY or DEVICE_SILENT: sent again at
                                 // busy_us_ + kStartBusyRetryUs
    bool device_silent_ = false; // the last START was refused as DEVICE_SILENT (said once)
    std::uint8_t last_errors_ = 0;  // FW_STATUS's last errors
    std::uint64_t busy_us_ = 0;
    std::uint32_t busy_retries_ = 0;
    std::uint32_t cut_ = 0;      // firmware episodes our starts cut
    std::uint32_t boot_ = 0, reboots_ = 0;
};

// Waits until `until` reading the bus; hands every frame to `on_frame`.
template <typename F>
void receive_until(BusLink &bus, Clock::time_point until, F on_frame)
{
    hal_can_frame_t f;
    for (;;) {
        while (bus.recv(&f, 0) == 1) on_frame(f);
        const auto now = Clock::now();
        if (now >= until || g_stop.load()) return;
        const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(until - now).count();
        struct timespec ts = {static_cast<time_t>(left / 1000000000), static_cast<long>(left % 1000000000)};
        struct pollfd p = {bus.rx_fd(), POLLIN, 0};
        (void)ppoll(&p, 1, &ts, nullptr);
    }
}

void declare_options(Options &o, DevicesSettings &s)
{
    o.add_string("--scenario", "S", "paper-sim, paper-lab, or a scenario file (docs/scenarios.md)", &s.scenario);
    o.add_double("--speed", "X", "world time runs X times faster than real time (default 1; the firmware's "
                 "--speed must match)", &s.speed, 0.0, 1000.0, true, false);
    o.add_uint("--seed", "N", "world and sensor noise seed (default 1)", &s.seed, 0, UINT32_MAX);
    o.add_uint("--set", "K", "use set K's seed of an experiment seeded with --seed, as `train --seed S` "
               "gives its set K (the world's and, printed as seed=N, the firmware's; default: --seed itself)",
               &s.set, 1, UINT32_MAX);
    o.add_double("--duration", "SEC", "stop after SEC seconds of wall time (default: until SIGINT/SIGTERM)",
                 &s.duration, 0.0, 1e9, true, false);
    o.add_flag("--supervise", "act as the operator: random start, TOOL_CMD START_EPISODE, one line per episode",
               &s.supervise);
    o.add_uint("--episodes", "N", "with --supervise: stop after N episodes", &s.episodes, 1, 100000000);
    o.add_flag("--wait-firmware", "send nothing (no frames, no Cricket lines) until the firmware is heard on "
               "the bus; world time starts then (for an exact frame count: tools/bench_bus.sh)",
               &s.wait_firmware);
}

// --wait-firmware: the devices are switched on once the firmware runs, so the firmware hears their
// first frame and the Cricket line's first byte. The heard frame goes to the supervisor. False if
// stopped (SIGINT/SIGTERM) before.
bool wait_for_firmware(BusLink &bus, Supervisor &sup, const DevicesSettings &s)
{
    const auto give_up = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                            std::chrono::duration<double>(s.duration > 0.0 ? s.duration : 1e9));
    bool heard = false;
    hal_can_frame_t first{};
    while (!heard && !g_stop.load() && Clock::now() < give_up) {
        receive_until(bus, std::min(give_up, Clock::now() + std::chrono::milliseconds(100)),
                      [&](const hal_can_frame_t &f) {
                          if (!heard && from_firmware(f)) {
                              heard = true;
                              first = f;
                          }
                      });
    }
    if (!heard) {
        if (g_stop.load()) return false;
        throw std::runtime_error("--wait-firmware: the firmware was not heard on the bus");
    }
    if (s.supervise) (void)sup.on_frame(first, 0);
    std::printf("devices: firmware heard; starting\n");
    std::fflush(stdout);
    return true;
}

// The devices' frames at t_us onto the bus, and the Cricket listener's bytes into its pty (nullptr:
// none); the buffers are the caller's, kept from step to step.
void emit(Devices &devices, BusLink &bus, pty_t *pty, std::uint64_t t_us, std::vector<hal_can_frame_t> *frames,
          std::string *serial, std::uint64_t *pty_bytes, std::uint64_t *pty_dropped)
{
    frames->clear();
    serial->clear();
    devices.emit(t_us, frames, serial);
    for (const hal_can_frame_t &f : *frames) (void)bus.send(f);
    if (pty != nullptr && !serial->empty()) {
        const int n = pty_write(pty, serial->data(), serial->size());
        const std::uint64_t written = n > 0 ? static_cast<std::uint64_t>(n) : 0u;
        *pty_bytes += written;
        *pty_dropped += serial->size() - written;  // nobody reading yet, or a reader too slow
    }
}

// What the run counted, for the last lines.
struct RunCounts {
    double wall_s;
    std::uint64_t t_us, late_steps, pty_bytes, pty_dropped;
};

void print_stopped(const RunCounts &c, const Supervisor &sup, const Devices &devices, const PoseCheck &pose_check,
                   const BusLink &bus)
{
    std::printf("devices: stopped after %.1f s wall, %.1f s world time; episodes=%u start_retries=%u start_busy_retries=%u "
                "safe_stops=%u safe_stop_restarts=%u reboots=%u cut_by_start=%u "
                "motor_cmds=%u motor_cmds_rejected=%u late_steps=%" PRIu64 " pty_bytes=%" PRIu64
                " pty_dropped=%" PRIu64 "\n",
                c.wall_s, static_cast<double>(c.t_us) * 1e-6, sup.episodes_done(), sup.start_retries(), sup.start_busy_retries(),
                sup.safe_stops(), sup.safe_stop_restarts(), sup.reboots(), sup.episodes_cut_by_start(),
                devices.motor_cmds(), devices.motor_cmds_rejected(), c.late_steps, c.pty_bytes, c.pty_dropped);
    std::printf("pose: learned_steps=%u %s learned_over_20deg=%u\n", pose_check.steps(), pose_check.summary().c_str(),
                pose_check.learned_over_20deg());
    std::printf("bus: frames_sent=%" PRIu64 " send_errors=%" PRIu64 " frames_received=%" PRIu64 " malformed=%" PRIu64 "\n",
                bus.frames_sent(), bus.send_errors(), bus.frames_received(), bus.frames_malformed());
    std::fflush(stdout);
}

// The devices in real time until stopped (a signal, --duration, or --episodes supervised).
void run_devices(const std::string &, const Options &o, DevicesSettings &s)
{
    o.require("--scenario", "paper-sim, paper-lab or a file");
    if (o.seen("--episodes") && !s.supervise) throw UsageError("--episodes: only with --supervise");

    const ScenarioBundle sb = load_scenario(s.scenario);
    if (o.seen("--set")) s.seed = set_seed(s.seed, s.set);
    world::World world(*sb.world, s.seed);
    Devices devices(world, s.seed);
    const std::uint64_t dt_us = static_cast<std::uint64_t>(std::llround(sb.world->timing.physics_dt * 1e6));

    pty_t pty{-1};
    const bool cricket = !sb.world->cricket.beacons.empty();
    if (cricket) {
        char path[64];
        if (pty_open(&pty, path, sizeof path) != FW_OK) throw std::runtime_error("cannot open a pty for the Cricket listener");
        std::printf("cricket_tty=%s\n", path);
    }
    BusLink bus;
    bus.open();
    Supervisor sup(world, sb.robot, bus);
    // Without a supervisor an operator (dynaqpc-operator start) starts the episodes: the robot
    // is put down at a random start, as the supervisor would, not at the arena's centre (which
    // may be in the goal, ending the first episode at its first step).
    if (!s.supervise) world.reset(world.sample_start_pose());
    std::printf("devices: %s, speed %gx, %s, seed=%u; ready\n", sb.name.c_str(), s.speed,
                s.supervise ? "supervising" : "no supervisor", s.seed);
    std::fflush(stdout);

    struct sigaction sa {};
    sa.sa_handler = on_devices_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);

    std::vector<hal_can_frame_t> frames;
    std::string serial;
    std::uint64_t t_us = 0, late_steps = 0, pty_bytes = 0, pty_dropped = 0;
    if (s.wait_firmware && !wait_for_firmware(bus, sup, s)) return;
    const auto wall0 = Clock::now();
    const auto wall_of = [&](std::uint64_t t) {
        return wall0 + std::chrono::nanoseconds(static_cast<std::int64_t>(static_cast<double>(t) * 1000.0 / s.speed));
    };
    bool finished = false;
    PoseCheck pose_check;  // the firmware's heading at its learned steps against the world's, whole run
    auto on_frame = [&](const hal_can_frame_t &f) {
        devices.receive(f, t_us);
        pose_check.on_frame(f, world.pose());
        if (s.supervise && sup.on_frame(f, t_us) && s.episodes != 0 && sup.episodes_done() >= s.episodes) {
            finished = true;
        }
    };
    while (!g_stop.load() && !finished) {
        if (s.duration > 0.0 && std::chrono::duration<double>(Clock::now() - wall0).count() >= s.duration) break;
        if (s.supervise) sup.poll(t_us);
        emit(devices, bus, cricket ? &pty : nullptr, t_us, &frames, &serial, &pty_bytes, &pty_dropped);
        // A device's frame due between two physics steps goes on the bus at its own time.
        for (std::uint64_t at = devices.next_due_us(); at < t_us + dt_us; at = devices.next_due_us()) {
            receive_until(bus, wall_of(at), on_frame);
            emit(devices, bus, cricket ? &pty : nullptr, at, &frames, &serial, &pty_bytes, &pty_dropped);
        }
        const auto due = wall_of(t_us + dt_us);
        if (Clock::now() > due) late_steps++;
        receive_until(bus, due, on_frame);
        world.step();
        t_us += dt_us;
        devices.check_timeouts(t_us);
    }
    const double wall_s = std::chrono::duration<double>(Clock::now() - wall0).count();
    receive_until(bus, Clock::now() + std::chrono::milliseconds(kDrainMs), [&](const hal_can_frame_t &) {});
    if (cricket) pty_close(&pty);
    const RunCounts counts{wall_s, t_us, late_steps, pty_bytes, pty_dropped};
    print_stopped(counts, sup, devices, pose_check, bus);
}

}  // namespace

int cmd_devices(const std::string &program, const std::vector<std::string> &args)
{
    return run_command(program, args, "devices",
                       "the simulated robot's devices in real time on the virtual CAN bus",
                       declare_options, run_devices);
}

}  // namespace dynaqpc
