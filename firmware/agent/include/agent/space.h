// SPDX-License-Identifier: MIT
// dynaqpc: the shape of a discrete state: a few small integer components packed into one word.
#ifndef AGENT_SPACE_H
#define AGENT_SPACE_H

#include <stdbool.h>
#include <stdint.h>

#include "fw_config.h"

#ifdef __cplusplus
extern "C" {
#endif

/// A state is an integer whose bit fields are its components: component 0 in the lowest bits.
/// The paper's robot: x, y, heading and a range-sensor code in 5, 5, 4, 4 bits (paper-sim) or
/// 3, 3, 4, 3 bits (paper-lab). A gridworld: row, column.
typedef uint32_t agent_state_t;

/// The most state bits any space may use (states and actions pack into one 32-bit queue key).
#define SPACE_MAX_STATE_BITS 24

typedef struct agent_space {
    uint8_t n_components;                    ///< 1..FW_CFG_MAX_COMPONENTS
    uint8_t bits[FW_CFG_MAX_COMPONENTS];     ///< width of each component, 1..16
    /// CMAC tile width of each component is 2^tile_shift (0: exact, no generalisation).
    uint8_t tile_shift[FW_CFG_MAX_COMPONENTS];
    uint8_t circular_mask;  ///< bit k: component k wraps around (a heading)
    /// bit k: the model predicts component k's next value itself (a sensor reading); otherwise
    /// it predicts the change (a position), which generalises across neighbouring states.
    uint8_t absolute_mask;
    uint8_t n_actions;      ///< 1..FW_CFG_MAX_ACTIONS
    /// bit k: component k is part of what the robot perceives of its situation (its heading, its
    /// range code), which keys the relocatable action model: the same action in the same
    /// situation has the same effect anywhere (docs/agent.md, "Generalisation"). The components
    /// outside it (a position) are what the model generalises over. 0: no generalisation (a
    /// gridworld, where a wall makes neighbouring cells unlike each other).
    uint8_t context_mask;
    /// The motion turns the circular component in steps of 2^turn_step_bits values (aligned
    /// turns: 90 degrees over 16 headings is 2 bits), so once the robot has turned its heading
    /// is a multiple of that step. Where its storage cannot hold every place, the model's
    /// percept map keeps only those headings' places (a quarter of the memory over 16
    /// headings), and a place between them (a start's heading before the first turn) is not
    /// mapped. 0: every value is reached (unaligned turns).
    uint8_t turn_step_bits;
} agent_space_t;

/// The most bits the absolute components of a space may have together: the model keeps, per
/// place, the set of their values seen there as a 16-bit mask.
#define SPACE_MAX_ABSOLUTE_BITS 4

/// Total bits of a state.
uint32_t space_state_bits(const agent_space_t *sp);

/// Checks a space's limits. Returns FW_OK or FW_ERR_INVAL.
int space_validate(const agent_space_t *sp);

/// The state bits of its position: every component outside context_mask and absolute_mask (x and
/// y on the robots, row and column on a gridworld). s & this is s's cell.
uint32_t space_position_mask(const agent_space_t *sp);

/// Splits a state into its components.
void space_unpack(const agent_space_t *sp, agent_state_t s, uint32_t *comp);

/// Packs components (each already within its bit range) into a state.
agent_state_t space_pack(const agent_space_t *sp, const uint32_t *comp);

/// The change of component k from `from` to `to` as the models learn it: the new value itself
/// for an absolute component; for another the signed difference, wrapped on a circular one into
/// [-2^(bits-1), 2^(bits-1)), the shorter way round (turning right from 15 of 16 headings is +1).
/// k < n_components; from and to within the component's bits.
int32_t space_change(const agent_space_t *sp, uint32_t k, uint32_t from, uint32_t to);

#ifdef __cplusplus
}
#endif

#endif // AGENT_SPACE_H
