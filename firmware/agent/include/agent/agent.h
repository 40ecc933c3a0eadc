// SPDX-License-Identifier: MIT
// dynaqpc: the learning agent: Q-learning, table-based Dyna-Q and Dyna-QPC behind one step API.
#ifndef AGENT_AGENT_H
#define AGENT_AGENT_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/alias.h"
#include "agent/algorithms.h"
#include "agent/explore.h"
#include "fw/fw_prng.h"
#include "agent/qstore.h"
#include "agent/region.h"
#include "agent/space.h"

#ifdef __cplusplus
extern "C" {
#endif

#define AGENT_KIND_VALUE_(kind, number, name, label, id, d) kind = (number),
/// The algorithms (algorithms.h), chosen at run time; they share the Q store and the step API so
/// every comparison is like for like.
typedef enum agent_kind { AGENT_ALGORITHMS(AGENT_KIND_VALUE_) } agent_kind_t;
#undef AGENT_KIND_VALUE_

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
    /// Dyna-QPC's departures from the paper switched off, for the ablation (docs/results/ablation.md): a
    /// mask of AGENT_ABLATE_*; 0 (the default) keeps them all.
    uint8_t ablate;
    /// Dyna-QPC's world model: AGENT_MODEL_RELOCATABLE (ours, the default) or AGENT_MODEL_PAPER
    /// (the paper's CMAC-Model and CMAC-R, paper_model.h).
    uint8_t model;
    /// With AGENT_MODEL_PAPER: the CMACs' tile width of each state component as a power of two
    /// (0: exact), up to PAPER_MAX_TILE_SHIFT.
    uint8_t model_tile_shift[FW_CFG_MAX_COMPONENTS];
    /// Dyna-QPC: nonzero when step_reward is the reward of an ordinary step, so that a step
    /// which earns it and changes nothing is known as a stay (model.h); 0 (the default): none is
    uint8_t stays;
    float step_reward;  ///< with `stays`: the reward of an ordinary step
    /// How agent_act() and planning explore: an agent_explore_t (explore.h); 0, epsilon-greedy
    /// alone, is the default. The bonus modes need the storage's tried-pairs table.
    uint8_t explore;
    /// The bonus kappa * sqrt(tau) of a pair untried for tau real steps, in reward units;
    /// [0, AGENT_KAPPA_MAX], used by the bonus modes only.
    float kappa;
    /// Q(s, a) of a state never written: what it reads and where its row starts, finite, within
    /// QSTORE_VALUE_LIMIT. 0 (the paper's, and the default) is optimistic wherever steps cost:
    /// every known state's value falls below it once the goal is more than about
    /// reward_goal / |step reward| steps away, and a robot far from its goal then prefers any
    /// state it does not know to the long way home (docs/agent.md, "What an unknown state is
    /// worth").
    float q_prior;
} agent_params_t;

/// The largest kappa agent_init() takes: a bonus beyond any reward scale the robots use.
#define AGENT_KAPPA_MAX 1000.0f

/// The world models (agent_params_t.model), registered in algorithms.h (AGENT_MODELS_OF): the
/// operations an algorithm runs with each.
#define AGENT_MODEL_RELOCATABLE 0u  ///< "relocatable": model.h (docs/agent.md)
#define AGENT_MODEL_PAPER 1u        ///< "paper": the paper's CMAC-Model and CMAC-R, paper_model.h
#define AGENT_COUNT_MODEL_(kind, model, name, id) +1
/// How many models there are: agent_params_t.model values 0 .. AGENT_MODELS - 1.
#define AGENT_MODELS (0u AGENT_MODELS_OF(AGENT_COUNT_MODEL_))

/// The name of a model as the tools and scenario files spell it ("relocatable", "paper"), or
/// NULL for a number that is none.
const char *agent_model_name(uint8_t model);

/// The model called `name`: FW_OK and *model, or FW_ERR_INVAL for a name that is none.
int agent_model_from_name(const char *name, uint8_t *model);

/// Whether an agent of `kind` runs operations of its own with `model` (a line of AGENT_MODELS_OF).
bool agent_kind_has_model(agent_kind_t kind, uint8_t model);

