// SPDX-License-Identifier: MIT
// dynaqpc drivers: the Cricket v2 listener on the robot (115200 8N1 ASCII lines over UART) and the
// position fix from its beacon ranges.
//
// A line looks like  VR=2.0,ID=01:23:45:67:89:ab:cd:ef,SP=lab,DB=210,DR=6174,TM=7012,TS=32457
// and any field may be switched off in the listener. Fields are read by key, whatever their
// order; unknown keys are ignored. A range needs ID and DR (time of flight, µs, times the speed
// of sound) or DB (distance, in the listener's unit: cm in metric mode); DR is preferred, being
// the more precise. Each range is stored for its beacon (the beacon table maps ID to x, y, z).
//
// The fix, as the paper's lab robot found it (Cricket is accurate only while the robot stands
// still; beacons fire one at a time every 0.67-1.33 s):
//   FRESH   >= 3 ranges taken after the robot last moved, none older than max_age_us, that
//           agree; one range that disagrees with the others is dropped, and with more than 3
//           beacons a fix waits up to 1.5 s after the motion for a fourth range (cricket.c,
//           without_outlier_())
//   MOVING  a fix that uses a range taken before the robot last moved (the app reports motion
//           with cricket_note_motion): do not trust it; the paper's agent waited for FRESH
//   STALE   every range taken after the last motion, but one is older than max_age_us
//   LOST    fewer than 3 beacons heard within lost_age_us, or no consistent solution
//
// Usage (fixed memory; the beacon table must outlive the cricket_t):
//   static const cricket_beacon_t beacons[] = {{0x0102030405060708u, 0, 0, 2500}, ...};
//   struct cricket_config cfg; cricket_default_config(&cfg);
//   cfg.beacons = beacons; cfg.n_beacons = 4; cfg.listener_z_mm = 150;
//   cricket_init(&ck, &cfg);
//   n = hal_uart_read(buf, sizeof buf); cricket_feed(&ck, buf, n, hal_time_us());
//   if (wheels moved this period) cricket_note_motion(&ck, now);
//   state = cricket_get_fix(&ck, now, &fix);
// Context: one thread; nothing blocks; every call does bounded work.
#ifndef DRIVERS_CRICKET_H
#define DRIVERS_CRICKET_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "drivers/drivers_config.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Fix states; the values of TLM_POSE FixState (drivers/telemetry.h enum tlm_fix_state).
typedef enum cricket_fix_state {
    CRICKET_FIX_FRESH = 0,
    CRICKET_FIX_STALE = 1,
    CRICKET_FIX_MOVING = 2,
    CRICKET_FIX_LOST = 3,
} cricket_fix_state_t;

typedef struct cricket_beacon {
    uint64_t id;           ///< the 8-byte ID as printed, first byte most significant
    float x_mm, y_mm, z_mm;
} cricket_beacon_t;

struct cricket_config {
    const cricket_beacon_t *beacons; ///< beacon table (kept by pointer)
    size_t n_beacons;                ///< 3..FW_CFG_CRICKET_MAX_BEACONS
    float listener_z_mm;             ///< height of the listener on the robot
    float speed_of_sound_m_s;        ///< DR to distance; default 343 (20 °C)
    float db_unit_mm;                ///< unit of DB; default 10 (cm: metric mode)
    float max_range_mm;              ///< ranges beyond are refused; default 10000
    size_t max_line;                 ///< longest line kept, <= FW_CFG_CRICKET_LINE_MAX (default)
    uint64_t max_age_us;             ///< FRESH ranges are younger; default 3 s
    uint64_t lost_age_us;            ///< older ranges are never used; default 10 s
    float min_spread_mm;             ///< trilat_params.min_spread; default 300
    float max_residual_mm;           ///< trilat_params.max_residual; default 60
};

/// One parsed line. `fields` says which keys were present (CRICKET_FIELD_*).
#define CRICKET_FIELD_VR 0x01u
#define CRICKET_FIELD_ID 0x02u
#define CRICKET_FIELD_SP 0x04u
#define CRICKET_FIELD_DB 0x08u
#define CRICKET_FIELD_DR 0x10u
#define CRICKET_FIELD_TM 0x20u
#define CRICKET_FIELD_TS 0x40u

