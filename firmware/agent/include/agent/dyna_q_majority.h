// SPDX-License-Identifier: MIT
// dynaqpc: Dyna-Q with the majority rule (dyna_q_majority.c): its state and storage.
#ifndef AGENT_DYNA_Q_MAJORITY_H
#define AGENT_DYNA_Q_MAJORITY_H

#include <stdint.h>

#include "agent/dynaq_table.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Its state: Dyna-Q's table of observed transitions, and per record and action how far the
/// kept outcome leads (counts[record * FW_CFG_MAX_ACTIONS + a]: observations that agreed with it
/// minus those that did not, as CMAC-Model's cell counts; meaningful where the action's tried
/// bit is set).
typedef struct agent_dyna_q_majority {
    dynaq_table_t table;
    uint8_t *counts;
    uint32_t kept;      ///< observations that disagreed with an outcome that kept the majority
    uint32_t replaced;  ///< observations that replaced an outcome which had lost it
} agent_dyna_q_majority_t;

/// Its part of agent_storage_t.
typedef struct agent_dyna_q_majority_storage {
    dynaq_record_t *records;  ///< `states` records
    uint32_t *index_keys;     ///< DYNAQ_INDEX_SLOTS(states)
    uint32_t *index_rec;      ///< DYNAQ_INDEX_SLOTS(states)
    uint8_t *counts;          ///< states * FW_CFG_MAX_ACTIONS
    uint32_t states;
} agent_dyna_q_majority_storage_t;

/// Its memory in a profile P (agent_profiles.h): as many records as fit, with their counts and
/// index, in P(ALGORITHM_BYTES), the bytes every algorithm gets.
#define AGENT_DYNA_Q_MAJORITY_RECORDS_(P) DYNAQ_RECORDS_IN(P(ALGORITHM_BYTES), FW_CFG_MAX_ACTIONS)
#define AGENT_MEMORY_dyna_q_majority(P)                                                        \
    struct {                                                                                   \
        dynaq_record_t records[AGENT_DYNA_Q_MAJORITY_RECORDS_(P)];                             \
        uint32_t index_keys[DYNAQ_INDEX_SLOTS(AGENT_DYNA_Q_MAJORITY_RECORDS_(P))];             \
        uint32_t index_rec[DYNAQ_INDEX_SLOTS(AGENT_DYNA_Q_MAJORITY_RECORDS_(P))];              \
        uint8_t counts[AGENT_DYNA_Q_MAJORITY_RECORDS_(P) * FW_CFG_MAX_ACTIONS];                \
    }
/// Its part of agent_storage_t, in memory `m` of that type.
#define AGENT_STORAGE_dyna_q_majority(m) \
    {(m).records, (m).index_keys, (m).index_rec, (m).counts, AGENT_COUNT_OF((m).records)}

#ifdef __cplusplus
}
#endif

#endif // AGENT_DYNA_Q_MAJORITY_H
