// SPDX-License-Identifier: MIT
// dynaqpc-fw: the robot firmware's host build. The same application the MCU runs
// (robot_app_init, then for (;;) robot_app_step()), on the host port in real-time mode:
//   - time is CLOCK_MONOTONIC x --speed; the main loop sleeps in hal_cpu_wait_until() as the MCU
//     sleeps in WFI;
//   - CAN goes over the virtual CAN bus (host_sim/transport/vcan.h): hal_can_send() through a
//     transport, and a receiver thread standing in for the CAN interrupt hands each received
//     frame to hal_host_can_deliver();
//   - the Cricket listener's serial line is a tty (the simulator's pty, or a USB adapter) opened
//     with hal_host_uart_open_path(); the port's reader thread is the UART interrupt;
//   - flash is a file (--flash), so what was learned survives a restart, as on the robot.
// The robot's configuration comes from the scenario file, as dynaqpc-sim builds it.
//
// It lives in host_sim/ (not firmware/) because it is C++ and reads scenario files through the
// simulator's scenario_bridge; the firmware itself is untouched C99.
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <unistd.h>
#include <sys/prctl.h>

#include <atomic>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "agent_pick.h"
#include "bus_link.h"
#include "dynaqpc_can.h"
#include "hal/hal_can.h"
#include "hal/hal_time.h"
#include "hal/hal_uart.h"
#include "hal_host/hal_host.h"
#include "options.h"
#include "robot/pose_trust.h"
#include "robot/robot_app.h"
#include "scenario_bridge.h"
#include "sched/sched.h"
#include "world/scenario.h"

