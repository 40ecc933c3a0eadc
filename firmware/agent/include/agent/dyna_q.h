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

/// Its memory in a profile P (agent_profiles.h: P(KNOB) is the profile's setting KNOB): as many
/// records as fit, with their index, in P(ALGORITHM_BYTES), the bytes every algorithm gets.
#define AGENT_DYNA_Q_RECORDS_(P) DYNAQ_RECORDS_IN(P(ALGORITHM_BYTES), 0u)
#define AGENT_MEMORY_dyna_q(P)                                                                 \
    struct {                                                                                   \
        dynaq_record_t records[AGENT_DYNA_Q_RECORDS_(P)];                                      \
        uint32_t index_keys[DYNAQ_INDEX_SLOTS(AGENT_DYNA_Q_RECORDS_(P))];                      \
        uint32_t index_rec[DYNAQ_INDEX_SLOTS(AGENT_DYNA_Q_RECORDS_(P))];                       \
    }
/// Its part of agent_storage_t, in memory `m` of that type.
#define AGENT_STORAGE_dyna_q(m) {(m).records, (m).index_keys, (m).index_rec, AGENT_COUNT_OF((m).records)}

#ifdef __cplusplus
}
#endif

#endif // AGENT_DYNA_Q_H
