// SPDX-License-Identifier: MIT
// dynaqpc-sim: whether a set learned, and whether it stayed learned (learning_record.h).
#include "learning_record.h"

#include <algorithm>
#include <cstdio>

namespace dynaqpc {

SetRecord record_of_set(const std::vector<EpisodeOutcome> &episodes, std::uint32_t threshold)
{
    SetRecord r;
    auto good = [&](const EpisodeOutcome &e) { return e.reached_goal && e.steps <= threshold; };
    // A relapse is judged against twice the threshold: a learned robot that takes a slightly
    // longer way once (a bump, a noisy fix) has not forgotten the way.
    auto relapse = [&](const EpisodeOutcome &e) { return !e.reached_goal || e.steps > 2ull * threshold; };
    std::size_t first = episodes.size();
    for (std::size_t i = 0; i + kLearnedRun <= episodes.size(); i++) {
        if (std::all_of(episodes.begin() + static_cast<long>(i), episodes.begin() + static_cast<long>(i + kLearnedRun), good)) {
            first = i;
            break;
        }
    }
    for (std::size_t i = 0; i < first && i < episodes.size(); i++) r.steps_to_learn += episodes[i].steps;
    if (first == episodes.size()) return r;
    r.learned_episode = static_cast<std::uint32_t>(first + 1);
    std::uint32_t run = 0;
    for (std::size_t i = first + kLearnedRun; i < episodes.size(); i++) {
        r.episodes_after++;
        if (relapse(episodes[i])) {
            r.relapses++;
            r.longest_relapse_run = std::max(r.longest_relapse_run, ++run);
        } else {
            run = 0;
        }
    }
    return r;
}

std::uint32_t default_learned_threshold(const robot_config_t &cfg)
{
    return cfg.pose_source == ROBOT_POSE_CRICKET ? 50u : 500u;
}

const char *default_threshold_source(const robot_config_t &cfg)
{
    return cfg.pose_source == ROBOT_POSE_CRICKET ? "train's default for a robot on Cricket beacons; 500 on GPS"
                                                 : "train's default for a robot on GPS; 50 on Cricket beacons";
}

std::string long_path_warning(long longest, long beyond, long starts, std::uint32_t threshold,
                              const std::string &which, bool fitted)
{
    if (longest <= static_cast<long>(threshold)) return "";
    char line[640];
    std::snprintf(line, sizeof line,
                  "the longest path, %ld actions at best, is longer than the %u steps within which an episode "
                  "counts toward learning (%s): episodes from %ld of the %ld start (place, heading) pairs can "
                  "never count; give train --threshold %ld or more, or %s",
                  longest, threshold, which.c_str(), beyond, starts, longest,
                  fitted ? "a larger cell (encode auto cell M)" : "a coarser grid (fewer encode x/y bits) or encode auto");
    return line;
}

void print_learning_summary(std::FILE *out, const std::vector<SetRecord> &sets, std::uint32_t threshold)
{
    std::vector<std::uint64_t> steps;
    std::uint64_t after = 0, relapses = 0;
    std::uint32_t longest = 0, runs_of_3 = 0;
    for (const SetRecord &r : sets) {
        if (r.learned_episode == 0) continue;
        steps.push_back(r.steps_to_learn);
        after += r.episodes_after;
        relapses += r.relapses;
        longest = std::max(longest, r.longest_relapse_run);
        runs_of_3 += r.longest_relapse_run >= 3;
    }
    std::fprintf(out, "  learned (%u episodes running reach the goal in <= %u steps): %zu of %zu sets", kLearnedRun,
                 threshold, steps.size(), sets.size());
    if (steps.empty()) {
        std::fputs("\n", out);
        return;
    }
    std::sort(steps.begin(), steps.end());
    const std::size_t n = steps.size();
    const double median = n % 2 ? static_cast<double>(steps[n / 2])
                                : 0.5 * static_cast<double>(steps[n / 2 - 1] + steps[n / 2]);
    std::fprintf(out, ", median %.0f real steps before\n", median);
    std::fprintf(out,
                 "  relapses after learning (missed the goal or took > %u steps): %llu of %llu episodes (%.1f %%); "
                 "longest run %u; sets with 3 or more in a row: %u\n",
                 2u * threshold, static_cast<unsigned long long>(relapses), static_cast<unsigned long long>(after),
                 after ? 100.0 * static_cast<double>(relapses) / static_cast<double>(after) : 0.0, longest, runs_of_3);
}

const char *set_record_csv_header()
{
    return "agent,set,learned_episode,steps_to_learn,episodes_after,relapses,longest_relapse_run\n";
}

std::string set_record_csv_row(const std::string &agent, std::uint32_t set, const SetRecord &r)
{
    char line[160];
    std::snprintf(line, sizeof line, "%s,%u,%u,%llu,%u,%u,%u\n", agent.c_str(), set, r.learned_episode,
                  static_cast<unsigned long long>(r.steps_to_learn), r.episodes_after, r.relapses,
                  r.longest_relapse_run);
    return line;
}

}  // namespace dynaqpc
