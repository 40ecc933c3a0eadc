// SPDX-License-Identifier: MIT
// The three agents on Sutton & Barto's Dyna maze (Fig. 8.2), 30 seeds each: what they learn and
// how fast; and Dyna-QPC's sweep on a maze whose start is far from its goal. Deterministic:
// every run is seeded.
#include "test_common.h"

#include <stdio.h>
#include <string.h>

#include "robot/agent_profiles.h"
#include "maze/maze.h"
#include "maze/maze_run.h"

static const char dyna_maze_[] = ".......#G\n"
                                 "..#....#.\n"
                                 "S.#....#.\n"
                                 "..#......\n"
                                 ".....#...\n"
                                 ".........\n";

enum { RUNS = 30, EPISODES = 10 };

static maze_t maze_;
static double mean_steps_[EPISODES];
static uint32_t optimal_runs_;
static uint32_t runs_seen_;

static void on_episode(void *ctx, const maze_episode_row_t *row)
{
    (void)ctx;
    mean_steps_[row->episode - 1] += (double)row->steps / RUNS;
}

static uint32_t corridor_worst_;

static void on_corridor_run(void *ctx, const maze_run_row_t *row)
{
    (void)ctx;
    assert_true(row->optimal);
    if (row->episodes > corridor_worst_) {
        corridor_worst_ = row->episodes;
    }
}

static void on_run(void *ctx, const maze_run_row_t *row)
{
    (void)ctx;
    runs_seen_++;
    optimal_runs_ += row->optimal;
}

static int setup(void **state)
{
    (void)state;
    maze_error_t err;
    return maze_parse(&maze_, dyna_maze_, strlen(dyna_maze_), "dyna-maze", &err);
}

// Mean steps per episode over 30 runs of `kind` with N = 5.
static void learning_curve(agent_kind_t kind)
{
    memset(mean_steps_, 0, sizeof mean_steps_);
    maze_run_config_t cfg = maze_run_default_config();
    cfg.maze = &maze_;
    cfg.kind = kind;
    cfg.runs = RUNS;
    cfg.episodes = EPISODES;
    cfg.planning = 5;
    cfg.seed = 1;
    cfg.on_episode = on_episode;
    const char *why = NULL;
    assert_int_equal(maze_run(&cfg, &why), 0);
}

static double mean_of_episodes_2_to_10(void)
{
    double sum = 0.0;
    for (int e = 1; e < EPISODES; e++) {
        sum += mean_steps_[e];
    }
    return sum / (EPISODES - 1);
}

static void shortest_path_is_14(void **state)
{
    (void)state;
    assert_int_equal(maze_shortest_max(&maze_), 14);
}

// Dyna-QPC with N = 5 on `m`, each run until its greedy path is within `factor` x the shortest.
static maze_run_config_t until_config_(const maze_t *m, uint32_t runs, double factor,
                                       uint32_t max_episodes,
                                       void (*on_run_row)(void *, const maze_run_row_t *))
{
    maze_run_config_t cfg = maze_run_default_config();
    cfg.maze = m;
    cfg.kind = AGENT_DYNA_QPC;
    cfg.runs = runs;
    cfg.until_optimal = factor;
    cfg.max_episodes = max_episodes;
    cfg.planning = 5;
    cfg.seed = 1;
    cfg.on_run = on_run_row;
    return cfg;
}

static uint32_t runs_until(double factor, uint32_t max_episodes)
{
    maze_run_config_t cfg = until_config_(&maze_, RUNS, factor, max_episodes, on_run);
    optimal_runs_ = 0;
    runs_seen_ = 0;
    const char *why = NULL;
    assert_int_equal(maze_run(&cfg, &why), 0);
    assert_int_equal(runs_seen_, RUNS);
    return optimal_runs_;
}

// Dyna-QPC with N = 5 learns the optimal path: in every one of 30 runs the greedy policy is
// within Sutton & Barto's Example 8.4 tolerance (1.2 x the 14 steps) in under 200 episodes, and
// most runs walk exactly the 14 steps. The rest settle on a 16-step path over the top: the lower
// route's cells are reached only by a run of exploratory moves, and epsilon-greedy with Q
// starting at 0 may never make them (Q-learning misses it in about half its runs).
static void dyna_qpc_learns_the_optimal_path(void **state)
{
    (void)state;
    assert_int_equal(runs_until(1.2, 200), RUNS);
    assert_true(runs_until(1.0, 200) >= 2 * RUNS / 3);
}

// Both Dyna agents need fewer steps than Q-learning over episodes 2-10, and Dyna-QPC is down
// to 20 steps per episode by episode 4 (Sutton & Barto's Dyna-Q with N = 5 gets there at 6).
static void dyna_agents_beat_q_learning(void **state)
{
    (void)state;
    learning_curve(AGENT_Q_LEARNING);
    const double q = mean_of_episodes_2_to_10();
    learning_curve(AGENT_DYNA_Q);
    const double dyna_q = mean_of_episodes_2_to_10();
    learning_curve(AGENT_DYNA_QPC);
    const double dyna_qpc = mean_of_episodes_2_to_10();
    print_message("mean steps, episodes 2-10: q %.1f, dyna-q %.1f, dyna-qpc %.1f\n", q, dyna_q,
                  dyna_qpc);
    print_message("dyna-qpc mean steps at episode 4: %.1f\n", mean_steps_[3]);
    assert_true(dyna_q < q);
    assert_true(dyna_qpc < q);
    assert_true(mean_steps_[3] <= 20.0);
}

// A goal 240 steps away (host_sim/maps/corridor_240.txt, `--map corridor-240`: rows of wall with
// a gap at alternate ends). The maze runner's threshold is 0, so the sweep after the first goal reaches the start:
// in every run the greedy path is within 1.2 x by the second episode. With the agents' 1e-4 a
// change falls below it 180 steps from the goal (0.95^180), and the far part is learned from
// real steps alone, over some 85 episodes.
static uint32_t corridor_episodes_(float theta)
{
    static maze_t corridor;
    static char text[MAZE_MAX_FILE_BYTES];
    FILE *f = fopen(DYNAQPC_MAPS_DIR "/corridor_240.txt", "rb");
    assert_non_null(f);
    const size_t n = fread(text, 1, sizeof text, f);
    (void)fclose(f);
    maze_error_t err;
    assert_int_equal(maze_parse(&corridor, text, n, "corridor_240.txt", &err), 0);
    assert_int_equal(maze_shortest_max(&corridor), 240);
    maze_run_config_t cfg = until_config_(&corridor, 5, 1.2, 300, on_corridor_run);
    cfg.max_steps = 1000000;
    cfg.params.theta = theta;
    corridor_worst_ = 0;
    const char *why = NULL;
    assert_int_equal(maze_run(&cfg, &why), 0);
    return corridor_worst_;
}

static void the_sweep_reaches_a_far_start(void **state)
{
    (void)state;
    assert_true(maze_run_default_config().params.theta == 0.0f);
    const uint32_t swept = corridor_episodes_(0.0f);
    const uint32_t cut = corridor_episodes_(1e-4f);
    print_message("corridor, episodes to within 1.2 x (worst of 5 runs): theta 0 %u, 1e-4 %u\n",
                  swept, cut);
    assert_true(swept <= 3u);
    assert_true(cut >= 30u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(shortest_path_is_14),
        cmocka_unit_test(dyna_qpc_learns_the_optimal_path),
        cmocka_unit_test(dyna_agents_beat_q_learning),
        cmocka_unit_test(the_sweep_reaches_a_far_start),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
