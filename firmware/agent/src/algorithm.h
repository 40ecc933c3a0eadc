// SPDX-License-Identifier: MIT
// dynaqpc: private to the agent's sources: what an algorithm file provides (its table of
// operations, as a TinyUSB class driver does) and the shared Q-learning step it builds on.
#ifndef AGENT_ALGORITHM_H
#define AGENT_ALGORITHM_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/agent.h"
#include "inline.h"

/// One learning algorithm. agent.c does what every algorithm does (the Q store, acting, the
/// real step's Q update, the counters of steps and updates) and calls these for the rest. Every
/// operation is given (a trivial one where the algorithm has nothing to do).
/// An outcome of one step, as an algorithm's experience keeps it.
typedef struct agent_outcome {
    agent_state_t next;
    float reward;
    bool terminal;
} agent_outcome_t;

/// Whether a real step's outcome disagrees with a kept one: another next state, another end, or a
/// reward more than 0.5 away (the models' own test: model.c, dyna_q_majority.c).
AGENT_ALWAYS_INLINE bool agent_outcome_differs_(const agent_outcome_t *kept, float r,
                                                agent_state_t s_next, bool terminal)
{
    const float d = kept->reward - r;
    return kept->next != s_next || kept->terminal != terminal || d > 0.5f || d < -0.5f;
}

typedef struct agent_algorithm {
    /// Takes the algorithm's own part of `st` (FW_ERR_INVAL when a part it needs is missing)
    /// and prepares it knowing nothing.
    int (*init)(agent_t *ag, const agent_storage_t *st);
    /// Forgets what it learned (agent_reset()).
    void (*clear)(agent_t *ag);
    /// After a real step's shared Q update (agent_observe()); `priority` is |target - Q(s, a)|
    /// before that update.
    void (*observe)(agent_t *ag, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                    bool terminal, float priority);
    /// Up to n planning updates, stopping when there is nothing to plan on; returns how many
    /// did work (agent_plan()).
    uint32_t (*plan)(agent_t *ag, uint32_t n);
    /// Its regions of learned memory, after the Q store's (agent_learned_regions()).
    uint32_t (*regions)(const agent_t *ag, agent_region_t *out);
    /// Checks its part of a saved image (agent_learned_check()): FW_OK or not.
    int (*check)(const agent_t *ag, const void *const *image, uint32_t state_bits);
    /// Its regions' bytes were restored (agent_learned_restored()).
    void (*restored)(agent_t *ag);
    /// What it knows (agent_walk()), after the Q store's facts: the kinds `what` asks for of its
    /// counters (at most AGENT_MAX_COUNTERS - 5), its tables' fill and the states it knows
    /// something of; 0, or the nonzero a visit returned.
    int (*walk)(agent_t *ag, uint32_t what, agent_visit_t visit, void *data);
    /// What the algorithm's own experience says taking `a` in `s` does (the outcome its model
    /// keeps for a tried pair; never a generalised guess), without changing anything: false when
    /// it has none. Called before the real step is learned, to watch for aliasing (alias.h).
    /// NULL: the algorithm keeps no outcomes (Q-learning).
    bool (*predict)(const agent_t *ag, agent_state_t s, uint8_t a, agent_outcome_t *out);
    /// Planning work waiting (agent_backlog()).
    uint32_t (*backlog)(const agent_t *ag);
    /// MCU cycles one planning update takes (agent_info_t.plan_cycles), as measured.
    uint32_t plan_cycles;
} agent_algorithm_t;

/// The operations every algorithm file defines itself, under these names, for its table:
///     const agent_algorithm_t agent_X_algorithm = {AGENT_OWN_OPERATIONS_, .backlog = ..., ...};
/// (the table adds predict, backlog and plan_cycles). An operation added to agent_algorithm_t
/// that every algorithm defines is added here once.
#define AGENT_OWN_OPERATIONS_                                                                  \
    .init = init_, .clear = clear_, .observe = observe_, .plan = plan_, .regions = regions_, \
    .check = check_, .restored = restored_, .walk = walk_

#define AGENT_DECLARE_ALGORITHM_(kind, number, name, label, id, d) \
    extern const agent_algorithm_t agent_##id##_algorithm;