/// No predictions for untried pairs (the relocatable action model): the planner knows only the
/// pairs the robot tried, and confirms predecessors against them only.
#define AGENT_ABLATE_GENERALISE MODEL_ABLATE_GENERALISE
/// A tried pair's model keeps its last outcome (the paper's CMAC rule), not the majority's.
#define AGENT_ABLATE_MAJORITY MODEL_ABLATE_MAJORITY
/// A state seen for the first time does not queue its predicted pairs and those leading into it.
#define AGENT_ABLATE_NEW_STATES 0x04u
/// A move into a place seen with several range codes backs up the first code's value only.
#define AGENT_ABLATE_EXPECTED 0x08u
/// Dyna-QPC: a step that stays in its cell is an outcome like any other, not a share of its move
/// (model.h, MODEL_ABLATE_STAY).
#define AGENT_ABLATE_STAY MODEL_ABLATE_STAY
/// Every real step learns at alpha, however often its cell's outcomes disagreed (alias.h); by
/// default a cell that aliased k times learns from a real step at alpha / (1 + min(k, 7)).
#define AGENT_ABLATE_ALIAS 0x20u
/// Every AGENT_ABLATE_* bit.
#define AGENT_ABLATE_ALL 0x3Fu

/// The elements of array `a`, for the storage initializers (AGENT_STORAGE_<id>, agent_profiles.h).
#define AGENT_COUNT_OF(a) ((uint32_t)(sizeof(a) / sizeof((a)[0])))

/// Caller-owned static storage for an agent: the Q store every algorithm has, and each
/// algorithm's own part. Each algorithm's header says what memory its part points into
/// (AGENT_MEMORY_<id>) and how (AGENT_STORAGE_<id>); an agent runs one algorithm, so a profile
/// overlays their memories (agent_profiles.h). Parts the chosen algorithm does not use may
/// be left zero (NULL).
#define AGENT_STORAGE_MEMBER_(kind, number, name, label, id, d) agent_##id##_storage_t id;
typedef struct agent_storage {
    void *q;              ///< q_states * FW_CFG_MAX_ACTIONS values of q_value_bytes each
    uint8_t q_value_bytes; ///< 4: float, 2: value16 (qstore.h)
    uint32_t *q_keys;     ///< q_states
    uint32_t q_states;
    /// Or q_states 16-bit keys, q_keys NULL (qstore_init16: a profile whose RAM holds its rows
    /// only so, paper-sim-large; exact for its capacity and state widths, qstore.h).
    uint16_t *q_keys16;
    /// The tried-pairs table of the bonus modes (explore.h), tried_pairs entries each; NULL and 0
    /// where the agent only explores epsilon-greedily. Shared by every algorithm: the same
    /// exploration for each.
    uint32_t *tried_keys;
    uint32_t *tried_at;
    uint32_t tried_pairs;
    AGENT_ALGORITHMS(AGENT_STORAGE_MEMBER_)
} agent_storage_t;
#undef AGENT_STORAGE_MEMBER_

typedef struct agent_config {
    agent_kind_t kind;
    const agent_space_t *space;  ///< must outlive the agent
    agent_params_t params;
    const agent_storage_t *storage;
    uint32_t seed;
} agent_config_t;

/// Counters for telemetry, benchmarks and tests. They only grow, until agent_reset().
typedef struct {
    uint32_t real_steps;        ///< calls to agent_observe()
    uint32_t real_updates;      ///< Q updates from real steps
    uint32_t planning_updates;  ///< Q updates from planning
    uint32_t planning_skipped;  ///< planning calls that found nothing it could trust or do
} agent_stats_t;

struct agent_algorithm;

