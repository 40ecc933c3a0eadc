// SPDX-License-Identifier: MIT
// dynaqpc: the registry of learning algorithms: one line per algorithm.
//
// Adding an algorithm: write its header (its state and its part of agent_storage_t, as
// dyna_q.h) and its .c file (its agent_algorithm_t, as dyna_q.c), include the header here and
// add its line to AGENT_ALGORITHMS. Everything else (the agent_kind_t value, the name the
// tools accept, the agent's state and storage, the dispatch) follows from that line.
#ifndef AGENT_ALGORITHMS_H
#define AGENT_ALGORITHMS_H

#include "agent/dyna_q.h"
#include "agent/dyna_q_majority.h"
#include "agent/dyna_qpc.h"
#include "agent/q_learning.h"

/// X(KIND, number, "name", id): the agent_kind_t value KIND (saved in the learned-data store's
/// header, so never renumbered), the name the tools and scenario files use, and `id`, which
/// names the algorithm's state type agent_<id>_t, its storage type agent_<id>_storage_t and its
/// operations agent_<id>_algorithm (algorithm.h).
#define AGENT_ALGORITHMS(X)                                                                    \
    X(AGENT_Q_LEARNING, 0, "q", q_learning)   /* the paper's Fig. 1: no model, no planning */  \
    X(AGENT_DYNA_Q, 1, "dyna-q", dyna_q)      /* Fig. 5: transition table, random replay */    \
    X(AGENT_DYNA_QPC, 2, "dyna-qpc", dyna_qpc) /* Figs. 3, 7, 10: model, prioritized sweeping */ \
    X(AGENT_DYNA_Q_MAJORITY, 3, "dyna-q-majority", dyna_q_majority) /* Dyna-Q, majority outcome */

#endif // AGENT_ALGORITHMS_H
