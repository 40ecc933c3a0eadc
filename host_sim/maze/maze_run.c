// SPDX-License-Identifier: MIT
// dynaqpc: gridworld experiments. Pure C99: no I/O, no allocation; rows leave by callback.
#include "maze/maze_run.h"

#include <math.h>
#include <stddef.h>

#include "robot/agent_profiles.h"
#include "fw/fw_base.h"

// ---- Seeds --------------------------------------------------------------------------------------

// The 32-bit finaliser of MurmurHash3 after a golden-ratio step (as splitmix does): every input
// bit reaches every output bit, so seeds 1, 2, 3 and runs 1, 2, 3 give unrelated streams.
static uint32_t mix32_(uint32_t x)
{
    x += 0x9e3779b9u;
    x ^= x >> 16;
    x *= 0x85ebca6bu;
    x ^= x >> 13;
    x *= 0xc2b2ae35u;
    x ^= x >> 16;
    return x;
}

uint32_t maze_run_seed(uint32_t seed, uint32_t run)
{
    return mix32_(mix32_(seed) + run);
}

// The episode generator (the choice of start) must not share a stream with the agent's, or the
// agents' different uses of randomness would give them different starts for the same seed.
static uint32_t episode_seed_(uint32_t run_seed)
{
    return mix32_(run_seed ^ 0x5851f42du);
}

// ---- Configuration ------------------------------------------------------------------------------

maze_run_config_t maze_run_default_config(void)
{
    maze_run_config_t cfg;
    cfg.maze = NULL;
    cfg.kind = AGENT_DYNA_QPC;
    cfg.params = agent_default_params();
    // Every change is swept. A threshold in value units ends the sweep where gamma^d falls below
    // it: with the goal's reward 1, gamma 0.95 and the agents' 1e-4, at 180 steps from the goal,
    // and on a corridor maze with a 240-step path Dyna-QPC then learned from real steps alone
    // beyond it (241,000 real steps against 62,000 with 0, 5 runs; Dyna-Q 177,000). Sutton &
    // Barto's refined mazes learn the same with either (docs/results/maze.md).
    cfg.params.theta = 0.0f;
    cfg.storage = &agent_storage_maze;
    cfg.runs = 1;
    cfg.episodes = 50;
    cfg.until_optimal = 0.0;
    cfg.max_episodes = 10000;
    cfg.planning = 5;
    cfg.max_steps = 100000;
    cfg.step_reward = 0.0f;
    cfg.goal_reward = 1.0f;
    cfg.seed = 1;
    cfg.on_episode = NULL;
    cfg.on_run = NULL;
    cfg.clock = NULL;
    cfg.ctx = NULL;
    return cfg;
}

static int set_why_(const char **why, const char *reason)
{
    if (why != NULL) {
        *why = reason;
    }
    return -1;
}

// Prepares the agent the config describes on `space` (which must outlive it).
static int init_agent_(const maze_run_config_t *cfg, const agent_space_t *space, agent_t *ag,
                       const char **why)
{
    agent_config_t acfg;
    acfg.kind = cfg->kind;
    acfg.space = space;
    acfg.params = cfg->params;
    acfg.storage = cfg->storage;
    acfg.seed = maze_run_seed(cfg->seed, 1);
    if (agent_init(ag, &acfg) != FW_OK) {
        return set_why_(why, "agent_init() refused the agent (a bad space, parameter, or "
                             "missing storage)");
    }
    return 0;
}

int maze_run_check(const maze_run_config_t *cfg, const char **why)
{
    agent_space_t space;
    agent_t ag;
    uint32_t bits;

    if (cfg == NULL || cfg->maze == NULL) {
        return set_why_(why, "no maze");
    }
    if (cfg->storage == NULL) {
        return set_why_(why, "no agent storage");
    }
    if (agent_kind_name(cfg->kind) == NULL) {
        return set_why_(why, "unknown agent kind");
    }
    if (cfg->runs < 1u) {
        return set_why_(why, "runs must be at least 1");
    }
    if (cfg->until_optimal == 0.0) {
        if (cfg->episodes < 1u) {
            return set_why_(why, "episodes must be at least 1");
        }
    } else {
        if (!(cfg->until_optimal >= 1.0) || !isfinite(cfg->until_optimal)) {
            return set_why_(why, "the until-optimal factor must be finite and at least 1");
        }
        if (cfg->max_episodes < 1u) {
            return set_why_(why, "max_episodes must be at least 1");
        }
    }
    if (cfg->max_steps < 1u) {
        return set_why_(why, "max_steps must be at least 1");
    }
    if (!isfinite(cfg->step_reward) || !isfinite(cfg->goal_reward)) {
        return set_why_(why, "rewards must be finite");
    }
    if (cfg->maze->n_starts < 1u || cfg->maze->n_goals < 1u) {
        return set_why_(why, "the maze needs a start and a goal");
    }

    maze_space(cfg->maze, &space);
    bits = (uint32_t)space.bits[0] + space.bits[1];
    if (bits > 31u || (1u << bits) > cfg->storage->q_states) {
        return set_why_(why, "map too big for the agent profile: 2^(row bits + column bits) "
                             "states exceed its dense Q store");
    }
    return init_agent_(cfg, &space, &ag, why);
}

