// SPDX-License-Identifier: MIT
// dynaqpc drivers: the yaw-rate gyro (GYRO_RATE, 16 ms) and a heading integrator.
//
// gyro_rx_rate() decodes a frame and integrates the heading: the trapezoid of the last two rates
// over the time between their receive stamps, minus the bias estimate. The bias is learnt while
// the application says the robot stands still (gyro_set_stationary), which is when a rate is
// pure bias, from samples within FW_CFG_GYRO_BIAS_GATE_DEG_S of the estimate (farther: the robot
// is still turning after the wheels were told to stop). Samples with Status INIT or FAULT are not integrated; a gap longer than
// FW_CFG_GYRO_MAX_DT_US is not bridged (counted in `gaps`: the heading is then suspect).
// Context: one thread; nothing blocks.
#ifndef DRIVERS_GYRO_H
#define DRIVERS_GYRO_H

#include <stdbool.h>
#include <stdint.h>

#include "drivers/can_link.h"
#include "hal/hal_can.h"

/// Full scale of GYRO_RATE YawRate (docs/dynaqpc.dbc), deg/s: faster turns saturate the reading.
#define GYRO_RANGE_DEG_S 300
/// The largest counter step GYRO_RATE may take (can_link_rx_accept_e2e): the samples of the
/// longest gap the integrator bridges (FW_CFG_GYRO_MAX_DT_US, 100 ms: 6 samples of 16 ms).
#define GYRO_MAX_STEP 6u

#ifdef __cplusplus
extern "C" {
#endif

/// GYRO_RATE Status values.
enum gyro_status { GYRO_STATUS_OK = 0, GYRO_STATUS_INIT = 1, GYRO_STATUS_FAULT = 2 };

typedef struct gyro {
    int16_t rate_cdeg_s;    ///< last yaw rate, 0.01 deg/s, counter-clockwise positive
    int8_t temperature_c;
    uint8_t status;         ///< enum gyro_status of the last frame
    uint16_t period_us;     ///< the samples' period (0: integrate over receive times); gyro_set_sample_period
    uint16_t rate_limit_cdeg_s; ///< |rate| beyond it is implausible (0: none); gyro_set_rate_limit
    can_link_rx_t rx;
    // Integrator.
    float heading_deg;      ///< [0, 360), counter-clockwise
    float bias_deg_s;       ///< estimated rate offset, subtracted before integrating
    bool stationary;        ///< the app says the robot stands still: learn the bias
    bool have_prev;         ///< prev_* hold a usable sample
    float prev_rate_deg_s;  ///< last integrated rate (bias not removed)
    uint64_t prev_us;
    uint32_t gaps;          ///< intervals longer than FW_CFG_GYRO_MAX_DT_US not integrated
    float gap_bound_deg;    ///< the most the last such gap can have turned: its length times the larger end rate
    uint32_t bias_rejected; ///< stationary samples beyond the bias gate (still turning): not learnt
} gyro_t;

/// Clears the state; heading 0, bias 0, not stationary.
void gyro_init(gyro_t *gyro);

/// Decodes GYRO_RATE received at `now_us` and integrates. Returns FW_OK, FW_ERR_INVAL (malformed:
/// wrong id/dlc, a Crc that fails (the end-to-end check over the data id and the data, counter
/// included), rate beyond ±300 deg/s, unknown status; counted in rx.malformed; or implausible: a
/// counter jump over GYRO_MAX_STEP, more samples than a gap the integrator bridges, or an OK
/// sample's rate beyond gyro_set_rate_limit's, counted in rx.implausible; nothing changes, the
/// next good sample bridges it) or FW_ERR_NOENT (counter
/// repeated: ignored). A frame that resynchronises after a jump is taken but not integrated
/// across: a gap.
int gyro_rx_rate(gyro_t *gyro, const hal_can_frame_t *frame, uint64_t now_us);

/// Integrates over the samples' own clock: each interval is the counter's steps times `period_us`
/// (GYRO_RATE's cycle, 16000), whatever the receive times, which a loaded host or a stalled
/// task bunches up; 0 integrates over receive times. gyro_init sets FW_CFG_GYRO_PERIOD_US.
void gyro_set_sample_period(gyro_t *gyro, uint16_t period_us);

/// The fastest the robot can turn now, 0.01 deg/s (0: no limit but the sensor's range): an OK
/// sample beyond it is refused as implausible and bridged like a lost one. The application sets
/// it from the wheel speeds it commanded lately (robot_app.c, gyro_limit_).
void gyro_set_rate_limit(gyro_t *gyro, uint16_t limit_cdeg_s);

/// Sets the heading (deg, any value; wrapped into [0, 360)), e.g. from an absolute reference.
void gyro_set_heading(gyro_t *gyro, float heading_deg);

/// Heading in [0, 360) degrees.
float gyro_heading_deg(const gyro_t *gyro);

/// Tells whether the robot stands still (wheels stopped and measured still). While true, each
/// OK sample updates the bias estimate.
void gyro_set_stationary(gyro_t *gyro, bool stationary);

/// Device side: builds GYRO_RATE. `rate_cdeg_s` within ±30000. FW_OK or FW_ERR_INVAL.
int gyro_encode_rate(uint8_t *counter, int16_t rate_cdeg_s, int8_t temperature_c, uint8_t status,
                     hal_can_frame_t *out);

#ifdef __cplusplus
}
#endif

#endif // DRIVERS_GYRO_H
