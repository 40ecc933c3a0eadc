// SPDX-License-Identifier: MIT
// Tests of the learning record (host_sim/src/learning_record.h): when a set has learned, which
// later episodes are relapses, and their longest run.
#include <cstring>
#include <string>
#include <vector>

// cmocka 1.1.5's header has no extern "C" of its own.
extern "C" {
#include "test_common.h"
}
#include "learning_record.h"

namespace {

using dynaqpc::EpisodeOutcome;
using dynaqpc::record_of_set;
using dynaqpc::SetRecord;

EpisodeOutcome ok(unsigned steps) { return {steps, true}; }
EpisodeOutcome miss(unsigned steps) { return {steps, false}; }

void never_learned(void **state)
{
    (void)state;
    // Two good episodes, a miss, two good: never three running.
    const SetRecord r = record_of_set({ok(10), ok(20), miss(200), ok(30), ok(40)}, 50);
    assert_int_equal(r.learned_episode, 0);
    assert_int_equal(r.steps_to_learn, 300);
    assert_int_equal(r.episodes_after, 0);
    assert_int_equal(r.relapses, 0);
}

void learned_then_relapses(void **state)
{
    (void)state;
    // Learned at episode 2 (episodes 2-4 reach the goal in <= 50 steps); after those three: a
    // slower but good episode (90 <= 2 x 50), a miss, one over 100 steps, a good one, a miss.
    const SetRecord r = record_of_set({miss(200), ok(50), ok(12), ok(30), ok(90), miss(200), ok(101), ok(20),
                                       miss(200)},
                                      50);
    assert_int_equal(r.learned_episode, 2);
    assert_int_equal(r.steps_to_learn, 200);
    assert_int_equal(r.episodes_after, 5);
    assert_int_equal(r.relapses, 3);
    assert_int_equal(r.longest_relapse_run, 2);
}

void threshold_is_inclusive_and_goal_needed(void **state)
{
    (void)state;
    // A 40-step episode that missed the goal does not count towards learning.
    assert_int_equal(record_of_set({miss(40), ok(50), ok(50), ok(50)}, 50).learned_episode, 2);
    assert_int_equal(record_of_set({ok(51), ok(50), ok(50), ok(50)}, 50).learned_episode, 2);
}

void default_thresholds(void **state)
{
    (void)state;
    robot_config_t c{};
    c.pose_source = ROBOT_POSE_CRICKET;
    assert_int_equal(dynaqpc::default_learned_threshold(c), 50);
    c.pose_source = ROBOT_POSE_GPS;
    assert_int_equal(dynaqpc::default_learned_threshold(c), 500);
}

// A room whose farthest start needs more actions at best than the threshold: episodes from there
// can never count toward learning, and the warning says how many starts and what to change.
void long_path_warns_over_threshold(void **state)
{
    (void)state;
    assert_string_equal(dynaqpc::long_path_warning(50, 0, 100, 50, "x", false).c_str(), "");
    const std::string w = dynaqpc::long_path_warning(56, 80, 3068, 50, "--threshold", false);
    assert_string_equal(w.c_str(), "the longest path, 56 actions at best, is longer than the 50 steps within which an "
                                   "episode counts toward learning (--threshold): episodes from 80 of the 3068 start "
                                   "(place, heading) pairs can never count; give train --threshold 56 or more, or a "
                                   "coarser grid (fewer encode x/y bits) or encode auto");
    assert_non_null(std::strstr(dynaqpc::long_path_warning(51, 1, 9, 50, "x", true).c_str(), "encode auto cell M"));
    robot_config_t c{};
    c.pose_source = ROBOT_POSE_CRICKET;
    assert_non_null(std::strstr(dynaqpc::default_threshold_source(c), "Cricket beacons; 500 on GPS"));
}

}  // namespace

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(never_learned),
        cmocka_unit_test(learned_then_relapses),
        cmocka_unit_test(threshold_is_inclusive_and_goal_needed),
        cmocka_unit_test(default_thresholds),
        cmocka_unit_test(long_path_warns_over_threshold),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
