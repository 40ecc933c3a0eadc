// SPDX-License-Identifier: MIT
// dynaqpc drivers: range sensors — IR_RANGES (3 IR, lab robot, 48 ms) and SONAR_RANGES_A/B/C
// (16 sonars, simulated robot: one scan is three frames of one Counter every 96 ms; 2 cm per
// bit, raw 127 = no echo).
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
#define RANGES_SONAR_PARTS 3u     ///< frames of one scan: SONAR_RANGES_A (0..6), _B (7..13), _C (14, 15)
/// ranges_rx_sonar()'s result for a part taken whose scan is not complete yet.
#define RANGES_SONAR_PART 1

enum ranges_ir { RANGES_IR_LEFT = 0, RANGES_IR_FRONT = 1, RANGES_IR_RIGHT = 2 };

/// Which frames carry a robot's `n` range sensors: IR_RANGES for exactly three, the sonar scans
/// (SONAR_RANGES_A/B/C, up to RANGES_SONAR_COUNT, the rest sent as no echo) for any other number,
/// whatever the sensors' kind. The firmware reads, and a range board sends, by this rule.
static inline bool ranges_in_ir_frame(uint32_t n)
{
    return n == RANGES_IR_COUNT;
}

// (The links first: the 192 KiB paper-sim image has no byte to spare for padding.)
typedef struct ranges {
    can_link_rx_t ir_rx;
    uint16_t sonar_mm[RANGES_SONAR_COUNT];   ///< the last scan taken, RANGES_NO_ECHO if none
    /// The scans: `frames` scans taken, `counter` the last one's, `lost` scans missed by counter
    /// gaps, `last_ok_us` the last one's time (its silence is the sonars'); `implausible` complete
    /// scans refused for a counter jump and parts refused as a second, different copy; `malformed`
    /// parts refused (dlc, Crc); `repeated` parts that came again, the same copy.
    can_link_rx_t sonar_rx;
    uint8_t sonar_raw[RANGES_SONAR_COUNT];   ///< the scan being assembled (raw, 2 cm per bit)
    uint8_t sonar_parts;                     ///< bit p: part p of scan `sonar_counter` is in sonar_raw
    uint8_t sonar_counter;                   ///< the Counter of the scan being assembled
    uint16_t sonar_dropped;                  ///< scans never taken: a part missing, or two different
                                             ///< copies of one part (sonar_mm held); saturated
    uint16_t ir_mm[RANGES_IR_COUNT];         ///< last IR ranges
    bool ir_valid[RANGES_IR_COUNT];          ///< false: nothing in view (ir_mm meaningless)
} ranges_t;

/// Clears the state: no IR valid, every sonar RANGES_NO_ECHO.
void ranges_init(ranges_t *ranges);

/// Decodes IR_RANGES. FW_OK, FW_ERR_INVAL (malformed: a Crc that fails, range >
/// RANGES_IR_MAX_MM, counted in malformed; or a counter jump over CAN_LINK_MAX_STEP, counted in
/// implausible) or FW_ERR_NOENT.
int ranges_rx_ir(ranges_t *ranges, const hal_can_frame_t *frame, uint64_t now_us);

/// Decodes SONAR_RANGES_A, _B or _C (the id says which part) into the scan of its Counter, and
/// takes the scan into sonar_mm when its three parts, each with its Crc good, carry one Counter:
/// FW_OK (scan taken), RANGES_SONAR_PART (part kept, scan not complete), FW_ERR_INVAL (a
/// malformed part: dlc, Crc or Reserved not 0, counted in malformed; a second, different copy of a part, which
/// drops its scan; or the complete scan's Counter jumped over CAN_LINK_MAX_STEP: counted in
/// implausible) or FW_ERR_NOENT (the same copy of a part again, counted in repeated; or the
/// scan's Counter repeats the last one's). A part of another Counter drops an incomplete scan.
/// A dropped scan is counted in sonar_dropped; sonar_mm keeps the last scan taken.
int ranges_rx_sonar(ranges_t *ranges, const hal_can_frame_t *frame, uint64_t now_us);

/// Device side: IR_RANGES from mm (valid[i] false sends 0). FW_OK or FW_ERR_INVAL.
int ranges_encode_ir(uint8_t *counter, const uint16_t mm[RANGES_IR_COUNT],
                     const bool valid[RANGES_IR_COUNT], hal_can_frame_t *out);

/// Device side: one scan, out[0..2] = SONAR_RANGES_A, _B and _C, from `mm[RANGES_SONAR_COUNT]`,
/// rounded to 2 cm; RANGES_NO_ECHO or anything beyond RANGES_SONAR_MAX_MM is sent as no echo. All
/// three carry the Counter *counter, which advances once. FW_OK or FW_ERR_INVAL.
int ranges_encode_sonar(uint8_t *counter, const uint16_t mm[RANGES_SONAR_COUNT],
                        hal_can_frame_t out[RANGES_SONAR_PARTS]);

#ifdef __cplusplus
}
#endif

#endif // DRIVERS_RANGES_H
