// SPDX-License-Identifier: MIT
// dynaqpc-sim train: sets of episodes of the firmware learning on the simulated robot.
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>

#include "commands.h"
#include "hal_host/hal_host_config.h"
#include "learning_record.h"
#include "world/grid_fit.h"
#include "world/rooms.h"
#include "lockstep.h"
#include "options.h"
#include "scenario_bridge.h"

namespace dynaqpc {

namespace {

struct TrainSettings {
    std::string scenario;
    std::string agent;
    std::uint32_t sets = 1;
    std::uint32_t first_set = 1;
    std::uint32_t episodes = 0;
    std::uint32_t planning = 0;
    std::uint32_t seed = 1;
    std::uint32_t jobs = 1;
    std::uint32_t step_cap = 0;
    std::uint32_t plan_cycles = 0;
    double epsilon = 0, alpha = 0;
    std::string gamma, ablate, model, model_tiles, explore;
    double kappa = 0;
    std::string csv;
    std::string sets_csv;
    std::uint32_t threshold = 0;
    std::string save;
    std::uint32_t change_at = 0;
    std::string changed;
    const world::Scenario *changed_world = nullptr;  // loaded from `changed`
    bool no_wall_time = false;
    bool quiet = false;
    bool counters = false;
};

// "q 4213, dyna-q 389, ...": each algorithm's own figure (agent_info_t.plan_cycles).
std::string plan_cycles_list()
{
    std::string list;
    for (const std::string &name : agent_kind_names()) {
        list += (list.empty() ? "" : ", ") + name + " " + std::to_string(plan_cycles_of(agent_kind_of(name)));
    }
    return list;
}

// What the sets run: the scenario, the agent and their settings.
void declare(Options &o, TrainSettings &s)
{
    o.add_string("--scenario", "S", "paper-sim, paper-lab, or a scenario file (docs/scenarios.md)",
                 &s.scenario);
    o.add_choice("--agent", "NAME", agent_kind_list(), &s.agent, agent_kind_names());
    o.add_uint("--sets", "N", "independent sets, each learning from scratch (default 1)", &s.sets, 1,
               100000);
    o.add_uint("--first-set", "K",
               "number the sets K..K+N-1 with their seeds, so blocks of sets run apart give the rows "
               "of one run (default 1)",
               &s.first_set, 1, 100000);
    o.add_uint("--episodes", "E", "episodes per set (default: the scenario's)", &s.episodes, 1,
               10000000);
    o.add_uint("--planning", "N",
               "planning updates after each real step (default: the scenario's); 0 = as many as "
               "the MCU's idle time allows, modelled with --plan-cycles",
               &s.planning, 0, 1000000);
    o.add_uint("--plan-cycles", "C",
               "with idle-time planning (--planning 0, the default of the shipped scenarios): MCU "
               "cycles per planning update at 168 MHz (default: the agent's own Cortex-M4 "
               "measurement: " + plan_cycles_list() + "; docs/results/paper-lab.md)",
               &s.plan_cycles, 1, 100000000);
    o.add_uint("--seed", "S", "experiment seed; set k uses a seed mixed from S and k (default 1)",
               &s.seed, 0, UINT32_MAX);
    o.add_uint("--jobs", "J", "sets run in J parallel processes (default 1)", &s.jobs, 1, 256);
    o.add_uint("--step-cap", "N", "steps per episode before it ends (default: the scenario's)",
               &s.step_cap, 1, 100000000);
    o.add_double("--epsilon", "EPS", "exploration probability (default: the scenario's)", &s.epsilon,
                 0.0, 1.0);
    o.add_double("--alpha", "B", "learning rate, the paper's beta (default: the scenario's)",
                 &s.alpha, 0.0, 1.0, true, false);
    o.add_string("--gamma", "G|auto",
                 "discount: a number in [0, 1] (and theta 1e-3: the paper's mode, gamma 0.9), or auto (from the "
                 "room's size: docs/agent.md); default: the scenario's",
                 &s.gamma);
    o.add_choice("--explore", "MODE",
                 "egreedy (epsilon alone), plan-bonus (Dyna-Q+: planning adds kappa sqrt(steps untried) to a "
                 "pair's reward) or act-bonus (acting picks the largest Q + that bonus); default: the scenario's "
                 "(docs/agent.md)",
                 &s.explore, explore_mode_names());
    o.add_double("--kappa", "K", "the exploration bonus's scale, in reward units (default: the scenario's)",
                 &s.kappa, 0.0, 1000.0);
    o.add_string("--ablate", "PARTS",
                 "Dyna-QPC with its departures from the paper switched off, for the ablation: a comma-separated "
                 "list of generalise, majority, new-states, expected, stay, alias (docs/results/ablation.md)",
                 &s.ablate);
    o.add_string("--model", "NAME",
                 "Dyna-QPC's world model: relocatable (ours) or paper (the paper's CMAC-Model and CMAC-R); "
                 "default: the scenario's (relocatable)",
                 &s.model);
    o.add_string("--model-tiles", "X,Y,H,C",
                 "with --model paper: the CMACs' tile widths of x, y, heading and range code as powers of two "
                 "(default: the scenario's, else 0,0,0,1)",
                 &s.model_tiles);
}

// What train writes and keeps, and the room changing mid-run.
void declare_outputs(Options &o, TrainSettings &s)
{
    o.add_string("--csv", "OUT", "write one row per set and episode to OUT ('-': stdout)", &s.csv);
    o.add_string("--sets-csv", "OUT",
                 "write one row per set to OUT: the first learned episode, the real steps before it, the "
                 "relapses after it and their longest run (docs/results/README.md, \"Relapses\")",
                 &s.sets_csv);
    o.add_uint("--threshold", "N",
               "a set has learned at the first of 3 episodes running that reach the goal in at most N steps; "
               "after that an episode that misses it or takes more than 2N is a relapse (default: 50 for the "
               "lab robot, 500 for the sonar robot)",
               &s.threshold, 1, 100000000);
    o.add_string("--save", "FILE",
                 "keep what the first set learned: the firmware's flash image, replaced at the start and saved at "
                 "each episode end "
                 "(dynaqpc-sim run --load FILE replays it)",
                 &s.save);
    declare_change_options(o,
                           "the room changes: from episode K of every set on, the obstacles are --changed's "
                           "(the firmware is not told and keeps learning; default: never)",
                           &s.change_at, 10000000, &s.changed);
    o.add_flag("--no-wall-time", "write wall_s as 0, so one seed gives byte-identical CSVs",
               &s.no_wall_time);
    o.add_flag("--quiet", "no progress bar, no summary and no warnings about a scenario file (rooms --check gives them)",
               &s.quiet);
    o.add_flag("--counters", "print the firmware's counters after each set (table fill, drops, bus)",
               &s.counters);
}

// All of train's options.
void declare_options(Options &o, TrainSettings &s)
{
    declare(o, s);
    declare_outputs(o, s);
}

void write_set_records(const std::string &path, const std::string &agent,
                       const std::map<std::uint32_t, std::vector<EpisodeOutcome>> &outcomes,
                       const std::vector<SetRecord> &records)
{
    std::FILE *f = open_output("--sets-csv", path);
    std::fputs(set_record_csv_header(), f);
    std::size_t i = 0;
    for (const auto &kv : outcomes) std::fputs(set_record_csv_row(agent, kv.first, records[i++]).c_str(), f);
    if (f != stdout && std::fclose(f) != 0) throw std::runtime_error("--sets-csv: cannot write '" + path + "'");
}

std::string csv_row(const std::string &agent, std::uint32_t set, const EpisodeRow &r, bool no_wall)
{
    char buf[256];
    std::snprintf(buf, sizeof buf, "%s,%u,%u,%u,%.0f,%d,%u,%.3f,%" PRIu64 ",%.4f\n", agent.c_str(), set,
                  r.episode, r.steps, r.reward, r.reached_goal ? 1 : 0, r.bumps, r.robot_time_s,
                  r.updates, no_wall ? 0.0 : r.wall_s);
    return buf;
}

// Runs sets first, first + stride, ... and hands each row to `emit`.
// --save names the firmware's flash image: a file of another size is not ours to overwrite, and a
// path that cannot be created is refused before any training, both as user errors.
void check_save_target(const std::string &path)
{
    const std::uint64_t image = static_cast<std::uint64_t>(FW_CFG_HOST_FLASH_SECTOR_SIZE) * FW_CFG_HOST_FLASH_SECTOR_COUNT;
    struct stat st;
    if (stat(path.c_str(), &st) == 0) {
        if (!S_ISREG(st.st_mode) || static_cast<std::uint64_t>(st.st_size) != image) {
            throw UsageError("--save: '" + path + "' is not a flash image of this firmware (" +
                             std::to_string(static_cast<long long>(st.st_size)) + " bytes, an image is " +
                             std::to_string(image) + "): not overwritten");
        }
        return;
    }
    const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
    if (fd < 0) {
        throw UsageError("--save: cannot create '" + path + "': " + std::strerror(errno));
    }
    close(fd);
    (void)std::remove(path.c_str());
}

template <typename Emit>
void run_sets(const ScenarioBundle &sb, const robot_config_t &cfg, const TrainSettings &s,
              std::uint32_t first, std::uint32_t stride, Emit emit)
{
    for (std::uint32_t set = first; set < s.first_set + s.sets; set += stride) {
        LockstepOptions lo;
        lo.seed = set_seed(s.seed, set);
        lo.plan_update_cycles = s.plan_cycles;
        if (set == s.first_set && !s.save.empty()) {
            // A set learns from scratch: the firmware would restore an old image at boot.
            if (std::remove(s.save.c_str()) != 0 && errno != ENOENT) {
                throw UsageError("--save: cannot replace '" + s.save + "': " + std::strerror(errno));
            }
            lo.flash_file = s.save;
        }
        Lockstep sim(*sb.world, cfg, lo);
        for (std::uint32_t e = 1; e <= s.episodes; e++) {
            if (e == s.change_at && s.changed_world != nullptr) {
                sim.change_layout(*s.changed_world);
            }
            EpisodeRow row = sim.run_episode();
            row.episode = e;  // of this set; the firmware's own count is what it has ever run
            emit(set, row);
        }
        if (s.counters) {
            std::fprintf(stderr, "set %u: %s\n", set, sim.counters().c_str());
        }
    }
}

class Progress {
public:
    Progress(std::uint64_t total, bool on) : total_(total), on_(on && isatty(2)) {}
    void tick(std::uint64_t done)
    {
        if (!on_) {
            return;
        }
        const int width = 40;
        const int filled = static_cast<int>(width * done / std::max<std::uint64_t>(1, total_));
        if (filled == last_ && done != total_) {
            return;
        }
        last_ = filled;
        std::fprintf(stderr, "\r[%s%s] %" PRIu64 "/%" PRIu64 " episodes", std::string(filled, '#').c_str(),
                     std::string(width - filled, '.').c_str(), done, total_);
        if (done == total_) {
            std::fputc('\n', stderr);
        }
    }

private:
    std::uint64_t total_;
    bool on_;
    int last_ = -1;
};

// Per episode, sums over sets for the summary; per set, its episodes in order for the learning
// record.
struct TrainTally {
    std::vector<double> steps_sum, time_sum;
    std::map<std::uint32_t, std::vector<EpisodeOutcome>> outcomes;
    std::uint64_t done = 0;
};

// A user's room (a file, not a shipped name) with a code bit no reading changes, with beacons that
// transmit too seldom for a fix, on equal cells
// that its walls cut, fitted at another cell side than the robot's (rule 7), with stops that reach
// no goal stop, with starts behind a slot beside angled or round furniture, with starts farther
// from the goal at best than the learned threshold, or with starts that no passage as wide as the
// robot's diagonal joins to the goal (rooms --check refuses such a room; train runs it, and the
// sets that start there cannot learn).
void warn_room(const std::string &program, const TrainSettings &s, const ScenarioBundle &sb)
{
    if (s.quiet || world::resolve_scenario_path(s.scenario) != s.scenario) return;  // a shipped name
    for (const world::ConstantCodeBit &c : world::constant_code_bits(*sb.world)) {
        std::fprintf(stderr, "%s train: warning: %s:%d: %s\n", program.c_str(), s.scenario.c_str(), c.line,
                     world::constant_code_bit_warning(*sb.world, c).c_str());
    }
    if (const std::string w = beacon_rate_warning(*sb.world); !w.empty()) {
        std::fprintf(stderr, "%s train: warning: %s: %s\n", program.c_str(), s.scenario.c_str(), w.c_str());
    }
    if (const int faces = world::faces_inside_cells(*sb.world)) {
        std::fprintf(stderr,
                     "%s train: warning: %s: %d wall face(s) lie inside state cells of the equal grid; 'encode "
                     "auto' fits the cells to the room (dynaqpc-sim rooms --check says more)\n",
                     program.c_str(), s.scenario.c_str(), faces);
    }
    if (const world::Encoding::WalkRefit &w = sb.world->encoding.walk_refit; w.to > 0.0) {
        std::fprintf(stderr,
                     "%s train: note: %s: cells of about %.3f m, not %.3f m, so that every stop reaches the goal "
                     "(dynaqpc-sim rooms --check says more)\n",
                     program.c_str(), s.scenario.c_str(), w.to, w.from);
    }
    const world::StopWalkReport walk = world::stop_walk(*sb.world);
    if (walk.stranded > 0) {
        std::fprintf(stderr,
                     "%s train: warning: %s: %ld of the %ld stops the robot's steps end at reach no goal stop a "
                     "step and a turn at a time, past stops where it bumps (dynaqpc-sim rooms --check says "
                     "where)\n",
                     program.c_str(), s.scenario.c_str(), walk.stranded, walk.cells);
    }
    if (const world::SlotReport slot = world::tight_slot(*sb.world); world::slot_warns(slot)) {
        std::fprintf(stderr,
                     "%s train: warning: %s: %ld of the %ld start points reach the goal only through a slot "
                     "narrower than %.3f m beside furniture at an angle or round (dynaqpc-sim rooms --check says "
                     "where)\n",
                     program.c_str(), s.scenario.c_str(), slot.behind, slot.starts, slot.limit);
    }
    if (const world::PathReport p = world::longest_path(*sb.world); p.longest >= 0) {
        const std::uint32_t threshold = s.threshold != 0 ? s.threshold : default_learned_threshold(sb.robot);
        const std::string late =
            long_path_warning(p.longest, p.beyond(threshold), p.start_states, threshold,
                              s.threshold != 0 ? "--threshold" : default_threshold_source(sb.robot),
                              sb.world->encoding.fitted);
        if (!late.empty()) {
            std::fprintf(stderr, "%s train: warning: %s: %s\n", program.c_str(), s.scenario.c_str(), late.c_str());
        }
    }
    const world::PassageReport passages = world::check_passages(*sb.world);
    if (!passages.ok) {
        std::fprintf(stderr, "%s train: warning: %s: %s: the robot cannot learn from those starts\n",
                     program.c_str(), s.scenario.c_str(), passages.problem.c_str());
    }
}

// The scenario's robot with the command line's overrides; fills in the scenario's defaults.
robot_config_t configure(const Options &o, TrainSettings &s, const ScenarioBundle &sb)
{
    robot_config_t cfg = sb.robot;
    apply_overrides(o, {&s.agent, &s.planning, &s.step_cap, &s.epsilon, &s.alpha, &s.gamma, &s.model, &s.model_tiles,
                        &s.explore, &s.kappa},
                    &cfg);
    if (o.seen("--ablate")) cfg.params.ablate = ablate_mask(s.ablate);
    // Idle-time planning (planning 0) is the shipped scenarios' default, or --planning 0.
    if (o.seen("--plan-cycles") && cfg.planning != 0) {
        throw UsageError("--plan-cycles: only with idle-time planning (--planning 0, the shipped scenarios' default)");
    }
    if (!o.seen("--episodes")) s.episodes = sb.episodes;
    if (!o.seen("--sets")) s.sets = sb.sets;
    if (cfg.planning == 0 && s.plan_cycles == 0) s.plan_cycles = plan_cycles_of(cfg.agent);
    return cfg;
}

std::FILE *open_csv(const TrainSettings &s)
{
    std::FILE *out = nullptr;
    if (!s.csv.empty()) {
        out = open_output("--csv", s.csv);
        std::fputs("agent,set,episode,steps,reward,reached_goal,bumps,robot_time_s,updates,wall_s\n", out);
    }
    return out;
}

// One process per job, each writing its rows into a pipe; rows are then written in set order, so
// the CSV does not depend on --jobs.
void run_sets_in_jobs(const std::string &program, const ScenarioBundle &sb, const robot_config_t &cfg,
                      const TrainSettings &s, std::uint32_t jobs, std::FILE *out, TrainTally &tally,
                      Progress &progress)
{
    const std::uint64_t total = static_cast<std::uint64_t>(s.sets) * s.episodes;
    std::fflush(nullptr);
    std::vector<pid_t> pids;
    std::vector<int> fds;
    for (std::uint32_t j = 0; j < jobs; j++) {
        int p[2];
        if (pipe(p) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
        const pid_t pid = fork();
        if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
        if (pid == 0) {
            close(p[0]);
            std::FILE *w = fdopen(p[1], "w");
            int status = 0;
            try {
                run_sets(sb, cfg, s, s.first_set + j, jobs, [&](std::uint32_t set, const EpisodeRow &r) {
                    std::fputs(csv_row(s.agent, set, r, s.no_wall_time).c_str(), w);
                    std::fflush(w);
                });
            } catch (const std::exception &e) {
                std::fprintf(stderr, "%s train: set worker: %s\n", program.c_str(), e.what());
                status = kExitFailure;
            }
            std::fclose(w);
            _exit(status);
        }
        close(p[1]);
        pids.push_back(pid);
        fds.push_back(p[0]);
    }
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::pair<EpisodeRow, std::string>> rows;
    for (int fd : fds) {
        std::FILE *r = fdopen(fd, "r");
        char line[512];
        while (std::fgets(line, sizeof line, r) != nullptr) {
            EpisodeRow row;
            unsigned set = 0, ep = 0, steps = 0, bumps = 0;
            int goal = 0;
            char agent[32];
            unsigned long long upd = 0;
            if (std::sscanf(line, "%31[^,],%u,%u,%u,%lf,%d,%u,%lf,%llu,%lf", agent, &set, &ep, &steps,
                            &row.reward, &goal, &bumps, &row.robot_time_s, &upd, &row.wall_s) == 10) {
                row.episode = ep;
                row.steps = steps;
                row.bumps = bumps;
                row.reached_goal = goal != 0;
                row.updates = upd;
                rows[{set, ep}] = {row, line};
                tally.steps_sum[ep] += steps;
                tally.outcomes[set].resize(std::max<std::size_t>(tally.outcomes[set].size(), ep));
                tally.outcomes[set][ep - 1] = {steps, row.reached_goal};
                tally.time_sum[ep] += row.robot_time_s;
                progress.tick(++tally.done);
            }
        }
        std::fclose(r);
    }
    int failed = 0;
    for (pid_t pid : pids) {
        int st = 0;
        waitpid(pid, &st, 0);
        failed += !(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    }
    for (const auto &kv : rows) {
        if (out != nullptr) std::fputs(kv.second.second.c_str(), out);
    }
    if (failed) throw std::runtime_error(std::to_string(failed) + " set worker(s) failed");
    if (rows.size() != total) throw std::runtime_error("missing rows from the set workers");
}

void print_summary(const TrainSettings &s, const ScenarioBundle &sb, const ScenarioBundle &changed,
                   const robot_config_t &cfg, const TrainTally &tally, const std::vector<SetRecord> &records,
                   std::uint32_t threshold)
{
    std::FILE *sum = s.csv == "-" ? stderr : stdout;
    const std::string plan = cfg.planning == 0
                                 ? "planning in idle time (" + std::to_string(s.plan_cycles) + " cycles per update)"
                                 : "planning " + std::to_string(cfg.planning) + " per real step";
    std::fprintf(sum, "%s on %s, %u sets, %s: mean steps per episode\n", s.agent.c_str(), sb.name.c_str(), s.sets,
                 plan.c_str());
    if (s.changed_world != nullptr) {
        std::fprintf(sum, "  the room is %s from episode %u on\n", changed.name.c_str(), s.change_at);
    }
    for (std::uint32_t e = 1; e <= s.episodes; e++) {
        const bool near_change = s.changed_world != nullptr && e + 1 >= s.change_at && e <= s.change_at + 9;
        if (e <= 10 || near_change || e == s.episodes || e % std::max<std::uint32_t>(1, s.episodes / 10) == 0) {
            std::fprintf(sum, "  episode %5u: %9.1f steps, %8.1f s robot time\n", e, tally.steps_sum[e] / s.sets,
                         tally.time_sum[e] / s.sets);
        }
    }
    print_learning_summary(sum, records, threshold);
}

// The sets, one after another or in --jobs processes, then the CSVs and the summary.
void train(const std::string &program, const Options &o, TrainSettings &s)
{
    o.require("--scenario", "paper-sim, paper-lab or a file");
    o.require("--agent", agent_kind_list());
    const ScenarioBundle sb = load_scenario(s.scenario);
    warn_room(program, s, sb);
    const robot_config_t cfg = configure(o, s, sb);
    const ScenarioBundle changed = load_change_options(o, sb, s.changed, s.change_at, s.episodes, "episode");
    s.changed_world = changed.world.get();
    if (!s.save.empty()) {
        check_save_target(s.save);
    }
    std::FILE *out = open_csv(s);
    const std::uint64_t total = static_cast<std::uint64_t>(s.sets) * s.episodes;
    Progress progress(total, !s.quiet);
    TrainTally tally;
    tally.steps_sum.assign(s.episodes + 1, 0.0);
    tally.time_sum.assign(s.episodes + 1, 0.0);
    const std::uint32_t jobs = std::min(s.jobs, s.sets);
    if (jobs <= 1) {
        run_sets(sb, cfg, s, s.first_set, 1, [&](std::uint32_t set, const EpisodeRow &r) {
            tally.outcomes[set].push_back({r.steps, r.reached_goal});
            if (out != nullptr) {
                // A row per episode as it ends: dynaqpc-experiment counts them for its progress bar.
                std::fputs(csv_row(s.agent, set, r, s.no_wall_time).c_str(), out);
                std::fflush(out);
            }
            tally.steps_sum[r.episode] += r.steps;
            tally.time_sum[r.episode] += r.robot_time_s;
            progress.tick(++tally.done);
        });
    } else {
        run_sets_in_jobs(program, sb, cfg, s, jobs, out, tally, progress);
    }
    if (out != nullptr && out != stdout && std::fclose(out) != 0) {
        throw std::runtime_error("--csv: cannot write '" + s.csv + "'");
    }
    const std::uint32_t threshold = s.threshold != 0 ? s.threshold : default_learned_threshold(cfg);
    std::vector<SetRecord> records;
    for (const auto &kv : tally.outcomes) records.push_back(record_of_set(kv.second, threshold));
    if (!s.sets_csv.empty()) write_set_records(s.sets_csv, s.agent, tally.outcomes, records);
    if (!s.quiet) print_summary(s, sb, changed, cfg, tally, records, threshold);
}

}  // namespace

int cmd_train(const std::string &program, const std::vector<std::string> &args)
{
    return run_command(
        program, args, "train",
        "the firmware learns on the simulated robot: sets of episodes, one CSV row each",
        declare_options, train);
}

}  // namespace dynaqpc
