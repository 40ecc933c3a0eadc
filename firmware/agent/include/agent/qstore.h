// SPDX-License-Identifier: MIT
// dynaqpc: the action-value table Q(s, a), dense or hashed, in static storage.
#ifndef AGENT_QSTORE_H
#define AGENT_QSTORE_H

#include <stdbool.h>
#include <stdint.h>

#include "agent/value16.h"
#include "agent/oa_table.h"
#include "agent/region.h"
#include "agent/space.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Q values are single-precision floats, or, where a profile needs the rows more than the
/// precision, 16-bit values (agent/value16.h: a float with a 6-bit exponent and 10 significant
/// bits), read as floats, updated in float and rounded to the nearest value16 when written.
/// A profile chooses by the type of its array (agent_profiles.h): paper-lab and the gridworlds
/// keep floats (they fit); paper-sim's 16-bit values hold twice the rows in the same RAM, so a
/// floor with four times its cells runs in 192 KB (docs/agent.md, "Q store"; it learns reliably
/// only with twice those rows again, paper-sim-large's in 256 KB with 16-bit keys, below:
/// docs/results/far-goal.md). 10 significant bits
/// suffice there: the step between values is 2^-10 of them (0.1 at a robot's returns near
/// -100) while an action's values differ by whole step costs, and a gridworld's far values
/// (1e-6) are still normal numbers (measured: docs/results/far-goal.md). (Fixed point
/// lost: a gridworld's values of 1e-4 vanish in 16 fixed-point bits; IEEE half's below 6e-5.)
///
/// Dense when every state fits (2^state_bits <= capacity): row s is at s * n_actions, no keys.
/// Hashed otherwise: the rows' states in an open-addressing index (oa_table.h) of `capacity`
/// slots, bounded windows of FW_CFG_MAX_PROBE slots; row i belongs to the state in slot i. A row is created the first time its state's Q is written; an unwritten state
/// reads as all zeros. When no row is free within the probe limit, the row of that window that
/// has learned least (smallest sum of |Q|) is forgotten and reused, and counted in `dropped`: a
/// robot that keeps exploring keeps learning where it is, at the cost of states it barely knew.
typedef struct qstore {
    union {
        float *f;        // capacity * n_actions floats (wide)
        value16_t *h;    // or value16s
    } v;
    uint8_t wide;        // 1: floats, 0: value16s
    uint8_t narrow;      // 1: 16-bit keys (qstore_init16); index.keys then holds their address
    oa_table_t index;    // capacity slots (hashed mode only; keys NULL when dense)
    uint32_t capacity;   // rows
    uint8_t n_actions;
    uint8_t dense;
    float prior;         ///< Q of a state never written: what it reads, where its row starts
    uint32_t rows_used;  ///< rows holding a state (hashed) or written at least once (dense: 0)
    uint32_t dropped;    ///< states forgotten to make room: a full probe window reuses the row that learned least
    uint32_t plan_refused; ///< planning writes refused: the state had no row and no free slot (planning never evicts)
} qstore_t;

/// Whether the store holds a row for s: hashed, whether s has a slot; dense (every state has its
/// row), whether a value of s's row is nonzero. For views of what was learned, not the planner.
bool qstore_has_row(const qstore_t *qs, agent_state_t s);

/// A row of the store (a state's slot), for the writes of one update; QSTORE_NO_ROW: none.
typedef uint32_t qstore_row_t;
#define QSTORE_NO_ROW UINT32_MAX

/// Marks an empty row in hashed mode.
#define QSTORE_EMPTY OA_EMPTY

/// Prepares an all-zero table. `capacity` must be a power of two; `q` holds capacity *
/// n_actions values of `value_bytes` each (4: float, 2: value16); `keys` holds capacity words
/// (unused, may be NULL, if the table is dense). Returns FW_OK or FW_ERR_INVAL.
int qstore_init(qstore_t *qs, void *q, uint8_t value_bytes, uint32_t *keys, uint32_t capacity,
                uint8_t n_actions, uint32_t state_bits);

/// 16-bit keys (a profile whose Q store must hold more rows than its RAM would with 32-bit keys:
/// paper-sim-large, agent_profiles.h). A slot keeps the low QSTORE_KEY16_BITS bits of its state;
/// the rest is where the slot lies: the table is the one qstore_init() makes, slot for slot, as
/// long as two states with the same low bits never have overlapping probe windows, which
/// qstore_keys16_exact() says of a capacity and a state width (checked by brute force in the unit
/// tests). Returns FW_ERR_INVAL where it is not exact, or `keys` is not 4-byte aligned.
int qstore_init16(qstore_t *qs, void *q, uint8_t value_bytes, uint16_t *keys, uint32_t capacity,
                  uint8_t n_actions, uint32_t state_bits);

