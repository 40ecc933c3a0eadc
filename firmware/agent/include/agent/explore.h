// SPDX-License-Identifier: MIT
// dynaqpc: directed exploration: when each state-action pair was last tried, and the bonus
// kappa * sqrt(tau) of a pair untried for tau real steps (Sutton & Barto's Dyna-Q+, 8.3).
#ifndef AGENT_EXPLORE_H
#define AGENT_EXPLORE_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/oa_table.h"
#include "fw/fw_prng.h"

#ifdef __cplusplus
extern "C" {
#endif

/// How the agent explores (agent_params_t.explore).
typedef enum agent_explore {
    /// epsilon-greedy alone (the paper's; the default). The tried-pairs table is not used.
    AGENT_EXPLORE_EGREEDY = 0,
    /// Dyna-Q+: a planning update of (s, a) adds kappa * sqrt(tau(s, a)) to the predicted reward
    /// of a pair the robot tried tau real steps ago, so values lead it back to pairs it has not
    /// tried for long (a door that was shut). Never-tried pairs get no bonus (optimism already
    /// draws the robot to new places). Acting stays epsilon-greedy; real updates get no bonus.
    AGENT_EXPLORE_PLAN_BONUS = 1,
    /// The bonus on acting (Sutton & Barto's Exercise 8.4): agent_act() picks the largest
    /// Q(s, a) + kappa * sqrt(tau(s, a)) (epsilon still applies); values carry no bonus.
    AGENT_EXPLORE_ACT_BONUS = 2,
} agent_explore_t;

/// The number of agent_explore_t values.
#define AGENT_EXPLORE_MODES 3u

/// When pairs were last tried, in a fixed-size open-addressing table (oa_table.h, bounded windows)
/// keyed by the pair s * n_actions + a, in caller-owned static storage. A pair the table does not
/// hold counts as untried since step 0 (tau = now): never tried, or forgotten. A full window
/// forgets the pair tried longest ago, whose tau was the largest anyway (counted in `forgotten`).
typedef struct explore_table {
    oa_table_t index;    ///< capacity slots: the pairs
    uint32_t *tried_at;  ///< capacity: the real step at which the slot's pair was last tried
    uint32_t capacity;
    uint32_t used;       ///< slots holding a pair
    uint32_t forgotten;  ///< pairs forgotten to make room
} explore_table_t;

/// Prepares an empty table over `keys` and `tried_at` (`capacity` entries each, a power of two).
/// Returns FW_OK or FW_ERR_INVAL.
int explore_init(explore_table_t *t, uint32_t *keys, uint32_t *tried_at, uint32_t capacity);

/// Forgets every pair and zeroes the counters.
void explore_clear(explore_table_t *t);

/// Records that `pair` (below 2^31) was tried at real step `now`.
void explore_tried(explore_table_t *t, uint32_t pair, uint32_t now);

/// Real steps since `pair` was last tried, at step `now`: now - when, or `now` for a pair the
/// table does not hold. 0 for a pair recorded at a step after `now` (restored or reset clocks).
uint32_t explore_untried_for(const explore_table_t *t, uint32_t pair, uint32_t now);

/// Whether the table holds `pair` (tried, and not forgotten); if so, *tau = the real steps since
/// (as explore_untried_for()).
bool explore_last_tried(const explore_table_t *t, uint32_t pair, uint32_t now, uint32_t *tau);

/// A pair the table holds, drawn uniformly over its slots from `rng` (the first held slot from
/// a random one on): false if it holds none.
bool explore_sample(const explore_table_t *t, prng_t *rng, uint32_t *pair);

/// kappa * sqrt(tau): the bonus of a pair untried for tau steps.
float explore_bonus(float kappa, uint32_t tau);

#ifdef __cplusplus
}
#endif

#endif // AGENT_EXPLORE_H