AGENT_ALGORITHMS(AGENT_DECLARE_ALGORITHM_)
#undef AGENT_DECLARE_ALGORITHM_
#define AGENT_DECLARE_MODEL_(kind, model, name, id) extern const agent_algorithm_t agent_##id##_algorithm;
AGENT_MODELS_OF(AGENT_DECLARE_MODEL_)
#undef AGENT_DECLARE_MODEL_

// ---- The shared Q-learning step (Fig. 1), for the algorithm files ----------------------------

AGENT_ALWAYS_INLINE float agent_abs_(float x)
{
    return x < 0.0f ? -x : x;
}

/// r, plus gamma times the best value of s_next unless the episode ended there.
AGENT_ALWAYS_INLINE float agent_target_(const agent_t *ag, float r, agent_state_t s_next,
                                        bool terminal)
{
    return terminal ? r : r + ag->params.gamma * qstore_max(&ag->q, s_next);
}

/// Q(s, a) += alpha * (target - Q(s, a)). A real step's write may forget another state to make
/// room; a planning write may not (qstore_row_for_plan) and returns false when s has no row.
AGENT_ALWAYS_INLINE bool agent_q_update_(agent_t *ag, agent_state_t s, uint8_t a, float target,
                                         float alpha, bool planning)
{
    const qstore_row_t row =
        planning ? qstore_row_for_plan(&ag->q, s) : qstore_row_for_update(&ag->q, s);
    if (row == QSTORE_NO_ROW) {
        return false;
    }
    (void)qstore_learn(&ag->q, row, a, target, alpha, NULL);
    return true;
}

/// The pair (s, a) as one number: the tried-pairs table's key (below 2^31: states have at most
/// 24 bits and FW_CFG_MAX_ACTIONS is small).
AGENT_ALWAYS_INLINE uint32_t agent_pair_(const agent_t *ag, agent_state_t s, uint8_t a)
{
    return s * ag->space->n_actions + a;
}

/// The exploration bonus kappa * sqrt(tau) of (s, a), tau the real steps since it was last tried
/// (explore.h); 0 outside the bonus modes.
AGENT_ALWAYS_INLINE float agent_bonus_(const agent_t *ag, agent_state_t s, uint8_t a)
{
    if (ag->params.explore == AGENT_EXPLORE_EGREEDY) {
        return 0.0f;
    }
    const uint32_t tau = explore_untried_for(&ag->tried, agent_pair_(ag, s, a), ag->stats.real_steps);
    return explore_bonus(ag->params.kappa, tau);
}

/// Dyna-Q+'s planning bonus of (s, a) with AGENT_EXPLORE_PLAN_BONUS, else 0: kappa * sqrt(tau)
/// for a pair the robot tried, tau real steps ago; 0 for a pair never tried (or forgotten). Places
/// never seen already draw the robot by optimism (docs/agent.md item 12); a bonus of kappa *
/// sqrt(now) on every never-tried pair the model predicts (thousands: every heading and range
/// code of every cell) drew every greedy episode to the frontier and the robot stopped reaching
/// the goal (paper-lab, kappa 0.1: 150 steps an episode against 30).
AGENT_ALWAYS_INLINE float agent_plan_bonus_(const agent_t *ag, agent_state_t s, uint8_t a)
{
    uint32_t tau;
    if (ag->params.explore != AGENT_EXPLORE_PLAN_BONUS ||
        !explore_last_tried(&ag->tried, agent_pair_(ag, s, a), ag->stats.real_steps, &tau)) {
        return 0.0f;
    }
    return explore_bonus(ag->params.kappa, tau);
}

/// Dyna-Q's planning (Fig. 5 (f), dyna_q.c), for the algorithms that replay a transition table:
/// up to n updates, each a random observed state, a random action tried there and the table's
/// outcome; returns how many were made (0 before the first real step).
uint32_t agent_dyna_q_replay_(agent_t *ag, const dynaq_table_t *table, uint32_t n);

/// What a transition table knows (dyna_q.c), for an algorithm's walk: its counters `table`
/// (records of capacity) and `table_evicted`, its fill, and its states: each recorded state
/// visited, with its tried actions (n 1), and each state a tried action led to visited.
int agent_dyna_q_table_walk_(const agent_t *ag, const dynaq_table_t *table, uint32_t what,
                             agent_visit_t visit, void *data);

