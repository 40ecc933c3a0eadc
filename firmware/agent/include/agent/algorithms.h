// SPDX-License-Identifier: MIT
// dynaqpc: the registry of learning algorithms: one line per algorithm.
//
// Adding an algorithm: write its header (its state, its part of agent_storage_t and its memory,
// as dyna_q.h) and its .c file (its agent_algorithm_t, as dyna_q.c), include the header here,
// add its line to AGENT_ALGORITHMS and its .c file to firmware/CMakeLists.txt. Everything else
// (the agent_kind_t value, the name and label the tools use, the agent's state and storage, each
// profile's memory, the dispatch) follows from that line (docs/porting.md).
#ifndef AGENT_ALGORITHMS_H
#define AGENT_ALGORITHMS_H

#include "agent/dyna_q.h"
#include "agent/dyna_q_majority.h"
#include "agent/dyna_qpc.h"
#include "agent/q_learning.h"

/// X(KIND, number, "name", "label", id, d): the agent_kind_t value KIND (saved in the learned-data
/// store's header, so never renumbered), the name the tools and scenario files use, the label of
/// tables and plots, and `id`, which names the algorithm's state type agent_<id>_t, its storage
/// type agent_<id>_storage_t, its memory AGENT_MEMORY_<id>(P) with AGENT_STORAGE_<id>(m) (its
/// header: agent_profiles.h sizes it for each profile) and its operations agent_<id>_algorithm
/// (algorithm.h).
/// `dynaqpc-sim agents --json` prints what the tools learn from here (names, labels, models,
/// counters).
/// Each X is also given `d`, AGENT_ALGORITHMS_WITH's second argument, last (agent_profiles.h
/// passes the memory it points the storage into; AGENT_ALGORITHMS passes nothing of use).
#define AGENT_ALGORITHMS_WITH(X, d)                                                             \
    X(AGENT_Q_LEARNING, 0, "q", "Q-learning", q_learning, d) /* Fig. 1: no model, no planning */ \
    X(AGENT_DYNA_Q, 1, "dyna-q", "Dyna-Q", dyna_q, d)        /* Fig. 5: table, random replay */  \
    X(AGENT_DYNA_QPC, 2, "dyna-qpc", "Dyna-QPC", dyna_qpc, d) /* Figs. 3, 7, 10: model, sweeping */ \
    X(AGENT_DYNA_Q_MAJORITY, 3, "dyna-q-majority", "Dyna-Q (majority)", dyna_q_majority, d)
#define AGENT_ALGORITHMS(X) AGENT_ALGORITHMS_WITH(X, ~)

/// X(KIND, model, "name", id): the world models an algorithm plans through, one line each: with
/// agent_params_t.model == model, an agent of KIND runs the operations agent_<id>_algorithm (its
/// own file) over KIND's state and storage. `model` is saved in no header but named by scenario
/// files and `--model`, so a number names one model for every algorithm; a kind with no line
/// for a model runs its own operations and ignores the setting. A variant is a file and a line.
#define AGENT_MODELS_OF(X)                                                                     \
    X(AGENT_DYNA_QPC, 0, "relocatable", dyna_qpc) /* ours: model.h, docs/agent.md */           \
    X(AGENT_DYNA_QPC, 1, "paper", dyna_qpc_paper) /* the paper's CMAC-Model and CMAC-R */

#endif // AGENT_ALGORITHMS_H