/// An agent: the settings and Q store every algorithm shares, and the chosen algorithm's own
/// state. Read it through the functions below; only the algorithm files look inside `alg`.
#define AGENT_STATE_MEMBER_(kind, number, name, label, id, d) agent_##id##_t id;
typedef struct agent {
    agent_kind_t kind;
    const struct agent_algorithm *algorithm;  ///< the kind's operations (algorithm.h)
    const agent_space_t *space;
    uint32_t state_bits;  ///< space_state_bits(space): states are below 2^state_bits
    agent_params_t params;
    qstore_t q;
    prng_t rng;
    agent_stats_t stats;
    explore_table_t tried;  ///< when pairs were last tried (bonus modes only; explore.h)
    alias_watch_t alias;    ///< where real outcomes disagreed with the agent's own experience
    union {
        AGENT_ALGORITHMS(AGENT_STATE_MEMBER_)
    } alg;
} agent_t;
#undef AGENT_STATE_MEMBER_

/// The name of an algorithm as the tools and scenario files spell it ("q", "dyna-q",
/// "dyna-qpc"), or NULL for a kind that is not one.
const char *agent_kind_name(agent_kind_t kind);

/// The algorithm called `name`: FW_OK and *kind, or FW_ERR_INVAL for a name that is none.
int agent_kind_from_name(const char *name, agent_kind_t *kind);

/// What the registry (algorithms.h) and an algorithm's own file say of it, for the tools
/// (`dynaqpc-sim agents`).
typedef struct agent_info {
    const char *name;   ///< as the tools and scenario files spell it ("dyna-q")
    const char *label;  ///< as tables and plots name it ("Dyna-Q")
    /// MCU cycles one planning update takes: the Cortex-M4 build's guest instructions per update
    /// on the grid-robot bench (paper-lab, N = 5; `ctest --preset cortex-m4 -R
    /// bench.insn_paper_lab`), one cycle each. The simulator charges it in idle time.
    uint32_t plan_cycles;
} agent_info_t;

/// FW_OK and *info for an algorithm, or FW_ERR_INVAL for a kind that is none.
int agent_kind_info(agent_kind_t kind, agent_info_t *info);

/// How many algorithms there are: agent_kind_t values 0 .. AGENT_KINDS - 1.
#define AGENT_COUNT_KIND_(kind, number, name, label, id, d) +1
#define AGENT_KINDS (0 AGENT_ALGORITHMS(AGENT_COUNT_KIND_))

/// alpha 0.1, plan_alpha 1, gamma 0.95, epsilon 0.1, theta 1e-4, model_rate 0.999 (the paper's),
/// 16 tilings,
/// min_count 1; the relocatable model (the paper's model's tiles: component
/// PAPER_DEFAULT_TILED_COMPONENT, the robot's range code, 2 values wide, the others exact); epsilon-greedy exploration (kappa 0).
agent_params_t agent_default_params(void);

/// Checks the configuration and prepares an agent that knows nothing.
/// Returns FW_OK or FW_ERR_INVAL (a bad space, parameter, or missing storage).
int agent_init(agent_t *ag, const agent_config_t *cfg);

/// Forgets everything learned and zeroes the counters; reseeds the generator.
void agent_reset(agent_t *ag, uint32_t seed);

/// Epsilon-greedy action in s: with probability epsilon a uniform random action, otherwise a
/// greedy one with ties broken uniformly at random. With AGENT_EXPLORE_ACT_BONUS "greedy" is
/// over Q(s, a) + kappa * sqrt(tau(s, a)), tau the real steps since (s, a) was last tried.
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

/// One counter of what an agent holds or did, for telemetry, benchmarks and `--counters`.
typedef struct agent_counter {
    const char *name;   ///< e.g. "q_rows", "cmac_evicted"
    uint32_t value;
    uint32_t capacity;  ///< a table's size, or 0 for a plain count
} agent_counter_t;

/// The most counters agent_counters() lists.
#define AGENT_MAX_COUNTERS 19u

/// The kinds of fact agent_walk() hands over; its `what` is a mask of them.
typedef enum agent_fact_kind {
    AGENT_FACT_COUNTER = 1, ///< `counter`: one of agent_counters()' counters
    AGENT_FACT_TABLE = 2,   ///< `table`: how full one of its tables is
    AGENT_FACT_STATE = 4,   ///< `state`: what it knows of one state
    AGENT_FACT_ALIAS = 8,   ///< `alias`: a cell whose real outcomes disagreed (alias.h), most first
} agent_fact_kind_t;
#define AGENT_WALK_ALL 15u