// ---- Greedy test --------------------------------------------------------------------------------

bool maze_greedy_within(const maze_t *m, const agent_t *agent, double factor)
{
    uint16_t i;
    for (i = 0; i < m->n_starts; i++) {
        maze_pos_t pos = m->starts[i];
        const uint16_t shortest = maze_shortest_from(m, pos);
        // The epsilon keeps 1.15 x 20 from flooring to 22.
        const double budget = floor(factor * (double)shortest + 1e-9);
        double taken = 0.0;
        bool reached = false;

        if (shortest == MAZE_UNREACHABLE) {
            return false;
        }
        while (taken < budget) {
            const uint8_t a = agent_greedy(agent, maze_state(m, pos));
            taken += 1.0;
            if (maze_move(m, pos, a, &pos)) {
                reached = true;
                break;
            }
        }
        if (!reached) {
            return false;
        }
    }
    return true;
}

// ---- Runs ---------------------------------------------------------------------------------------

typedef struct episode_result {
    uint32_t steps;
    uint64_t updates;
    double wall_s;
    bool reached_goal;
} episode_result_t;

static double now_(const maze_run_config_t *cfg)
{
    return cfg->clock != NULL ? cfg->clock(cfg->ctx) : 0.0;
}

static episode_result_t episode_(const maze_run_config_t *cfg, agent_t *ag, prng_t *env)
{
    const maze_t *m = cfg->maze;
    const uint64_t updates0 = agent_updates(ag);
    const double t0 = now_(cfg);
    episode_result_t res;
    maze_pos_t pos;
    agent_state_t s;

    pos = m->starts[m->n_starts > 1u ? prng_below(env, m->n_starts) : 0u];
    s = maze_state(m, pos);
    res.steps = 0;
    res.reached_goal = false;
    while (res.steps < cfg->max_steps) {
        const uint8_t a = agent_act(ag, s);
        maze_pos_t next;
        float r;
        agent_state_t s2;
        const bool goal =
            maze_step(m, pos, a, cfg->step_reward, cfg->goal_reward, &next, &r);
        s2 = maze_state(m, next);
        agent_observe(ag, s, a, r, s2, goal);
        if (cfg->planning > 0u) {
            (void)agent_plan(ag, cfg->planning);
        }
        res.steps++;
        pos = next;
        s = s2;
        if (goal) {
            res.reached_goal = true;
            break;
        }
    }
    res.wall_s = cfg->clock != NULL ? now_(cfg) - t0 : 0.0;
    res.updates = agent_updates(ag) - updates0;
    return res;
}

int maze_run(const maze_run_config_t *cfg, const char **why)
{
    agent_space_t space;
    agent_t ag;
    uint32_t run;

    if (maze_run_check(cfg, why) != 0) {
        return -1;
    }
    maze_space(cfg->maze, &space);
    if (init_agent_(cfg, &space, &ag, why) != 0) {
        return -1;
    }

    for (run = 1; run <= cfg->runs; run++) {
        const uint32_t run_seed = maze_run_seed(cfg->seed, run);
        maze_run_row_t total;
        prng_t env;
        uint32_t ep;

        agent_reset(&ag, run_seed);
        prng_seed(&env, episode_seed_(run_seed));
        total.run = run;
        total.episodes = 0;
        total.real_steps = 0;
        total.updates = 0;
        total.wall_s = 0.0;
        total.optimal = false;

        for (ep = 1;; ep++) {
            const episode_result_t res = episode_(cfg, &ag, &env);
            if (cfg->until_optimal == 0.0) {
                if (cfg->on_episode != NULL) {
                    maze_episode_row_t row;
                    row.run = run;
                    row.episode = ep;
                    row.steps = res.steps;
                    row.updates = res.updates;
                    row.wall_s = res.wall_s;
                    row.reached_goal = res.reached_goal;
                    cfg->on_episode(cfg->ctx, &row);
                }
                if (ep >= cfg->episodes) {
                    break;
                }
            } else {
                total.episodes = ep;
                total.real_steps += res.steps;
                total.updates += res.updates;
                total.wall_s += res.wall_s;
                total.optimal = maze_greedy_within(cfg->maze, &ag, cfg->until_optimal);
                if (total.optimal || ep >= cfg->max_episodes) {
                    if (cfg->on_run != NULL) {
                        cfg->on_run(cfg->ctx, &total);
                    }
                    break;
                }
            }
        }
    }
    return 0;
}
