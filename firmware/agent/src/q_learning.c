// SPDX-License-Identifier: MIT
// dynaqpc: Q-learning (the paper's Fig. 1): the real step's Q update, which agent.c does for
// every algorithm, and nothing else: no model, no planning.
#include "algorithm.h"

static void observe_(agent_t *ag, agent_state_t s, uint8_t a, float r, agent_state_t s_next,
                     bool terminal, float priority)
{
    (void)ag;
    (void)s;
    (void)a;
    (void)r;
    (void)s_next;
    (void)terminal;
    (void)priority;
}

// It knows what its Q store knows; a state with a row was visited (only real steps write rows).
static int walk_(agent_t *ag, uint32_t what, agent_visit_t visit, void *data)
{
    return (what & AGENT_FACT_STATE) ? agent_walk_rows_as_visits_(ag, visit, data) : 0;
}

const agent_algorithm_t agent_q_learning_algorithm = {
    .init = agent_init_nothing_,
    .clear = agent_nothing_,
    .observe = observe_,
    .plan = agent_plan_nothing_,
    .regions = agent_list_nothing_,
    .check = agent_check_nothing_,
    .restored = agent_nothing_,
    .walk = walk_,
    .backlog = agent_backlog_none_,
    // It does not plan (its idle loop finds nothing to do): Dyna-QPC's figure, which nothing it
    // does depends on.
    .plan_cycles = 4213u,
};
