// SPDX-License-Identifier: MIT
// dynaqpc: the action-value table Q(s, a), dense or hashed, in static storage.
#ifndef AGENT_QSTORE_H
#define AGENT_QSTORE_H

#include <stdint.h>

#include "agent/oa_table.h"
#include "agent/region.h"
#include "agent/space.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Q values are single-precision floats: the Cortex-M4F has a single-precision FPU, and
/// docs/agent.md records why fixed point lost (gridworld values of 1e-4 vanish in 16 bits).
///
/// Dense when every state fits (2^state_bits <= capacity): row s is at s * n_actions, no keys.
/// Hashed otherwise: the rows' states in an open-addressing index (oa_table.h) of `capacity`
/// slots, bounded windows of FW_CFG_MAX_PROBE slots; row i belongs to the state in slot i. A row is created the first time its state's Q is written; an unwritten state
/// reads as all zeros. When no row is free within the probe limit, the row of that window that
/// has learned least (smallest sum of |Q|) is forgotten and reused, and counted in `dropped`: a
/// robot that keeps exploring keeps learning where it is, at the cost of states it barely knew.
typedef struct qstore {
    float *q;            // capacity * n_actions
    oa_table_t index;    // capacity slots (hashed mode only; keys NULL when dense)
    uint32_t capacity;   // rows
    uint8_t n_actions;
    uint8_t dense;
    uint32_t rows_used;  ///< rows holding a state (hashed) or written at least once (dense: 0)
    uint32_t dropped;    ///< states forgotten to make room: a full probe window reuses the row that learned least
    uint32_t plan_refused; ///< planning writes refused: the state had no row and no free slot (planning never evicts)
} qstore_t;

/// Marks an empty row in hashed mode.
#define QSTORE_EMPTY OA_EMPTY

/// Prepares an all-zero table. `capacity` must be a power of two; `q` holds capacity *
/// n_actions floats; `keys` holds capacity words (unused, may be NULL, if the table is dense).
/// Returns FW_OK or FW_ERR_INVAL.
int qstore_init(qstore_t *qs, float *q, uint32_t *keys, uint32_t capacity, uint8_t n_actions,
                uint32_t state_bits);

/// Zeroes every value.
void qstore_clear(qstore_t *qs);

/// The n_actions values of state s, read-only. An unknown state gives a row of zeros.
const float *qstore_row(const qstore_t *qs, agent_state_t s);

/// The row of state s for a real step's write, created if needed. A full probe window forgets the
/// row that learned least (counted in `dropped`); never NULL.
float *qstore_row_for_update(qstore_t *qs, agent_state_t s);

/// The row of state s for a planning write: the existing row, or a new one in a free slot of its
/// probe window. Planning never forgets a state to make room (that churned tens of millions of
/// rows per set on paper-sim, each a state real experience had taught): with no free slot it
/// returns NULL and counts `plan_refused`.
float *qstore_row_for_plan(qstore_t *qs, agent_state_t s);

/// max over a of Q(s, a).
float qstore_max(const qstore_t *qs, agent_state_t s);

/// The largest |Q| a restored table may hold: far beyond any return a robot's rewards and
/// discount give, and far enough below FLT_MAX that learning from it cannot overflow.
#define QSTORE_VALUE_LIMIT 1e9f

/// The most regions qstore_regions() lists.
#define QSTORE_MAX_REGIONS 2u

/// Lists the memory that holds what the store learned, in a fixed order: the values, then (hashed
/// only) the keys. Returns how many regions it wrote to `out`.
uint32_t qstore_regions(const qstore_t *qs, agent_region_t *out);

/// Checks restored contents before they are copied into `qs` (which gives the shape: capacity,
/// actions, dense or hashed): image[i] holds the bytes of region i as qstore_regions() lists
/// them. Every value must be finite and within QSTORE_VALUE_LIMIT; in a hashed table every key
/// must be empty or a state of `state_bits` bits, found by a search from its home slot within
/// FW_CFG_MAX_PROBE slots (no empty slot and no copy of it before it), and every empty row all
/// zeros (a new row is used as it is). Reads only. Returns FW_OK or FW_ERR_CORRUPT.
int qstore_check(const qstore_t *qs, const void *const *image, uint32_t state_bits);

/// After contents that passed qstore_check() were copied into the regions: recounts the rows in
/// use (the store's fill, which only the store computes). `dropped` and `plan_refused` are left
/// as they are: statistics are not saved.
void qstore_restored(qstore_t *qs);

#ifdef __cplusplus
}
#endif

#endif // AGENT_QSTORE_H
