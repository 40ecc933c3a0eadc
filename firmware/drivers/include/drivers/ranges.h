// SPDX-License-Identifier: MIT
// dynaqpc drivers: range sensors — IR_RANGES (3 IR, lab robot, 48 ms) and SONAR_RANGES_A/B
// (16 sonars, simulated robot, 96 ms; 2 cm per bit, raw 127 = no echo).
// Context: one thread; nothing blocks.
#ifndef DRIVERS_RANGES_H
#define DRIVERS_RANGES_H

#include <stdbool.h>
#include <stdint.h>

#include "drivers/can_link.h"
#include "hal/hal_can.h"

#ifdef __cplusplus
extern "C" {
#endif

#define RANGES_IR_COUNT 3u        ///< front-left, front, front-right
#define RANGES_IR_MAX_MM 2000u    ///< IR_RANGES limit; larger values are malformed
#define RANGES_SONAR_COUNT 16u    ///< sonar 0 points forward, numbered counter-clockwise
#define RANGES_SONAR_MAX_MM 2520u ///< the largest echo a sonar frame can carry (raw 126)
#define RANGES_NO_ECHO 0xFFFFu    ///< sonar_mm value: nothing in reach

enum ranges_ir { RANGES_IR_LEFT = 0, RANGES_IR_FRONT = 1, RANGES_IR_RIGHT = 2 };

typedef struct ranges {
    uint16_t ir_mm[RANGES_IR_COUNT];         ///< last IR ranges
    bool ir_valid[RANGES_IR_COUNT];          ///< false: nothing in view (ir_mm meaningless)
    can_link_rx_t ir_rx;
    uint16_t sonar_mm[RANGES_SONAR_COUNT];   ///< last sonar ranges, RANGES_NO_ECHO if none
    can_link_rx_t sonar_rx[2];               ///< [0]: SONAR_RANGES_A (0..7), [1]: B (8..15)
} ranges_t;

/// Clears the state: no IR valid, every sonar RANGES_NO_ECHO.
void ranges_init(ranges_t *ranges);

/// Decodes IR_RANGES. FW_OK, FW_ERR_INVAL (malformed: a Crc that fails, range >
/// RANGES_IR_MAX_MM, counted in malformed; or a counter jump over CAN_LINK_MAX_STEP, counted in
/// implausible) or FW_ERR_NOENT.
int ranges_rx_ir(ranges_t *ranges, const hal_can_frame_t *frame, uint64_t now_us);

/// Decodes SONAR_RANGES_A or _B (the id says which; their Crc is 4 bits). FW_OK, FW_ERR_INVAL
/// (as ranges_rx_ir) or FW_ERR_NOENT.
int ranges_rx_sonar(ranges_t *ranges, const hal_can_frame_t *frame, uint64_t now_us);

/// Device side: IR_RANGES from mm (valid[i] false sends 0). FW_OK or FW_ERR_INVAL.
int ranges_encode_ir(uint8_t *counter, const uint16_t mm[RANGES_IR_COUNT],
                     const bool valid[RANGES_IR_COUNT], hal_can_frame_t *out);

/// Device side: SONAR_RANGES_A (`half` 0: sonars 0..7) or _B (`half` 1: 8..15) from
/// `mm[RANGES_SONAR_COUNT]`, rounded to 2 cm; RANGES_NO_ECHO or anything beyond
/// RANGES_SONAR_MAX_MM is sent as no echo. FW_OK or FW_ERR_INVAL (half not 0 or 1).
int ranges_encode_sonar(uint8_t *counter, unsigned half, const uint16_t mm[RANGES_SONAR_COUNT],
                        hal_can_frame_t *out);

#ifdef __cplusplus
}
#endif

#endif // DRIVERS_RANGES_H
