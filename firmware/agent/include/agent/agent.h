// SPDX-License-Identifier: MIT
// dynaqpc: the learning agent: Q-learning, table-based Dyna-Q and Dyna-QPC behind one step API.
#ifndef AGENT_AGENT_H
#define AGENT_AGENT_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/dynaq_table.h"
#include "agent/model.h"
#include "agent/pqueue.h"
#include "fw/fw_prng.h"
#include "agent/qstore.h"
#include "agent/region.h"
#include "agent/space.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The three algorithms, chosen at run time; they share the Q store and the step API so every
/// comparison is like for like.
typedef enum agent_kind {
    AGENT_Q_LEARNING = 0,  ///< the paper's Fig. 1: no model, no planning
    AGENT_DYNA_Q = 1,      ///< Fig. 5: a table of observed transitions, uniform random replay
    AGENT_DYNA_QPC = 2,    ///< Figs. 3, 7, 10: CMAC-Model, generalisation, prioritized sweeping
} agent_kind_t;

/// Learning settings. agent_default_params() gives Sutton & Barto's gridworld values.
typedef struct agent_params {
    float alpha;       ///< Q learning rate of real steps (the paper's beta), (0, 1]
    /// Q learning rate of planning updates, (0, 1]. The models predict one outcome per pair (the
    /// deterministic world of Figs. 3 and 5), so 1 makes a planning update a full backup.
    float plan_alpha;
    float gamma;       ///< discount, [0, 1]
    float epsilon;     ///< exploration probability of agent_act(), [0, 1]
    float theta;       ///< prioritized sweeping: queue a pair only if its priority exceeds this
    float model_rate;  ///< CMAC learning rate (the gamma of the paper's Fig. 7), (0, 1]
    uint8_t tilings;   ///< CMAC tilings, a power of two up to FW_CFG_MAX_TILINGS
    uint8_t min_count; ///< plan only on predictions whose every cell was trained this often
} agent_params_t;

/// Caller-owned static storage for an agent. Dyna-Q and Dyna-QPC never run in the same agent at
/// once, so a profile may overlay their storage (see agent_profiles.h). Pointers for parts the
/// chosen algorithm does not use may be NULL.
typedef struct agent_storage {
    float *q;             // q_states * FW_CFG_MAX_ACTIONS
    uint32_t *q_keys;     // q_states
    uint32_t q_states;
    model_cmac_storage_t forward;  // weights: cells * (FW_CFG_MAX_COMPONENTS + 2)
    model_reloc_storage_t reloc;   // the relocatable model and the percept map
    pq_item_t *pq_heap;            // pq_capacity
    uint32_t *pq_index_keys;       // PQ_INDEX_SLOTS(pq_capacity)
    uint32_t *pq_index_pos;        // PQ_INDEX_SLOTS(pq_capacity)
    uint32_t pq_capacity;
    dynaq_record_t *table;         // table_states
    uint32_t *table_index_keys;    // DYNAQ_INDEX_SLOTS(table_states)
    uint32_t *table_index_rec;     // DYNAQ_INDEX_SLOTS(table_states)
    uint32_t table_states;
} agent_storage_t;

typedef struct agent_config {
    agent_kind_t kind;
    const agent_space_t *space;  ///< must outlive the agent
    agent_params_t params;
    const agent_storage_t *storage;
    uint32_t seed;
} agent_config_t;

/// Counters for telemetry, benchmarks and tests. They only grow, until agent_reset().
typedef struct agent_stats {
    uint32_t real_steps;        ///< calls to agent_observe()
    uint32_t real_updates;      ///< Q updates from real steps
    uint32_t planning_updates;  ///< Q updates from planning
    uint32_t planning_skipped;  ///< planning calls that found nothing it could trust or do
} agent_stats_t;

typedef struct agent {
    agent_kind_t kind;
    const agent_space_t *space;
    agent_params_t params;
    qstore_t q;
    world_model_t model;  // Dyna-QPC
    pqueue_t pq;          // Dyna-QPC
    dynaq_table_t table;  // Dyna-Q
    prng_t rng;
    agent_stats_t stats;
} agent_t;