/// How full a table is, for the learned-map view (`dynaqpc-sim learned`'s "fill").
typedef struct agent_table_fill {
    const char *name;  ///< "q", "cmac", "cmac_r", "percepts", "situations", "arrivals", "table"
    const char *unit;  ///< what `used` counts: "rows", "cells", "places", "used", "records"
    uint32_t used;
    uint32_t capacity;
    int8_t dense;      ///< the Q store's: 1 dense (every state has its row; `used` 0), 0 hashed; -1 others
} agent_table_fill_t;

/// What an agent knows of one state.
typedef struct agent_state_facts {
    agent_state_t state;
    bool row;       ///< the Q store holds a row for it (qstore_has_row)
    bool visited;   ///< perceived on a real step (an algorithm with no map of it: has a Q row)
    bool modelled;  ///< the model predicts an action there, tried or generalised
    uint32_t n[FW_CFG_MAX_ACTIONS];  ///< per action: the model's training count (Dyna-Q: 1 if tried)
} agent_state_facts_t;

typedef struct agent_fact {
    agent_fact_kind_t kind;
    union {
        agent_counter_t counter;
        agent_table_fill_t table;
        agent_state_facts_t state;
        alias_cell_t alias;
    } u;
} agent_fact_t;

/// Called by agent_walk() for each fact; a nonzero return stops the walk, which returns it.
typedef int (*agent_visit_t)(void *data, const agent_fact_t *fact);

/// Hands over what the agent knows, one fact at a time, each module walking its own state (the
/// Q store, then the algorithm: its operation `walk`; littlefs's lfs_fs_traverse is the model),
/// so that views, `--counters` and telemetry read no algorithm's insides. `what` is a mask of
/// agent_fact_kind_t. Counters come in agent_counters()' order; tables the Q store's first. A
/// state may come more than once: its facts add up (row, visited and modelled or'd, n per action
/// the largest); states nothing is known of do not come. Describing states asks the model as
/// planning does, which counts its answers (model_untrusted, model_generalised): hence non-const.
/// Returns 0 or the nonzero a visit returned.
int agent_walk(agent_t *ag, uint32_t what, agent_visit_t visit, void *data);

/// Lists the agent's counters (agent_walk()'s AGENT_FACT_COUNTER facts): the Q store's (q_rows
/// of its capacity, q_dropped, q_plan_refused), then the algorithm's own, then in a bonus mode
/// the tried-pairs table's (tried_pairs of its capacity, tried_forgotten), then, for an algorithm
/// with a model of its own experience (algorithm.h's `predict`), the aliasing watch's (alias.h:
/// alias_checked, the real steps whose pair had been tried; alias_steps, those whose outcome
/// disagreed; alias_cells, the cells counted, of FW_CFG_ALIAS_CELLS). Returns how many were
/// written to `out`. Counting changes nothing.
uint32_t agent_counters(agent_t *ag, agent_counter_t out[AGENT_MAX_COUNTERS]);

/// The aliasing count of s's cell (alias.h): real steps there whose outcome disagreed with the
/// algorithm's own experience of the same state and action; 0 without such experience.
uint32_t agent_aliasing(const agent_t *ag, agent_state_t s);

/// max_a Q(s, a): the value of s.
float agent_value(const agent_t *ag, agent_state_t s);

/// The step and update counts every algorithm keeps.
static inline const agent_stats_t *agent_stats(const agent_t *ag)
{
    return &ag->stats;
}

/// Planning work waiting to be done (Dyna-QPC: pairs in its queue; the others: 0).
uint32_t agent_backlog(const agent_t *ag);

/// Real plus planning Q updates so far.
static inline uint64_t agent_updates(const agent_t *ag)
{
    return (uint64_t)ag->stats.real_updates + ag->stats.planning_updates;
}

#ifdef __cplusplus
}
#endif

#endif // AGENT_AGENT_H
