// SPDX-License-Identifier: MIT
// dynaqpc-sim run: the firmware boots with what it learned (a flash image saved by `train
// --save`) and drives greedily from random starts: frozen (what the image holds, nothing more), or
// with --learn as a robot in service, still learning from every step.
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "commands.h"
#include "lockstep.h"
#include "options.h"
#include "robot/robot_app.h"
#include "scenario_bridge.h"

namespace dynaqpc {

namespace {

struct RunArgs {
    std::string scenario, load, trajectory, arena, agent = "dyna-qpc", changed_arg, model, model_tiles, explore;
    double kappa = 0;
    std::uint32_t starts = 10, seed = 1, step_cap = 0, planning = 0, change_at = 0;
    bool learn = false;
};

void declare_options(Options &o, RunArgs &a)
{
    o.add_string("--scenario", "S", "paper-sim, paper-lab, or a scenario file", &a.scenario);
    o.add_string("--load", "FILE", "the flash image `dynaqpc-sim train --save FILE` wrote", &a.load);
    o.add_choice("--agent", "NAME", "the algorithm that learned it: " + agent_kind_list() + " (default dyna-qpc)",
                 &a.agent, agent_kind_names());
    o.add_string("--model", "NAME",
                 "Dyna-QPC's model it learned with: relocatable or paper (default: the scenario's)", &a.model);
    o.add_string("--model-tiles", "X,Y,H,C", "with --model paper: the tile widths it learned with (default: the scenario's)",
                 &a.model_tiles);
    o.add_uint("--starts", "K", "random start poses, one episode each (default 10)", &a.starts, 1, 1000000);
    o.add_uint("--seed", "S", "seed of the start poses and sensor noise (default 1)", &a.seed, 0, UINT32_MAX);
    o.add_uint("--step-cap", "N", "steps before giving up on a start (default: the scenario's)", &a.step_cap, 1,
               100000000);
    o.add_flag("--learn",
               "keep learning while driving, as a robot in service does: greedy actions (epsilon 0), "
               "every real step learned and planned on; the --load file is not changed "
               "(default: frozen, no learning)",
               &a.learn);
    o.add_uint("--planning", "N",
               "with --learn: planning updates after each real step, 0 = as many as the MCU's idle "
               "time allows (default: the scenario's)",
               &a.planning, 0, 1000000);
    o.add_choice("--explore", "MODE",
                 "with --learn: egreedy, plan-bonus or act-bonus (train --explore; default: the scenario's)",
                 &a.explore, explore_mode_names());
    o.add_double("--kappa", "K", "with --learn: the exploration bonus's scale (default: the scenario's)", &a.kappa,
                 0.0, 1000.0);
    declare_change_options(o,
                           "the room changes: from start K on, the obstacles are --changed's (the firmware is not "
                           "told; default: never). To start in the changed room, give it as --scenario",
                           &a.change_at, 1000000, &a.changed_arg);
    o.add_string("--trajectory", "OUT",
                 "CSV of every control period: start,step,time_s,x,y,heading,action,reward,bump,in_goal; each "
                 "row carries the real step it belongs to, that step's action and the reward it earned, so a "
                 "bump's rows name the action that bumped (docs/tools.md)",
                 &a.trajectory);
    o.add_string("--arena", "OUT", "the arena as JSON, for plots (docs/tools.md)", &a.arena);
}

// --arena's JSON, and --trajectory's file with its header (nullptr without one).
std::FILE *open_outputs(const RunArgs &a, const ScenarioBundle &sb)
{
    if (!a.arena.empty()) {
        std::FILE *f = std::fopen(a.arena.c_str(), "w");
        if (f == nullptr) throw UsageError("--arena: cannot open '" + a.arena + "': " + std::strerror(errno));
        std::fputs(arena_json(*sb.world).c_str(), f);
        std::fclose(f);
    }
    std::FILE *traj = nullptr;
    if (!a.trajectory.empty()) {
        traj = open_output("--trajectory", a.trajectory);
        std::fputs("start,step,time_s,x,y,heading,action,reward,bump,in_goal\n", traj);
    }
    return traj;
}

// --trajectory's rows: one per control period, each with the real step it belongs to. The firmware
// reports a step when it ends (TLM_LEARN: its number, its reward, and the action chosen next), so
// the rows of a step are held until then and written with its number, action and reward: the rows
// where the robot touched something (bump 1) name the action that did and what it earned. Rows
// before the first action, and those of an action a safe stop cut short (a step 0 report follows
// it: not learned from), are step 0, reward 0; the first with action -1.
class TrajectoryRows {
public:
    explicit TrajectoryRows(std::FILE *out) : out_(out) {}

    void add(std::uint32_t start, const TrajectoryPoint &p)
    {
        if (start != start_) {
            flush(-1, step_, 0.0);
            start_ = start;
            doing_ = -1;
            step_ = 0;
        }
        held_.push_back(p);
        if (p.action < 0) return;  // no step ended in this period
        if (p.step == 0) {
            flush(doing_, 0, 0.0);  // the first state, or a resumption after a safe stop
        } else {
            flush(doing_, p.step, p.reward);
            step_ = p.step;
        }
        doing_ = p.action;
    }

    // The rows still held at the end of the run (none, when the episode ended on a step).
    void finish() { flush(-1, step_, 0.0); }

private:
    void flush(int action, std::uint32_t step, double reward)
    {
        for (const TrajectoryPoint &p : held_) {
            std::fprintf(out_, "%u,%u,%.3f,%.4f,%.4f,%.4f,%d,%.0f,%d,%d\n", start_, step, p.time_s, p.x, p.y, p.heading,
                         action, reward, p.bump ? 1 : 0, p.in_goal ? 1 : 0);
        }
        held_.clear();
    }

