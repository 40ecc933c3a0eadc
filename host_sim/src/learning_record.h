// SPDX-License-Identifier: MIT
// dynaqpc-sim: whether a set learned, and whether it stayed learned.
//
// A set has *learned* at the first of three episodes running that reach the goal within the
// threshold (50 steps for the lab robot, 500 for the sonar robot). Every episode after those
// three that misses the goal or takes more than twice the threshold is a *relapse*: a robot that
// learned the way and then forgets it has not learned (docs/results/README.md, "Relapses").
#ifndef DYNAQPC_LEARNING_RECORD_H
#define DYNAQPC_LEARNING_RECORD_H

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "robot/robot_config.h"

namespace dynaqpc {

/// Episodes running that must reach the goal within the threshold for a set to count as learned.
constexpr std::uint32_t kLearnedRun = 3;

/// One episode as the record needs it.
struct EpisodeOutcome {
    std::uint32_t steps = 0;
    bool reached_goal = false;
};

/// What one set's episodes say about learning.
struct SetRecord {
    std::uint32_t learned_episode = 0;  ///< first episode of the first run of kLearnedRun; 0: never
    std::uint64_t steps_to_learn = 0;   ///< real steps of the episodes before it (all, if never)
    std::uint32_t episodes_after = 0;   ///< episodes after that run
    std::uint32_t relapses = 0;         ///< of those, the ones that missed or took > 2 x threshold
    std::uint32_t longest_relapse_run = 0;
};

/// The record of one set's episodes, in order, at `threshold` steps.
SetRecord record_of_set(const std::vector<EpisodeOutcome> &episodes, std::uint32_t threshold);

/// The threshold the docs use for a robot: 50 steps for the lab robot (Cricket pose, the paper's
/// 4.3 x 3.2 m room), 500 for the sonar robot (GPS pose, the paper's 8 x 8 m floor).
std::uint32_t default_learned_threshold(const robot_config_t &cfg);

/// When a room's longest path at best (world::longest_path(): `longest` actions; `beyond` of its
/// `starts` (place, heading) pairs need more than `threshold`) is longer than `threshold`, what to
/// tell the user after "warning: ": episodes from those starts can never count toward learning, and
/// what to change; "" otherwise. `which` says where the threshold came from ("--threshold", "the
/// default for a robot on Cricket beacons"); `fitted`: the grid is already `encode auto`'s.
std::string long_path_warning(long longest, long beyond, long starts, std::uint32_t threshold,
                              const std::string &which, bool fitted);

/// Where default_learned_threshold() took its figure from, for a message.
const char *default_threshold_source(const robot_config_t &cfg);

/// Prints the summary of `sets` records: sets learned, median real steps to learn, relapses as a
/// share of the episodes after learning, the longest run and the sets with a run of 3 or more.
void print_learning_summary(std::FILE *out, const std::vector<SetRecord> &sets, std::uint32_t threshold);

/// The per-set CSV header and one row (`train --sets-csv`).
const char *set_record_csv_header();
std::string set_record_csv_row(const std::string &agent, std::uint32_t set, const SetRecord &r);

}  // namespace dynaqpc

#endif  // DYNAQPC_LEARNING_RECORD_H
