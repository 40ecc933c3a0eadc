// SPDX-License-Identifier: MIT
// dynaqpc drivers: position from ranges to beacons at known places (trilateration).
//
// Solves for the listener's x, y at a known height z from n >= 3 slant ranges: first the
// linearised least-squares solution of the horizontal ranges (exact for exact ranges), then
// Gauss-Newton on the slant ranges themselves (the statistically right objective when range
// noise is what it is: additive on each range). Refuses geometry that cannot fix x and y (all
// beacons nearly on one line seen from above) and range sets that disagree with each other.
// Units: whatever the caller uses consistently (the drivers use mm). Pure computation: any
// context, no state, never blocks, bounded work (n <= caller's array).
#ifndef DRIVERS_TRILAT_H
#define DRIVERS_TRILAT_H

#include <stdbool.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct trilat_anchor {
    float x, y, z;  ///< beacon position
    float range;    ///< measured slant range from the beacon to the listener
} trilat_anchor_t;

struct trilat_params {
    float listener_z;    ///< the listener's known height
    float min_spread;    ///< refuse when the beacons' spread (std. dev. of their x, y along the
                         ///< narrowest direction) is below this: near-collinear geometry
    float max_residual;  ///< refuse when the RMS range residual of the solution exceeds this
    unsigned iterations; ///< Gauss-Newton iterations at most (0: linear solution only)
};

typedef struct trilat_result {
    float x, y;
    float residual_rms;  ///< RMS of (distance to beacon - measured range) at the solution
} trilat_result_t;

/// Whether beacons at these places can fix x and y, by the rule trilat_solve() refuses geometry
/// with (FW_ERR_INVAL): n >= 3 and the beacons' spread along their narrowest direction (the
/// standard deviation of their x, y across it) at least `min_spread`. The ranges are not read,
/// so a tool can ask it of a layout before any range is measured. `*spread` (may be NULL): that
/// spread.
bool trilat_geometry_ok(const trilat_anchor_t *anchors, size_t n, float min_spread, float *spread);

/// Returns FW_OK with the solution in *out, FW_ERR_INVAL (n < 3, a negative or non-finite
/// range, or geometry below min_spread) or FW_ERR_CORRUPT (ranges inconsistent: residual above
/// max_residual; *out still holds the best solution found, for diagnosis).
int trilat_solve(const trilat_anchor_t *anchors, size_t n, const struct trilat_params *params,
                 trilat_result_t *out);

#ifdef __cplusplus
}
#endif

#endif // DRIVERS_TRILAT_H