namespace {

using namespace dynaqpc;

// After the main loop stops sending, the receiver keeps counting frames for this long, so that
// frames still in flight from the other programs are not reported as lost.
constexpr int kDrainMs = 500;

std::atomic<bool> g_stop{false};

extern "C" void on_signal(int)
{
    g_stop.store(true);  // lock-free atomic store: async-signal-safe
}

struct Settings {
    std::string scenario;
    std::string agent = "dyna-qpc";
    double speed = 1.0;
    std::string flash;
    std::string cricket_tty;
    std::uint32_t seed = 1;
    std::uint32_t planning = 0;
    std::uint32_t step_cap = 0;
    bool auto_start = false;
    double duration = 0.0;
};

BusLink g_bus;
std::atomic<bool> g_rx_run{true};

int transport_send(const hal_can_frame_t *frame, void *ctx)
{
    (void)ctx;
    return g_bus.send(*frame);
}

const hal_host_can_transport_t kTransport = {transport_send, nullptr};

// The CAN interrupt: frames from the bus into the firmware. Polls every kRxPollMs so that it
// notices a stop, and wakes the main loop then, so a signal ends a sleep at once.
//
// It also measures its own absence, as the UART's reader does (host_uart.c): more than
// kRxStallGapMs since it last looked at the bus, the process was not running (SIGSTOP, a machine
// that did not schedule it), and what the socket holds arrived while no interrupt could take it.
// That backlog meets bxCAN's three-mailbox FIFO (hal_host_can_stall_begin()): handed over whole it
// was thousands of stale frames at 10x, which filled the scheduler's event queue (events_dropped
// 2,604 over three 1 s stalls) and were read as fresh.
constexpr int kRxPollMs = 20;
constexpr auto kRxStallGap = std::chrono::milliseconds(50);
constexpr int kRxStallMaxFrames = 1 << 20;  // a bound on one backlog's reading

// Reads what the socket holds after a stall, `first` being its first frame. False on an error.
bool take_can_stall_backlog(const hal_can_frame_t &first)
{
    hal_host_can_stall_begin();
    (void)hal_host_can_deliver_stalled(&first);
    hal_can_frame_t f;
    int rc = 1;
    for (int i = 0; i < kRxStallMaxFrames && (rc = g_bus.recv(&f, 0)) == 1; i++) {
        (void)hal_host_can_deliver_stalled(&f);
    }
    hal_host_can_stall_end();
    return rc >= 0;
}

void *rx_thread(void *)
{
    hal_can_frame_t f;
    auto looked = std::chrono::steady_clock::now();
    while (g_rx_run.load()) {
        int rc = g_bus.recv(&f, kRxPollMs);
        const auto now = std::chrono::steady_clock::now();
        const bool stalled = now - looked > kRxStallGap;
        looked = now;
        if (rc == 1 && stalled) {
            rc = take_can_stall_backlog(f) ? 1 : -1;
            looked = std::chrono::steady_clock::now();  // reading the backlog is no absence
        } else if (rc == 1) {
            (void)hal_host_can_deliver(&f);  // filtered ids are not for the firmware
        }
        if (rc < 0) {
            std::fprintf(stderr, "dynaqpc-fw: virtual CAN bus receive failed\n");
            g_stop.store(true);
            hal_host_cpu_wake();
            break;
        }
        if (g_stop.load()) {
            hal_host_cpu_wake();
        }
    }
    return nullptr;
}

// One task's timing on exit, in firmware time (what the robot's control loop lived through: at
// --speed X the simulated world runs X times faster too), then the same lateness in wall time
// (firmware time / X): the PC's wake-up latency, which is what makes a host run late, not the
// firmware. Percentiles are bounds from the scheduler's log2 histogram (within a factor of 2).
void print_task_timing(sched_task_id_t id, const sched_task_stats_t &ts, double speed)
{
    sched_lateness_t l;
    if (sched_get_lateness(robot_app_sched(), id, &l) != 0) return;
    const char *name = l.name != nullptr ? l.name : "task";
    const std::uint32_t p50 = sched_lateness_percentile_us(&l, 500), p90 = sched_lateness_percentile_us(&l, 900),
                        p99 = sched_lateness_percentile_us(&l, 990);
    std::printf("%s: period_us=%u tolerance_us=%u runs=%u misses=%u late=%u skipped=%u overruns=%u "
                "lateness_us p50<=%u p90<=%u p99<=%u max=%u\n",
                name, l.period_us, l.tolerance_us, ts.runs, ts.misses, ts.late, ts.skipped, ts.overruns, p50, p90,
                p99, l.worst_us);
    const auto wall = [speed](std::uint32_t us) { return static_cast<double>(us) / speed; };
    std::printf("%s: wall-clock at %gx (the host's wake-up latency): tolerance_us=%.0f lateness_us p50<=%.0f "
                "p90<=%.0f p99<=%.0f max=%.0f\n",
                name, speed, wall(l.tolerance_us), wall(p50), wall(p90), wall(p99), wall(l.worst_us));
    std::printf("%s: lateness_hist_us", name);
    for (std::uint32_t b = 0; b < FW_CFG_SCHED_LATENESS_BUCKETS; b++) {
        if (l.bucket[b] == 0) continue;
        if (b + 1 == FW_CFG_SCHED_LATENESS_BUCKETS) {
            std::printf(" >%u:%u", sched_lateness_bucket_max_us(b - 1), l.bucket[b]);
        } else {
            std::printf(" <=%u:%u", sched_lateness_bucket_max_us(b), l.bucket[b]);
        }
    }
    std::printf("\n");
}

void declare_options(Options &o, Settings &s)
{
    o.add_string("--scenario", "S", "paper-sim, paper-lab or a scenario file: the robot's configuration",
                 &s.scenario);
    o.add_choice("--agent", "NAME", agent_kind_list() + " (default dyna-qpc)", &s.agent,
                 agent_kind_names());
    o.add_double("--speed", "X", "firmware time runs X times faster than real time (default 1)", &s.speed,
                 0.0, 1000.0, true, false);
    o.add_string("--flash", "FILE", "flash image file: learning restored at boot, saved at episode ends "
                 "(default: RAM only)", &s.flash);
    o.add_string("--cricket-tty", "PATH",
                 "the Cricket listener's serial line (dynaqpc-sim devices prints its pty); required "
                 "when the scenario has beacons", &s.cricket_tty);
    o.add_uint("--seed", "N", "the agent's seed (default 1)", &s.seed, 0, UINT32_MAX);
    o.add_uint("--planning", "N",
               "planning updates after each real step (default: the scenario's); 0 = in idle time "
               "until the next deadline", &s.planning, 0, 1000000);
    o.add_uint("--step-cap", "N", "steps per episode before it ends (default: the scenario's)", &s.step_cap,
               1, 100000000);
    o.add_flag("--auto-start", "start an episode at boot and after each end, without an operator",
               &s.auto_start);
    o.add_double("--duration", "SEC", "stop after SEC seconds of wall time (default: until SIGINT/SIGTERM)",
                 &s.duration, 0.0, 1e9, true, false);
}

// The host port in real time at --speed, its flash (from --flash) and the virtual CAN bus.
void start_host(const Settings &s)
{
    hal_host_reset();
    hal_host_time_set_mode(HAL_HOST_CLOCK_REALTIME);
    if (hal_host_time_set_speed(s.speed) != 0) {
        throw UsageError("--speed: not accepted by the host clock");
    }
    if (hal_host_flash_configure(FW_CFG_HOST_FLASH_SECTOR_SIZE, FW_CFG_HOST_FLASH_SECTOR_COUNT,
                                     FW_CFG_HOST_FLASH_WRITE_ALIGN) != 0) {
        throw std::runtime_error("host flash: cannot configure 4 x 128 KB");
    }
    if (!s.flash.empty() && hal_host_flash_attach_file(s.flash.c_str()) != 0) {
        throw UsageError("--flash: " + s.flash + ": not a flash image of this firmware (size) or unreadable");
    }
    g_bus.open();
    hal_host_can_set_transport(&kTransport);
}

// Whether `path` opens as a terminal (hal_host_uart_open_path()'s test), without keeping it open.
bool is_serial_line(const std::string &path)
{
    const int fd = open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    const bool tty = fd >= 0 && isatty(fd) != 0;
    if (fd >= 0) close(fd);
    return tty;
}

// robot_app_init() with the scenario's agent profile; returns the agent.
agent_t *boot_firmware(const robot_config_t &cfg, const Settings &s)
{
    robot_app_options_t ao = host_app_options(cfg, s.seed);
    ao.auto_start = s.auto_start;
    ao.plan_budget_us = ROBOT_PLAN_BUDGET_US;
    // In real time the host delivers gyro frames late and in bunches (a loaded machine, a stall):
    // integrate over the samples' own 16 ms clock, as the emulated board does. The lock-step
    // simulator (dynaqpc-sim) keeps the receive times, which there are the sample times.
    ao.gyro_period_ms = static_cast<std::uint8_t>(DYNAQPC_CAN_GYRO_RATE_CYCLE_TIME_MS);
    const int err = robot_app_init(&ao);
    if (err != 0) {
        throw std::runtime_error("robot_app_init failed (" + std::to_string(err) + ")");
    }
    if (!s.cricket_tty.empty()) {
        if (hal_host_uart_open_path(s.cricket_tty.c_str()) != 0) {
            throw UsageError("--cricket-tty: cannot open " + s.cricket_tty + " as a serial line");
        }
    }
    return ao.agent;
}

void print_ready(const ScenarioBundle &sb, const robot_config_t &cfg, const Settings &s)
{
    robot_app_stats_t st0;
    robot_app_get_stats(&st0);
    std::printf("dynaqpc-fw: %s, %s, speed %gx, planning %s, restored %s; ready\n", sb.name.c_str(),
                s.agent.c_str(), s.speed,
                cfg.planning == 0 ? "idle time" : std::to_string(cfg.planning).c_str(),
                st0.restore_result == 0 ? ("yes, " + std::to_string(st0.restored_episodes) + " episodes").c_str()
                                        : "no");
    if (st0.records_refused > 0 || st0.restore_fell_back) {
        // Never silent: what the flash held that could not be used, and what the robot does.
        std::printf("dynaqpc-fw: the flash held %u damaged or refused record(s); %s\n", st0.records_refused,
                    st0.restore_result == 0 ? "restored an older good one" : "starting fresh");
    }
    if (st0.records_foreign > 0) {
        // Another scenario's, agent's or build's learning: not restored here, and this firmware's
        // saves go over it (the first into a free slot if there is one). Back the image up to keep it.
        std::printf("dynaqpc-fw: the flash held %u record(s) of another scenario, agent or build: not restored; "
                    "this firmware's saves overwrite them (copy %s first to keep them)\n",
                    st0.records_foreign, s.flash.c_str());
    }
    std::fflush(stdout);
}

// Steps the firmware until SIGINT/SIGTERM or --duration; returns the wall time it ran.
double run_loop(const Settings &s)
{
    // Linux lets a sleeping thread wake up to 50 us late by default (timer slack) to batch
    // wake-ups; at --speed X that is X times as much firmware time, for nothing: ask for 1 ns.
    (void)prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
    const auto wall0 = std::chrono::steady_clock::now();
    bool cricket_lost_reported = false;
    while (!g_stop.load()) {
        robot_app_step();
        if (s.duration > 0.0 &&
            std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count() >= s.duration) {
            break;
        }
        if (!s.cricket_tty.empty() && !cricket_lost_reported && !hal_host_uart_path_alive()) {
            std::fprintf(stderr, "dynaqpc-fw: the Cricket serial line closed (%s)\n", s.cricket_tty.c_str());
            cricket_lost_reported = true;  // the firmware keeps running and reports a lost fix
        }
    }
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
}

// The firmware's counters as it stopped.
struct FinalCounts {
    robot_app_stats_t st;
    sched_stats_t ss;
    cricket_stats_t ck;
    hal_uart_stats_t us;
    std::uint32_t uart_discarded;
    std::uint32_t uart_stall_lost;
    std::uint32_t uart_stalls;
    agent_counter_t q_rows;
};

void collect_final(agent_t *agent, FinalCounts &f)
{
    robot_app_get_stats(&f.st);
    sched_get_stats(robot_app_sched(), &f.ss);
    robot_app_get_cricket_stats(&f.ck);
    hal_uart_get_stats(&f.us);
    f.uart_discarded = hal_host_uart_discarded();
    f.uart_stall_lost = hal_host_uart_stall_lost();
    f.uart_stalls = hal_host_uart_stalls();
    agent_counter_t counters[AGENT_MAX_COUNTERS];
    (void)agent_counters(agent, counters);
    f.q_rows = counters[0];  // agent_counters() lists the Q store's rows first
}

void print_final(const FinalCounts &f, const agent_t *agent, double wall_s, double speed)
{
    const robot_app_stats_t &st = f.st;
    const sched_stats_t &ss = f.ss;
    const cricket_stats_t &ck = f.ck;
    const hal_uart_stats_t &us = f.us;
    hal_can_stats_t cs;
    hal_can_get_stats(&cs);
    std::printf("dynaqpc-fw: stopped after %.1f s wall, %.1f s firmware time\n", wall_s,
                static_cast<double>(hal_time_us()) * 1e-6);
    std::printf("episodes=%u episodes_empty=%u saves=%u save_errors=%u frames_rx=%u frames_bad=%u tx_dropped=%u "
                "control_runs=%u misses=%u skipped=%u worst_lateness_us=%u events_dropped=%u q_rows=%u/%u uart_rx_bytes=%u "
                "uart_overruns=%u uart_discarded=%u uart_stall_lost=%u uart_stalls=%u\n",
                st.episodes, st.episodes_empty, st.saves, st.save_errors, st.frames_rx, st.frames_bad, st.frames_tx_dropped,
                ss.task[0].runs, ss.task[0].misses, ss.task[0].skipped, ss.task[0].worst_lateness_us, static_cast<unsigned>(ss.events_dropped),
                f.q_rows.value, f.q_rows.capacity, us.rx_bytes, us.rx_overruns,
                f.uart_discarded, f.uart_stall_lost, f.uart_stalls);
    // Planning: all of it (after each step, N or the first updates before acting) and the idle
    // loop's share (the scheduler's idle steps).
    {
        const agent_stats_t &as = agent->stats;
        const double steps = as.real_steps != 0 ? static_cast<double>(as.real_steps) : 1.0;
        std::printf("planning: real_steps=%u planning_updates=%u idle_loop_updates=%llu per_real_step=%.1f "
                    "idle_loop_per_real_step=%.1f\n",
                    as.real_steps, as.planning_updates, static_cast<unsigned long long>(ss.idle_steps),
                    as.planning_updates / steps, static_cast<double>(ss.idle_steps) / steps);
    }
    // Faults and how the firmware met them (docs/realtime.md "Faults").
    std::printf("faults: safe_stops=%u status_errors=0x%02x restore=%d records_refused=%u records_foreign=%u "
                "restore_fell_back=%d "
                "tool_refused=%u tool_answers=%u tool_malformed=%u resets=%u restores=%u uart_errors=%u "
                "uart_posts_failed=%u can_tx_dropped=%u can_rx_overruns=%u can_bus_errors=%u can_stall_lost=%u\n",
                st.safe_stops, st.status_errors, static_cast<int>(st.restore_result), st.records_refused,
                st.records_foreign, st.restore_fell_back ? 1 : 0, st.tool_refused, st.tool_answers, st.tool_malformed, st.resets,
                st.restores, us.rx_errors, st.uart_posts_failed, cs.tx_dropped,
                cs.rx_overruns, cs.bus_errors, hal_host_can_stall_lost());
    std::printf("boot: count=%u cut_episode=%u cut_steps=%u\n", st.boot_count, st.boot_cut_episode, st.boot_cut_steps);
    std::printf("trust: losses=%u gyro_gap=%u fix_jump=%u stall=%u legs=%u legs_failed=%u episodes_interrupted=%u\n",
                st.trust_losses, unsigned{st.trust_losses_by[POSE_TRUST_WHY_GYRO_GAP]},
                unsigned{st.trust_losses_by[POSE_TRUST_WHY_FIX_JUMP]}, unsigned{st.trust_losses_by[POSE_TRUST_WHY_STALL]},
                unsigned{st.trust_legs}, unsigned{st.trust_legs_failed}, st.episodes_interrupted);
    std::printf("cricket: lines=%u ranges=%u overlong=%u garbage=%u malformed=%u no_range=%u unknown_beacon=%u "
                "bad_range=%u bad_geometry=%u inconsistent=%u\n",
                ck.lines, ck.ranges, ck.overlong, ck.garbage, ck.malformed, ck.no_range, ck.unknown_beacon,
                ck.bad_range, ck.bad_geometry, ck.inconsistent);
    for (std::uint32_t i = 0; i < ss.task_count; i++) {
        print_task_timing(static_cast<sched_task_id_t>(i), ss.task[i], speed);
    }
    std::printf("bus: frames_sent=%" PRIu64 " send_errors=%" PRIu64 " frames_received=%" PRIu64
                " malformed=%" PRIu64 " can_rx_accepted=%u\n",
                g_bus.frames_sent(), g_bus.send_errors(), g_bus.frames_received(), g_bus.frames_malformed(),
                cs.rx_frames);
}

// The firmware in real time until a signal, then its counters.
void run_firmware(const std::string &, const Options &o, Settings &s)
{
    o.require("--scenario", "paper-sim, paper-lab or a file");
    const ScenarioBundle sb = load_scenario(s.scenario);
    robot_config_t cfg = sb.robot;
    apply_overrides(o, {&s.agent, &s.planning, &s.step_cap, nullptr, nullptr, nullptr}, &cfg);
    if (cfg.pose_source == ROBOT_POSE_CRICKET && s.cricket_tty.empty()) {
        throw UsageError("--cricket-tty: required, " + sb.name + " finds its pose with Cricket beacons");
    }
    // Every argument is checked before the flash is touched: the boot appends to its journal.
    if (!s.cricket_tty.empty() && !is_serial_line(s.cricket_tty)) {
        throw UsageError("--cricket-tty: cannot open " + s.cricket_tty + " as a serial line");
    }
    start_host(s);
    agent_t *agent = boot_firmware(cfg, s);

    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);