typedef struct cricket_line {
    uint32_t fields;
    uint64_t id;
    char space[FW_CFG_CRICKET_SPACE_MAX + 1];  ///< NUL-terminated
    float db;                                   ///< in the listener's unit
    uint32_t dr_us;
    uint32_t tm;
    uint32_t ts;
} cricket_line_t;

typedef struct cricket_stats {
    uint32_t lines;          ///< lines parsed
    uint32_t overlong;       ///< lines discarded: longer than max_line
    uint32_t garbage;        ///< lines discarded: bytes other than printable ASCII
    uint32_t malformed;      ///< lines refused by the parser: field without '=', bad number,
                             ///< duplicate key, over-long space id
    uint32_t no_range;       ///< parsed lines without ID, or without DR and DB
    uint32_t unknown_beacon; ///< ranges from an ID not in the beacon table
    uint32_t bad_range;      ///< ranges <= 0 or beyond max_range_mm
    uint32_t ranges;         ///< ranges stored
    uint32_t bad_geometry;   ///< fixes refused: beacons too close to a line
    uint32_t inconsistent;   ///< fixes refused: ranges disagree (residual too large)
} cricket_stats_t;

typedef struct cricket_fix {
    float x_mm, y_mm;
    float residual_mm;       ///< RMS range residual of the solution
    uint8_t n_ranges;        ///< ranges used
    uint64_t oldest_us;      ///< time of the oldest range used
} cricket_fix_t;

// (Members ordered widest first: the 192 KiB paper-sim image has no byte to spare for padding.)
typedef struct cricket_range {
    uint64_t t_us;           ///< when the line arrived
    float range_mm;
    bool valid;
    bool from_dr;            ///< from the time of flight (else from DB)
} cricket_range_t;

typedef struct cricket {
    struct cricket_config cfg;
    cricket_range_t range[FW_CFG_CRICKET_MAX_BEACONS];
    uint64_t last_motion_us;
    cricket_stats_t stats;
    size_t len;
    bool overlong;           ///< the current line overflowed: discard up to its end
    bool garbage;            ///< the current line has a non-ASCII byte: discard it
    bool moved;              ///< cricket_note_motion was called
    char line[FW_CFG_CRICKET_LINE_MAX + 1];
} cricket_t;

/// Fills `cfg` with the defaults above (no beacons).
void cricket_default_config(struct cricket_config *cfg);

/// Starts a listener. Returns FW_OK or FW_ERR_INVAL (a config value out of its documented range,
/// fewer than 3 or too many beacons, or a beacon ID listed twice).
int cricket_init(cricket_t *ck, const struct cricket_config *cfg);

/// Feeds received bytes (any split: a line may arrive over many calls). Returns the number of
/// ranges stored. Xon/Xoff bytes are skipped; CR, LF and CR LF end a line.
size_t cricket_feed(cricket_t *ck, const uint8_t *bytes, size_t n, uint64_t now_us);

/// The robot moved (its wheels turned) at `now_us`: every range taken until then is marked as
/// taken before the motion. Call it every control period in which the robot moved.
void cricket_note_motion(cricket_t *ck, uint64_t now_us);

/// Computes the fix at `now_us` (see the states above). *out is written unless LOST.
cricket_fix_state_t cricket_get_fix(cricket_t *ck, uint64_t now_us, cricket_fix_t *out);

/// Parses one line (no line end) by key. Returns FW_OK or FW_ERR_INVAL (malformed).
int cricket_parse_line(const char *line, size_t len, cricket_line_t *out);

/// A beacon ID as the listener prints it: eight hex bytes separated by ':' ("01:2a:e4:8a:0b:00:00:ac"),
/// one or two digits each, first byte most significant. Returns FW_OK or FW_ERR_INVAL.
int cricket_parse_id(const char *s, size_t n, uint64_t *out);

#ifdef __cplusplus
}
#endif

#endif // DRIVERS_CRICKET_H