/// The bits of a state a 16-bit key keeps; the top bit marks an empty slot (QSTORE_EMPTY16).
#define QSTORE_KEY16_BITS 15u
#define QSTORE_EMPTY16 0xFFFFu

/// Whether 16-bit keys give the same table as 32-bit ones for `capacity` rows and states of
/// `state_bits` bits: states of at most 15 bits, or capacities of 2^12..2^16 rows with states of
/// at most 20 bits (the Fibonacci homes of two states that differ only above bit 14 then lie at
/// least 65 slots apart, more than a probe window).
bool qstore_keys16_exact(uint32_t capacity, uint32_t state_bits);

/// Forgets every state: each reads the prior again.
void qstore_clear(qstore_t *qs);

/// Sets the prior, the value every action of a state never written reads and its row starts
/// from (qstore_init: 0, the paper's), and clears the store. A prior below zero tempers the
/// optimism of unknown states where the step reward is negative (agent_params_t.q_prior).
void qstore_set_prior(qstore_t *qs, float prior);

/// Q(s, a). An unknown state reads the prior.
float qstore_get(const qstore_t *qs, agent_state_t s, uint8_t a);

/// The n_actions values of state s into out[]. An unknown state gives the prior.
void qstore_values(const qstore_t *qs, agent_state_t s, float *out);

/// max over a of Q(s, a).
float qstore_max(const qstore_t *qs, agent_state_t s);

/// The row of state s for a real step's write, created if needed. A full probe window forgets the
/// row that learned least (counted in `dropped`); never QSTORE_NO_ROW.
qstore_row_t qstore_row_for_update(qstore_t *qs, agent_state_t s);

/// The row of state s for a planning write: the existing row, or a new one in a free slot of its
/// probe window. Planning never forgets a state to make room (that churned tens of millions of
/// rows per set on paper-sim, each a state real experience had taught): with no free slot it
/// returns QSTORE_NO_ROW and counts `plan_refused`.
qstore_row_t qstore_row_for_plan(qstore_t *qs, agent_state_t s);

/// Q += alpha * (target - Q) for action a of `row`, computed in float and stored rounded to the
/// nearest value16; *value (may be NULL) gets the value stored. Returns whether the stored value
/// changed: once Q is within about one value16 step of the target an update rounds back to where
/// it was, and a planner that requeued such a pair would replay it forever.
bool qstore_learn(qstore_t *qs, qstore_row_t row, uint8_t a, float target, float alpha,
                  float *value);

/// Whether an update of a stored value q towards `target` at rate alpha would change it: a
/// planner queues a pair only if so. In value16s a value near its target rounds back to itself
/// (the step between them is 2^-10 of the value, larger than a small sweep threshold), and a
/// pair queued for an update that changes nothing would be replayed, with its predecessors,
/// forever.
bool qstore_moves(const qstore_t *qs, float q, float target, float alpha);

/// Sets action a of `row` to v (rounded to the nearest value16).
void qstore_set(qstore_t *qs, qstore_row_t row, uint8_t a, float v);

/// max over a of the values of `row` (QSTORE_NO_ROW: the prior).
float qstore_row_max(const qstore_t *qs, qstore_row_t row);

/// The row of state s for reading, QSTORE_NO_ROW if it has none; a row stays s's until a write
/// makes or forgets a row. For a reader that wants several values of a state from one lookup.
qstore_row_t qstore_row_of(const qstore_t *qs, agent_state_t s);

/// Action a's value in `row` (QSTORE_NO_ROW: the prior): qstore_get() of the row's state.
float qstore_row_get(const qstore_t *qs, qstore_row_t row, uint8_t a);

/// The largest |Q| a restored table of floats may hold: far beyond any return a robot's rewards
/// and discount give, and far enough below FLT_MAX that learning from it cannot overflow.
/// (value16s saturate at VALUE16_MAX.)
#define QSTORE_VALUE_LIMIT 1e9f

/// The most regions qstore_regions() lists.
#define QSTORE_MAX_REGIONS 2u

/// Lists the memory that holds what the store learned, in a fixed order: the values, then (hashed
/// only) the keys (2 bytes each with qstore_init16()). Returns how many regions it wrote to `out`.
uint32_t qstore_regions(const qstore_t *qs, agent_region_t *out);

/// Checks restored contents before they are copied into `qs` (which gives the shape: capacity,
/// actions, dense or hashed): image[i] holds the bytes of region i as qstore_regions() lists
/// them. Every float must be finite and within QSTORE_VALUE_LIMIT, every value16 a value
/// (value16_ok: no exponent 63); in a hashed table every key
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