/// Dyna-Q's `predict` (dyna_q.c): the table's outcome for a tried (s, a). Dyna-Q (majority) keeps
/// its table at the same place (the first member of its state, as Dyna-Q's: a union's structs
/// with a common initial sequence may be read through either, C99 6.5.2.3) and predicts by it.
bool agent_dyna_q_predict_(const agent_t *ag, agent_state_t s, uint8_t a, agent_outcome_t *out);

/// The facts of a walk (agent_walk()), handed to `visit`; each returns what it returned.
int agent_visit_counter_(agent_visit_t visit, void *data, const char *name, uint32_t value,
                         uint32_t capacity);
int agent_visit_table_(agent_visit_t visit, void *data, const char *name, const char *unit,
                       uint32_t used, uint32_t capacity);
int agent_visit_state_(agent_visit_t visit, void *data, const agent_state_facts_t *facts);
/// Returns from the calling walk if `call` (a visit) returned nonzero.
#define AGENT_VISIT_(call)             \
    do {                               \
        const int visit_err_ = (call); \
        if (visit_err_ != 0) {         \
            return visit_err_;         \
        }                              \
    } while (0)

/// The states walk of an algorithm with no map of what was perceived: each state with a Q row
/// was visited (a real step writes its row).
int agent_walk_rows_as_visits_(const agent_t *ag, agent_visit_t visit, void *data);

/// Prioritized sweeping's two steps, whichever model Dyna-QPC plans through (dyna_qpc.c,
/// dyna_qpc_paper.c); inline, as they are the planning update's own work.
/// The update of the popped pair `key`, action a of state s whose Q row is `row`: Q(s, a) moves
/// towards `target` at the planning rate and is counted, and what a rate below 1 left goes back
/// in the queue if it is above theta and another update would change the stored value.
AGENT_ALWAYS_INLINE void agent_sweep_update_(agent_t *ag, qstore_row_t row, uint32_t key,
                                             uint8_t a, float target)
{
    float q_sa;
    (void)qstore_learn(&ag->q, row, a, target, ag->params.plan_alpha, &q_sa);
    ag->stats.planning_updates++;
    // With alpha < 1 one update leaves (1 - alpha) of the error behind; the pair goes back in
    // the queue with what is left, so planning keeps working on it while it is the most urgent.
    const float left = agent_abs_(target - q_sa);
    if (left > ag->params.theta && qstore_moves(&ag->q, q_sa, target, ag->params.plan_alpha)) {
        (void)pq_push(&ag->alg.dyna_qpc.pq, key, left);
    }
}

/// Queues (s, a) by |target - Q(s, a)| if that is above theta and an update would change the
/// stored value (a value16 near its target rounds back to itself: qstore_moves()).
AGENT_ALWAYS_INLINE void agent_sweep_queue_(agent_t *ag, agent_state_t s, uint8_t a, float target)
{
    const float q = qstore_get(&ag->q, s, a);
    const float p = agent_abs_(target - q);
    if (p > ag->params.theta && qstore_moves(&ag->q, q, target, ag->params.plan_alpha)) {
        (void)pq_push(&ag->alg.dyna_qpc.pq, agent_pair_(ag, s, a), p);
    }
}

/// Dyna-QPC's queue, whichever model plans through it (dyna_qpc.c, dyna_qpc_paper.c): its
/// counters `queue` (size of capacity) and `queue_dropped`, for a walk, and its backlog.
int agent_dyna_qpc_queue_counters_(const agent_t *ag, agent_visit_t visit, void *data);
uint32_t agent_dyna_qpc_backlog_(const agent_t *ag);

/// Trivial operations for an algorithm that has nothing to do there.
int agent_init_nothing_(agent_t *ag, const agent_storage_t *st);
void agent_nothing_(agent_t *ag);
uint32_t agent_plan_nothing_(agent_t *ag, uint32_t n);
uint32_t agent_list_nothing_(const agent_t *ag, agent_region_t *out);
int agent_check_nothing_(const agent_t *ag, const void *const *image, uint32_t state_bits);
int agent_walk_nothing_(agent_t *ag, uint32_t what, agent_visit_t visit, void *data);
uint32_t agent_backlog_none_(const agent_t *ag);

#endif // AGENT_ALGORITHM_H