    pthread_t rx;
    if (pthread_create(&rx, nullptr, rx_thread, nullptr) != 0) {
        throw std::runtime_error("cannot start the CAN receiver thread");
    }
    print_ready(sb, cfg, s);
    const double wall_s = run_loop(s);
    // The firmware's counters as it stopped: what the drain below receives is never handled, and
    // would count as dropped events (hundreds at 10x).
    FinalCounts final_counts{};
    collect_final(agent, final_counts);
    // Stop sending; keep receiving a little while for frames still in flight, then stop.
    hal_host_can_set_transport(nullptr);
    struct timespec drain = {0, kDrainMs * 1000000L};
    nanosleep(&drain, nullptr);
    g_rx_run.store(false);
    pthread_join(rx, nullptr);
    hal_host_uart_close_path();

    print_final(final_counts, agent, wall_s, s.speed);
    hal_host_flash_detach_file();
    g_bus.close();
}

}  // namespace

int main(int argc, char **argv)
{
    std::vector<std::string> args(argv + (argc > 0 ? 1 : 0), argv + argc);
    try {
        return run_command("dynaqpc-fw", args, "",
                           "the robot firmware on the host, in real time on the virtual CAN bus",
                           declare_options, run_firmware);
    } catch (const UsageError &e) {
        std::cerr << "dynaqpc-fw: " << e.what() << '\n';
        return kExitUsage;
    } catch (const std::exception &e) {
        std::cerr << "dynaqpc-fw: " << e.what() << '\n';
        return kExitFailure;
    }
}