/// alpha 0.1, plan_alpha 1, gamma 0.95, epsilon 0.1, theta 1e-4, model_rate 0.999 (the paper's),
/// 16 tilings,
/// min_count 1.
agent_params_t agent_default_params(void);

/// Checks the configuration and prepares an agent that knows nothing.
/// Returns FW_OK or FW_ERR_INVAL (a bad space, parameter, or missing storage).
int agent_init(agent_t *ag, const agent_config_t *cfg);

/// Forgets everything learned and zeroes the counters; reseeds the generator.
void agent_reset(agent_t *ag, uint32_t seed);

/// Epsilon-greedy action in s: with probability epsilon a uniform random action, otherwise a
/// greedy one with ties broken uniformly at random.
uint8_t agent_act(agent_t *ag, agent_state_t s);

/// The greedy action in s with ties broken uniformly at random: how a learned policy is replayed.
uint8_t agent_act_greedy(agent_t *ag, agent_state_t s);

/// The greedy action in s, ties going to the lowest action number. Uses no randomness.
uint8_t agent_greedy(const agent_t *ag, agent_state_t s);

/// One real step: a was taken in s, giving reward r and state s_next (terminal: the episode
/// ended there). Does the Q update, and for the Dyna agents the model update; Dyna-QPC queues
/// (s, a) when its priority exceeds theta.
void agent_observe(agent_t *ag, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                   bool terminal);

/// One planning update: a bounded amount of work (for Dyna-QPC, one queued pair, its model
/// lookup and its predecessors). Returns false when there is nothing to plan on (Q-learning
/// always; Dyna-QPC with an empty queue; Dyna-Q before its first step), so an idle loop can
/// stop early.
bool agent_plan_step(agent_t *ag);

/// Up to n planning updates, stopping early when there is nothing to plan on. Returns how many
/// calls did work.
uint32_t agent_plan(agent_t *ag, uint32_t n);

/// Q(s, a).
float agent_q(const agent_t *ag, agent_state_t s, uint8_t a);

/// The most regions agent_learned_regions() lists.
#define AGENT_MAX_REGIONS 10u

/// Lists, in a fixed order for the agent's kind and storage, the memory that holds what it
/// learned: each module's own regions one after the other, the Q store's (qstore_regions), then
/// the model's (model_regions: CMAC-Model, the percept map, the relocatable model and the changes
/// per action; Dyna-QPC) or the transition table's (dynaq_regions; Dyna-Q). The priority queue is not listed: it is work in progress, not
/// knowledge. Saving these bytes and, into an agent initialised with the same configuration,
/// restoring them and calling agent_learned_restored() gives back the same agent.
/// Returns the number of regions written to `out`.
uint32_t agent_learned_regions(const agent_t *ag, agent_region_t out[AGENT_MAX_REGIONS]);

/// Checks saved bytes before they are restored: image[i] points at the bytes of region i as
/// agent_learned_regions() lists them for this agent (the same sizes: the caller checked the
/// layout). Each module checks its own part of the image (qstore_check, model_check with
/// cmac_check, dynaq_check): what passes cannot make the agent read or write out of bounds or loop for ever, whatever the bytes.
/// Reads only; the agent is not changed. Returns FW_OK or FW_ERR_CORRUPT.
int agent_learned_check(const agent_t *ag, const void *const image[AGENT_MAX_REGIONS]);

/// Call after the regions' bytes were restored (bytes that passed agent_learned_check()): each
/// module recounts its own fill from the restored keys (qstore_restored, model_restored with
/// cmac_restored, dynaq_restored), and the priority queue is emptied. Statistics are not
/// restored.
void agent_learned_restored(agent_t *ag);

/// Real plus planning Q updates so far.
static inline uint64_t agent_updates(const agent_t *ag)
{
    return (uint64_t)ag->stats.real_updates + ag->stats.planning_updates;
}

#ifdef __cplusplus
}
#endif

#endif // AGENT_AGENT_H
