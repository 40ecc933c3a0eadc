// SPDX-License-Identifier: MIT
// dynaqpc-sim maze: runs of episodes of Q-learning, Dyna-Q or Dyna-QPC on a gridworld map.
#include <algorithm>
#include <cerrno>
#include <cstdarg>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "agent/agent.h"
#include "robot/agent_profiles.h"
#include "commands.h"
#include "maze/maze.h"
#include "maze/maze_run.h"
#include "options.h"
#include "scenario_bridge.h"

#ifndef DYNAQPC_MAPS_DIR
#define DYNAQPC_MAPS_DIR "host_sim/maps"
#endif

namespace dynaqpc {

namespace {

namespace fs = std::filesystem;

// ---- Settings -----------------------------------------------------------------------------------

struct MazeSettings {
    std::string map;
    std::uint32_t refine = 1;
    std::string agent;
    std::uint32_t runs = 1;
    std::uint32_t episodes = 0;
    double until_optimal = 0.0;
    std::uint32_t max_episodes = 10000;
    std::uint32_t planning = 5;
    std::uint32_t seed = 1;
    double alpha = 0.0;
    double plan_alpha = 0.0;
    double gamma = 0.0;
    double epsilon = 0.0;
    double theta = 0.0;
    double step_reward = 0.0;
    double goal_reward = 1.0;
    std::uint32_t max_steps = 100000;
    std::string csv;
    bool no_wall_time = false;
};

std::string fmt(const char *format, double x)
{
    char buf[64];
    std::snprintf(buf, sizeof buf, format, x);
    return buf;
}

void declare(Options &o, MazeSettings &s)
{
    const agent_params_t d = maze_run_default_config().params;
    s.alpha = d.alpha;
    s.plan_alpha = d.plan_alpha;
    s.gamma = d.gamma;
    s.epsilon = d.epsilon;
    s.theta = d.theta;

    o.add_string("--map", "FILE",
                 "map file, or a bare name such as dyna-maze for " DYNAQPC_MAPS_DIR "/dyna_maze.txt",
                 &s.map);
    o.add_uint("--refine", "K",
               "the map at K times its resolution: each cell a K x K block, a start or goal "
               "one cell of its block (Sutton & Barto's Example 8.4 mazes; default 1)",
               &s.refine, 1, MAZE_MAX_ROWS);
    o.add_choice("--agent", "NAME", agent_kind_list(), &s.agent, agent_kind_names());
    o.add_uint("--runs", "R", "independent runs (default 1)", &s.runs, 1, 1000000);
    o.add_uint("--episodes", "E", "episodes per run: one CSV row per run and episode", &s.episodes,
               1, 10000000);
    o.add_double("--until-optimal", "F",
                 "instead of --episodes: run until the greedy policy reaches a goal from every "
                 "start within F x its shortest path (F >= 1); one CSV row per run",
                 &s.until_optimal, 1.0, 1000.0);
    o.add_uint("--max-episodes", "M", "with --until-optimal: episodes cap per run (default 10000)",
               &s.max_episodes, 1, 10000000);
    o.add_uint("--planning", "N", "planning updates after each real step (default 5)", &s.planning,
               0, 1000000);
    o.add_uint("--seed", "S", "experiment seed; run k uses a seed mixed from S and k (default 1)",
               &s.seed, 0, UINT32_MAX);
    o.add_double("--alpha", "A", "learning rate, (0, 1] (default " + fmt("%g", s.alpha) + ")",
                 &s.alpha, 0.0, 1.0, true, false);
    o.add_double("--plan-alpha", "A",
                 "learning rate of planning updates, (0, 1] (default " + fmt("%g", s.plan_alpha) +
                     "; Sutton & Barto's reference uses --alpha)",
                 &s.plan_alpha, 0.0, 1.0, true, false);
    o.add_double("--gamma", "G", "discount, [0, 1] (default " + fmt("%g", s.gamma) + ")", &s.gamma,
                 0.0, 1.0);
    o.add_double("--epsilon", "EPS",
                 "exploration probability, [0, 1] (default " + fmt("%g", s.epsilon) + ")",
                 &s.epsilon, 0.0, 1.0);
    o.add_double("--theta", "T",
                 "prioritized sweeping threshold, >= 0 (default " + fmt("%g", s.theta) + ")",
                 &s.theta, 0.0, 1e9);
    o.add_double("--step-reward", "X", "reward of a step that does not reach a goal (default 0)",
                 &s.step_reward, -1e6, 1e6);
    o.add_double("--goal-reward", "Y", "reward of the step that reaches a goal (default 1)",
                 &s.goal_reward, -1e6, 1e6);
    o.add_uint("--max-steps", "M", "steps cap per episode; a capped episode just ends (default "
               "100000)", &s.max_steps, 1, 1000000000);
    o.add_string("--csv", "OUT",
                 "write the rows to OUT ('-': stdout, and the summary goes to stderr)", &s.csv);
    o.add_flag("--no-wall-time", "write wall_s as 0, so one seed gives byte-identical CSVs",
               &s.no_wall_time);
}

void check_combinations(const Options &o)
{
    o.require("--map");
    o.require("--agent", agent_kind_list());
    if (o.seen("--episodes") && o.seen("--until-optimal")) {
        throw UsageError("--until-optimal: cannot be combined with --episodes");
    }
    if (!o.seen("--episodes") && !o.seen("--until-optimal")) {
        throw UsageError("--episodes: required (or --until-optimal)");
    }
    if (o.seen("--max-episodes") && !o.seen("--until-optimal")) {
        throw UsageError("--max-episodes: only with --until-optimal");
    }
}

// ---- The map ------------------------------------------------------------------------------------

// A bare name (no '/', no ".txt") is one of ours: dyna-maze is <maps dir>/dyna_maze.txt.
std::string resolve_map(const std::string &arg)
{
    const std::string ext = ".txt";
    const bool has_ext = arg.size() >= ext.size() &&
                         arg.compare(arg.size() - ext.size(), ext.size(), ext) == 0;
    if (arg.find('/') != std::string::npos || has_ext) {
        return arg;
    }
    std::string name = arg;
    std::replace(name.begin(), name.end(), '-', '_');
    return std::string(DYNAQPC_MAPS_DIR) + "/" + name + ext;
}

// Reads at most one byte more than a map may have: enough for the parser to say "too large",
// whatever the file is (/dev/zero included).
std::string read_map(const std::string &path)
{
    std::unique_ptr<std::FILE, int (*)(std::FILE *)> f(std::fopen(path.c_str(), "rb"), std::fclose);
    if (!f) {
        throw UsageError("--map: cannot open '" + path + "': " + std::strerror(errno));
    }
    std::string text(MAZE_MAX_FILE_BYTES + 1u, '\0');
    const std::size_t n = std::fread(&text[0], 1, text.size(), f.get());
    if (std::ferror(f.get())) {
        throw UsageError("--map: cannot read '" + path + "': " + std::strerror(errno));
    }
    text.resize(n);
    return text;
}

// ---- Rows ---------------------------------------------------------------------------------------

struct Sink {
    std::FILE *csv = nullptr;  // nullptr: no CSV
    bool write_failed = false;
    std::string agent;
    std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
    // Episodes mode: sums over runs, per episode.
    std::vector<double> sum_steps;
    std::vector<double> sum_updates;
    std::uint64_t capped_episodes = 0;
    double wall_total = 0.0;
    // Until-optimal mode: every run's row.
    std::vector<maze_run_row_t> runs;
};

// One CSV line, printf-style (a line fits in 256 characters).
__attribute__((format(printf, 2, 3))) void write_row(Sink &sink, const char *format, ...)
{
    char line[256];
    va_list args;
    va_start(args, format);
    std::vsnprintf(line, sizeof line, format, args);
    va_end(args);
    if (sink.csv != nullptr && std::fputs(line, sink.csv) < 0) {
        sink.write_failed = true;
    }
}

extern "C" {

static double sink_clock(void *ctx)
{
    const Sink *sink = static_cast<const Sink *>(ctx);
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - sink->t0).count();
}

static void sink_episode(void *ctx, const maze_episode_row_t *row)
{
    Sink &sink = *static_cast<Sink *>(ctx);
    write_row(sink, "%s,%" PRIu32 ",%" PRIu32 ",%" PRIu32 ",%" PRIu64 ",%.6f\n", sink.agent.c_str(), row->run,
              row->episode, row->steps, row->updates, row->wall_s);
    const std::size_t i = row->episode - 1u;
    if (sink.sum_steps.size() <= i) {
        sink.sum_steps.resize(i + 1u, 0.0);
        sink.sum_updates.resize(i + 1u, 0.0);
    }
    sink.sum_steps[i] += row->steps;
    sink.sum_updates[i] += static_cast<double>(row->updates);
    sink.capped_episodes += row->reached_goal ? 0u : 1u;
    sink.wall_total += row->wall_s;
}

static void sink_run(void *ctx, const maze_run_row_t *row)
{
    Sink &sink = *static_cast<Sink *>(ctx);
    write_row(sink, "%s,%" PRIu32 ",%" PRIu32 ",%" PRIu64 ",%" PRIu64 ",%.6f\n", sink.agent.c_str(), row->run,
              row->episodes, row->real_steps, row->updates, row->wall_s);
    sink.runs.push_back(*row);
    sink.wall_total += row->wall_s;
}

}  // extern "C"

// ---- Summary ------------------------------------------------------------------------------------

double median(std::vector<double> v)
{
    if (v.empty()) {
        return 0.0;
    }
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2u == 1u ? v[n / 2u] : 0.5 * (v[n / 2u - 1u] + v[n / 2u]);
}

double mean(const std::vector<double> &v)
{
    double s = 0.0;
    for (double x : v) {
        s += x;
    }
    return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

// At most `most` episode numbers: the first ten (where the curves differ), then the rest evenly
// spread, the last always included.
std::vector<std::size_t> sample_episodes(std::size_t n, std::size_t most)
{
    const std::size_t head = std::min<std::size_t>(10, most / 2);
    std::vector<std::size_t> out;
    for (std::size_t e = 1; e <= n && (n <= most || e <= head); e++) {
        out.push_back(e);
    }
    if (n <= most) {
        return out;
    }
    const std::size_t tail = most - head;  // spread over head + 1 .. n
    const double span = static_cast<double>(n - head - 1u);
    for (std::size_t i = 1; i <= tail; i++) {
        const std::size_t e =
            head + 1u +
            static_cast<std::size_t>(std::llround(span * static_cast<double>(i) /
                                                   static_cast<double>(tail)));
        if (out.back() != e) {
            out.push_back(e);
        }
    }
    return out;
}

void print_summary(std::ostream &out, const MazeSettings &s, const std::string &map_path,
                   const maze_t &m, const Sink &sink)
{
    const double shortest = maze_shortest_mean(&m);
    char buf[256];

    out << map_path << (s.refine > 1u ? " refined " + std::to_string(s.refine) + " times" : "")
        << ": " << m.rows << " x " << m.cols << " cells, " << m.n_starts
        << (m.n_starts == 1 ? " start, " : " starts, ") << m.n_goals
        << (m.n_goals == 1 ? " goal" : " goals") << ", shortest path "
        << (m.n_starts == 1 ? fmt("%g", shortest) + " steps\n"
                            : fmt("%.2f", shortest) + " steps (mean over starts)\n");

    if (s.until_optimal == 0.0) {
        out << s.agent << ": " << s.runs << (s.runs == 1 ? " run" : " runs") << " x "
            << s.episodes << " episodes, planning " << s.planning << ", seed " << s.seed << "\n";
        out << "episode  mean_steps  mean_updates\n";
        const double runs = s.runs;
        for (std::size_t e : sample_episodes(sink.sum_steps.size(), 30)) {
            std::snprintf(buf, sizeof buf, "%7zu  %10.2f  %12.1f\n", e,
                          sink.sum_steps[e - 1u] / runs, sink.sum_updates[e - 1u] / runs);
            out << buf;
        }
        const double threshold = 1.5 * shortest;
        std::size_t first = 0;
        for (std::size_t i = 0; i < sink.sum_steps.size(); i++) {
            if (sink.sum_steps[i] / runs <= threshold) {
                first = i + 1u;
                break;
            }
        }
        out << "first episode with mean steps <= " << fmt("%g", threshold)
            << " (1.5 x shortest path): "
            << (first != 0 ? std::to_string(first) : "none in " + std::to_string(s.episodes))
            << "\n";
        if (sink.capped_episodes != 0) {
            out << "episodes cut at --max-steps " << s.max_steps << ": " << sink.capped_episodes
                << "\n";
        }
    } else {
        out << s.agent << ": " << s.runs << (s.runs == 1 ? " run" : " runs")
            << " until the greedy path is within " << fmt("%g", s.until_optimal)
            << " x shortest (cap " << s.max_episodes << " episodes), planning " << s.planning
            << ", seed " << s.seed << "\n";
        std::vector<double> eps, steps, updates;
        std::size_t capped = 0;
        for (const maze_run_row_t &r : sink.runs) {
            eps.push_back(r.episodes);
            steps.push_back(static_cast<double>(r.real_steps));
            updates.push_back(static_cast<double>(r.updates));
            capped += r.optimal ? 0u : 1u;
        }
        std::snprintf(buf, sizeof buf, "%-10s  %12s  %12s\n", "", "mean", "median");
        out << buf;
        const std::pair<const char *, const std::vector<double> *> rows[] = {
            {"episodes", &eps}, {"real_steps", &steps}, {"updates", &updates}};
        for (const auto &r : rows) {
            std::snprintf(buf, sizeof buf, "%-10s  %12.1f  %12.1f\n", r.first, mean(*r.second),
                          median(*r.second));
            out << buf;
        }
        out << "runs that hit --max-episodes without getting there: " << capped << "\n";
    }
    if (!s.no_wall_time) {
        out << "wall time in episodes: " << fmt("%.3f", sink.wall_total) << " s\n";
    }
}

// ---- Output file --------------------------------------------------------------------------------

// The CSV goes to "<OUT>.partial" and is renamed to OUT only when complete, so a failed run
// never leaves a half-written OUT (nor clobbers an old one). Devices and pipes (/dev/null, a
// FIFO) are written directly: renaming over them would be wrong.
class CsvFile {
public:
    explicit CsvFile(const std::string &path) : path_(path)
    {
        if (path == "-") {
            file_ = stdout;
            return;
        }
        std::error_code ec;
        const bool special = fs::exists(path, ec) && !fs::is_regular_file(path, ec);
        tmp_ = special ? path : path + ".partial";
        file_ = std::fopen(tmp_.c_str(), "wb");
        if (file_ == nullptr) {
            throw UsageError("--csv: cannot write '" + tmp_ + "': " + std::strerror(errno));
        }
        if (special) {
            tmp_.clear();
        }
    }
    CsvFile(const CsvFile &) = delete;
    CsvFile &operator=(const CsvFile &) = delete;
    ~CsvFile()
    {
        if (file_ != nullptr && file_ != stdout) {
            std::fclose(file_);
            if (!tmp_.empty()) {
                std::remove(tmp_.c_str());
            }
        }
    }

    std::FILE *get() const { return file_; }

    // Flushes, closes and moves the file into place; throws on any write error.
    void commit()
    {
        const bool flushed = std::fflush(file_) == 0 && !std::ferror(file_);
        if (file_ == stdout) {
            file_ = nullptr;
            if (!flushed) {
                throw std::runtime_error("--csv: error writing to stdout");
            }
            return;
        }
        const bool closed = std::fclose(file_) == 0;
        file_ = nullptr;
        if (!flushed || !closed) {
            if (!tmp_.empty()) {
                std::remove(tmp_.c_str());
            }
            throw std::runtime_error("--csv: error writing '" + path_ + "'");
        }
        if (!tmp_.empty() && std::rename(tmp_.c_str(), path_.c_str()) != 0) {
            const std::string why = std::strerror(errno);
            std::remove(tmp_.c_str());
            throw std::runtime_error("--csv: cannot rename '" + tmp_ + "' to '" + path_ +
                                     "': " + why);
        }
    }

private:
    std::string path_;
    std::string tmp_;  // to remove on failure, or empty
    std::FILE *file_ = nullptr;
};

// The runs' configuration from the options (the sink and clock are set by the caller).
maze_run_config_t run_config(const MazeSettings &s, const maze_t *maze)
{
    maze_run_config_t cfg = maze_run_default_config();
    cfg.maze = maze;
    cfg.kind = agent_kind_of(s.agent);
    cfg.params.alpha = static_cast<float>(s.alpha);
    cfg.params.plan_alpha = static_cast<float>(s.plan_alpha);
    cfg.params.gamma = static_cast<float>(s.gamma);
    cfg.params.epsilon = static_cast<float>(s.epsilon);
    cfg.params.theta = static_cast<float>(s.theta);
    cfg.storage = &agent_storage_maze;
    cfg.runs = s.runs;
    cfg.episodes = s.episodes;
    cfg.until_optimal = s.until_optimal;
    cfg.max_episodes = s.max_episodes;
    cfg.planning = s.planning;
    cfg.max_steps = s.max_steps;
    cfg.step_reward = static_cast<float>(s.step_reward);
    cfg.goal_reward = static_cast<float>(s.goal_reward);
    cfg.seed = s.seed;
    return cfg;
}

// ---- The command --------------------------------------------------------------------------------

// The runs, their CSV rows and the summary.
int run_maze(const std::string &, const Options &opts, MazeSettings &s)
{
    check_combinations(opts);

    // Everything is checked before the CSV is opened.
    const std::string map_path = resolve_map(s.map);
    const std::string text = read_map(map_path);
    // maze_t is ~225 KB: keep it off the stack.
    auto maze = std::make_unique<maze_t>();
    maze_error_t err;
    if (maze_parse(maze.get(), text.data(), text.size(), map_path.c_str(), &err) != 0) {
        std::cerr << err.message << '\n';
        return kExitUsage;
    }
    if (s.refine > 1u) {
        auto base = std::move(maze);
        maze = std::make_unique<maze_t>();
        if (maze_refine(maze.get(), base.get(), s.refine, map_path.c_str(), &err) != 0) {
            std::cerr << "--refine: " << err.message << '\n';
            return kExitUsage;
        }
    }

    maze_run_config_t cfg = run_config(s, maze.get());
    const char *why = nullptr;
    if (maze_run_check(&cfg, &why) != 0) {
        // The only check the options cannot have made already is the map's size against the
        // profile (or agent_init() refusing it): report it against the map.
        std::cerr << map_path << ":1:1: " << why << '\n';
        return kExitUsage;
    }

    Sink sink;
    sink.agent = s.agent;
    if (s.until_optimal == 0.0) {
        sink.sum_steps.reserve(s.episodes);
        sink.sum_updates.reserve(s.episodes);
    }
    std::unique_ptr<CsvFile> csv;
    if (!s.csv.empty()) {
        csv = std::make_unique<CsvFile>(s.csv);
        sink.csv = csv->get();
        write_row(sink, s.until_optimal == 0.0 ? "agent,run,episode,steps,updates,wall_s\n"
                                               : "agent,run,episodes,real_steps,updates,wall_s\n");
    }
    cfg.on_episode = sink_episode;
    cfg.on_run = sink_run;
    cfg.clock = s.no_wall_time ? nullptr : sink_clock;
    cfg.ctx = &sink;

    if (maze_run(&cfg, &why) != 0) {
        throw std::runtime_error(std::string("maze run failed: ") + why);
    }
    if (sink.write_failed) {
        throw std::runtime_error("--csv: error writing '" + s.csv + "'");
    }
    if (csv) {
        csv->commit();
    }
    print_summary(s.csv == "-" ? std::cerr : std::cout, s, map_path, *maze, sink);
    return kExitOk;
}

}  // namespace

int cmd_maze(const std::string &program, const std::vector<std::string> &args)
{
    return run_command(
        program, args, "maze",
        "Runs of episodes of one agent on a gridworld map (Sutton & Barto's Dyna maze\n"
        "protocol). CSV columns: agent,run,episode,steps,updates,wall_s; with\n"
        "--until-optimal: agent,run,episodes,real_steps,updates,wall_s. A learning-curve\n"
        "summary follows on stdout.",
        declare, run_maze);
}

}  // namespace dynaqpc
