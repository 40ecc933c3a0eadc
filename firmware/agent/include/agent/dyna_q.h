// SPDX-License-Identifier: MIT
// dynaqpc: table-based Dyna-Q (the paper's Fig. 5): its state and storage.
#ifndef AGENT_DYNA_Q_H
#define AGENT_DYNA_Q_H

#include <stdint.h>

#include "agent/dynaq_table.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Dyna-Q's state: the observed transitions, replayed uniformly at random.
typedef struct agent_dyna_q {
    dynaq_table_t table;
} agent_dyna_q_t;

/// Dyna-Q's part of agent_storage_t.
typedef struct agent_dyna_q_storage {
    dynaq_record_t *records;  ///< `states` records
    uint32_t *index_keys;     ///< DYNAQ_INDEX_SLOTS(states)
    uint32_t *index_rec;      ///< DYNAQ_INDEX_SLOTS(states)
    uint32_t states;
} agent_dyna_q_storage_t;

#ifdef __cplusplus
}
#endif

#endif // AGENT_DYNA_Q_H