    std::FILE *out_;
    std::vector<TrajectoryPoint> held_;
    std::uint32_t start_ = 0, step_ = 0;
    int doing_ = -1;
};

// The simulated robot booted from --load's flash image, which must hold a record it restores.
std::unique_ptr<Lockstep> boot_from_load(const std::string &program, const RunArgs &a, const ScenarioBundle &sb,
                                         const robot_config_t &cfg)
{
    LockstepOptions lo;
    lo.seed = a.seed;
    lo.flash_file = a.load;
    lo.evaluate = !a.learn;
    lo.flash_read_only = true;
    lo.plan_update_cycles = plan_cycles_of(cfg.agent);  // a scenario with planning 0 plans in idle time
    std::unique_ptr<Lockstep> sim;
    try {
        sim = std::make_unique<Lockstep>(*sb.world, cfg, lo);
    } catch (const std::runtime_error &e) {
        throw UsageError(std::string("--load: ") + e.what());
    }
    if (!sim->restored()) {
        throw UsageError("--load: '" + a.load + "' holds no record this firmware can restore (" + a.agent + " on " +
                         sb.name + ")");
    }
    robot_app_stats_t restored;
    robot_app_get_stats(&restored);
    if (restored.restore_fell_back) {
        // The firmware boots from the older record when the newest is damaged: say so, as
        // dynaqpc-learned does, so that a replay is not mistaken for the latest learning.
        std::fprintf(stderr,
                     "%s run: warning: the newest record in '%s' is damaged or refused; running the older one "
                     "(%u episodes), as the firmware would\n",
                     program.c_str(), a.load.c_str(), restored.restored_episodes);
    }
    return sim;
}

// The replay from --starts random starts, a line each, and what it came to on stderr.
void replay(const std::string &program, const Options &o, RunArgs &a)
{
    o.require("--scenario");
    if (o.seen("--planning") && !a.learn) {
        throw UsageError("--planning: only with --learn (a frozen replay plans nothing)");
    }
    o.require("--load", "a file written by train --save");
    struct stat st;
    if (stat(a.load.c_str(), &st) != 0) {
        throw UsageError("--load: cannot open '" + a.load + "': " + std::strerror(errno));
    }
    const ScenarioBundle sb = load_scenario(a.scenario);
    const ScenarioBundle changed = load_change_options(o, sb, a.changed_arg, a.change_at, a.starts, "start");
    robot_config_t cfg = sb.robot;
    if ((o.seen("--explore") || o.seen("--kappa")) && !a.learn) {
        throw UsageError(std::string(o.seen("--explore") ? "--explore" : "--kappa") +
                         ": only with --learn (a frozen replay acts greedily)");
    }
    apply_overrides(o, {&a.agent, &a.planning, &a.step_cap, nullptr, nullptr, nullptr, &a.model, &a.model_tiles,
                        &a.explore, &a.kappa},
                    &cfg);
    if (a.learn) cfg.params.epsilon = 0.0f;
    std::FILE *traj = open_outputs(a, sb);
    const std::unique_ptr<Lockstep> sim_ptr = boot_from_load(program, a, sb, cfg);
    Lockstep &sim = *sim_ptr;
    std::uint32_t current = 0;
    TrajectoryRows rows(traj);
    if (traj != nullptr) {
        sim.set_trajectory_sink([&](const TrajectoryPoint &p) { rows.add(current, p); });
    }
    std::vector<std::uint32_t> steps;
    std::uint32_t reached = 0;
    std::uint64_t updates = 0;
    std::printf("start,steps,reached_goal,bumps,robot_time_s\n");
    for (current = 1; current <= a.starts; current++) {
        if (changed.world && current == a.change_at) {
            sim.change_layout(*changed.world);
        }
        const EpisodeRow r = sim.run_episode();
        std::printf("%u,%u,%d,%u,%.1f\n", current, r.steps, r.reached_goal ? 1 : 0, r.bumps, r.robot_time_s);
        updates += r.updates;
        if (r.reached_goal) {
            reached++;
            steps.push_back(r.steps);
        }
    }
    if (traj != nullptr) rows.finish();
    if (traj != nullptr && traj != stdout) std::fclose(traj);
    std::sort(steps.begin(), steps.end());
    std::string room = sb.name;
    if (changed.world) room += ", " + changed.name + " from start " + std::to_string(a.change_at);
    std::fprintf(stderr, "%s on %s (%s): reached the goal from %u of %u starts", a.agent.c_str(), room.c_str(),
                 a.learn ? "learning" : "frozen", reached, a.starts);
    if (!steps.empty()) {
        std::fprintf(stderr, "; steps to the goal: median %u, max %u", steps[steps.size() / 2], steps.back());
    }
    if (!a.learn) {
        // A state met for the third time within the last steps took the best action taken least
        // often there (controller.c, leave_loop_()): how often that overruled the greedy one.
        std::fprintf(stderr, "; loops left %u", robot_app_ctrl()->loop_escapes);
    }
    std::fprintf(stderr, "; Q updates %llu\n", static_cast<unsigned long long>(updates));
}

}  // namespace

int cmd_run(const std::string &program, const std::vector<std::string> &args)
{
    return run_command(program, args, "run",
                       "replay a learned policy greedily from random start poses", declare_options,
                       replay);
}

}  // namespace dynaqpc
