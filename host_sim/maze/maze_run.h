// SPDX-License-Identifier: MIT
// dynaqpc: gridworld experiments: runs of episodes of one agent on one maze, rows by callback.
#ifndef MAZE_MAZE_RUN_H
#define MAZE_MAZE_RUN_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/agent.h"
#include "maze/maze.h"

#ifdef __cplusplus
extern "C" {
#endif

/// One finished episode (episodes mode).
typedef struct maze_episode_row {
    uint32_t run;      ///< from 1
    uint32_t episode;  ///< from 1
    uint32_t steps;    ///< real steps taken
    uint64_t updates;  ///< Q updates during the episode, real and planning (agent_updates())
    double wall_s;     ///< seconds by the clock callback, 0 without one
    bool reached_goal; ///< false when the episode hit max_steps
} maze_episode_row_t;

/// One finished run (until-optimal mode).
typedef struct maze_run_row {
    uint32_t run;         ///< from 1
    uint32_t episodes;    ///< episodes played, the one after which the policy was good included
    uint64_t real_steps;  ///< real steps over all those episodes
    uint64_t updates;     ///< Q updates over all those episodes
    double wall_s;        ///< seconds by the clock callback, 0 without one
    bool optimal;         ///< false when the run stopped at max_episodes without getting there
} maze_run_row_t;

typedef struct maze_run_config {
    const maze_t *maze;
    agent_kind_t kind;
    agent_params_t params;            ///< agent_default_params() is Sutton & Barto's
    const agent_storage_t *storage;   ///< e.g. &agent_storage_maze
    uint32_t runs;                    ///< >= 1
    /// Episodes mode (until_optimal == 0): this many episodes per run, one row each.
    uint32_t episodes;
    /// Until-optimal mode (> 0, at least 1): after each episode, follow agent_greedy() from every
    /// start; a run ends once each reaches a goal within until_optimal x its shortest path, or
    /// after max_episodes (Sutton & Barto's Example 8.4). One row per run.
    double until_optimal;
    uint32_t max_episodes;
    uint32_t planning;     ///< planning updates after each real step (agent_plan(n))
    uint32_t max_steps;    ///< an episode ends after this many steps even without a goal; >= 1
    float step_reward;     ///< reward of a step that does not reach a goal (S&B: 0)
    float goal_reward;     ///< reward of the step that reaches a goal (S&B: +1)
    uint32_t seed;         ///< run k gets maze_run_seed(seed, k)

    /// Rows go here as they are made; either may be NULL. `ctx` is passed through.
    void (*on_episode)(void *ctx, const maze_episode_row_t *row);
    void (*on_run)(void *ctx, const maze_run_row_t *row);
    /// A monotonic clock in seconds for the wall_s figures; NULL gives wall_s 0 (so that rows
    /// of two runs with one seed compare equal).
    double (*clock)(void *ctx);
    void *ctx;
} maze_run_config_t;

/// A config with Sutton & Barto's settings (agent_default_params() but theta 0, step reward 0,
/// goal reward +1), planning 5, one run of 50 episodes, max_steps 100,000, max_episodes 10,000, seed 1,
/// the "maze" profile's storage, and no callbacks. Set `maze` and `kind` before use.
maze_run_config_t maze_run_default_config(void);

/// The seed of run `run` (from 1) of an experiment seeded with `seed`: a splitmix-style mix, so
/// neighbouring seeds and runs give unrelated streams.
uint32_t maze_run_seed(uint32_t seed, uint32_t run);

/// Checks a configuration without running it: counts and settings in range, the maze's states
/// fit the storage's dense Q store (2^(row_bits + col_bits) <= q_states), and agent_init()
/// accepts the agent. Returns 0, or -1 with *why (if not NULL) set to a static one-line reason.
int maze_run_check(const maze_run_config_t *cfg, const char **why);

/// Runs the experiment: for each run, agent_reset() with that run's seed, then episodes of
///   a = agent_act(s); step; agent_observe(s, a, r, s', goal); agent_plan(planning)
/// from a start drawn (uniformly, when there are several) with an episode generator that is
/// seeded from the run's seed and separate from the agent's. Deterministic for a config (the
/// clock aside). The agent lives on this function's stack; its learning lives in cfg->storage
/// (so two experiments on one storage must not run at once). Returns 0, or -1 (with *why) if
/// maze_run_check() fails.
int maze_run(const maze_run_config_t *cfg, const char **why);

/// The until-optimal test on its own: true if, from every start, following agent_greedy()
/// reaches a goal within floor(factor x shortest path) steps. No learning, no randomness.
bool maze_greedy_within(const maze_t *m, const agent_t *agent, double factor);

#ifdef __cplusplus
}
#endif

#endif // MAZE_MAZE_RUN_H
