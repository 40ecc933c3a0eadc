// SPDX-License-Identifier: MIT
// dynaqpc drivers: Cricket listener lines, beacon ranges and the position fix (see cricket.h).
//
// Why parse by key: the listener's fields can be switched on and off, and its firmware versions
// differ in what they print; the order is fixed but a parser that relies on positions breaks the
// day someone switches TM off. Why count and drop instead of guessing: a serial line picks up
// garbage when a cable is plugged in or the listener resets; one bad range pulls a fix by
// metres, while a dropped line costs one beacon period.
#include "drivers/cricket.h"

#include <string.h>

#include "drivers/trilat.h"
#include "fw/fw_base.h"
#include "fw/fw_util.h"

#define XON 0x11u
#define XOFF 0x13u
#define GN_ITERATIONS 8u

void cricket_default_config(struct cricket_config *cfg)
{
    FW_ASSERT(cfg != NULL);
    memset(cfg, 0, sizeof *cfg);
    cfg->speed_of_sound_m_s = 343.0f;
    cfg->db_unit_mm = 10.0f;
    cfg->max_range_mm = 10000.0f;
    cfg->max_line = FW_CFG_CRICKET_LINE_MAX;
    cfg->max_age_us = 3000000u;
    cfg->lost_age_us = 10000000u;
    cfg->min_spread_mm = 300.0f;
    cfg->max_residual_mm = 60.0f;
}

int cricket_init(cricket_t *ck, const struct cricket_config *cfg)
{
    FW_ASSERT(ck != NULL && cfg != NULL);
    if (cfg->beacons == NULL || cfg->n_beacons < 3u ||            // a fix needs 3 beacons
        cfg->n_beacons > FW_CFG_CRICKET_MAX_BEACONS ||            // one range slot each
        !(cfg->speed_of_sound_m_s > 100.0f && cfg->speed_of_sound_m_s < 1000.0f) ||
        !(cfg->db_unit_mm > 0.0f) || !(cfg->max_range_mm > 0.0f) ||
        cfg->max_line < 16u || cfg->max_line > FW_CFG_CRICKET_LINE_MAX ||
        cfg->max_age_us == 0u || cfg->lost_age_us < cfg->max_age_us ||  // stale before lost
        !(cfg->min_spread_mm >= 0.0f) || !(cfg->max_residual_mm > 0.0f)) {
        return FW_ERR_INVAL;
    }
    for (size_t i = 0; i < cfg->n_beacons; i++) {
        for (size_t j = i + 1u; j < cfg->n_beacons; j++) {
            if (cfg->beacons[i].id == cfg->beacons[j].id) {
                return FW_ERR_INVAL;
            }
        }
    }
    memset(ck, 0, sizeof *ck);
    ck->cfg = *cfg;
    return FW_OK;
}

// ---- Parser --------------------------------------------------------------------------------------

static int parse_u32(const char *s, size_t n, uint32_t *out)
{
    uint32_t v = 0u;
    if (n == 0u || n > 10u) {
        return FW_ERR_INVAL;
    }
    for (size_t i = 0; i < n; i++) {
        if (s[i] < '0' || s[i] > '9') {
            return FW_ERR_INVAL;
        }
        uint32_t d = (uint32_t)(s[i] - '0');
        if (v > (UINT32_MAX - d) / 10u) {
            return FW_ERR_INVAL;
        }
        v = v * 10u + d;
    }
    *out = v;
    return FW_OK;
}

/// Unsigned decimal with an optional fraction: "210", "210.5". No sign, no exponent.
static int parse_decimal(const char *s, size_t n, float *out)
{
    size_t dot = n;
    for (size_t i = 0; i < n; i++) {
        if (s[i] == '.') {
            dot = i;
            break;
        }
    }
    uint32_t whole = 0u, frac = 0u;
    if (parse_u32(s, dot, &whole) != FW_OK) {
        return FW_ERR_INVAL;
    }
    float value = (float)whole;
    if (dot < n) {
        size_t fn = n - dot - 1u;
        if (fn == 0u || fn > 6u || parse_u32(s + dot + 1u, fn, &frac) != FW_OK) {
            return FW_ERR_INVAL;
        }
        float scale = 1.0f;
        for (size_t i = 0; i < fn; i++) {
            scale *= 10.0f;
        }
        value += (float)frac / scale;
    }
    *out = value;
    return FW_OK;
}

int cricket_parse_id(const char *s, size_t n, uint64_t *out)
{
    uint64_t id = 0u;
    unsigned bytes = 0u;
    size_t i = 0;
    while (i < n) {
        unsigned v = 0u, digits = 0u;
        while (i < n && s[i] != ':') {
            int d = fw_hex_digit(s[i]);
            if (d < 0 || digits == 2u) {
                return FW_ERR_INVAL;
            }
            v = v * 16u + (unsigned)d;
            digits++;
            i++;
        }
        if (digits == 0u || bytes == 8u) {
            return FW_ERR_INVAL;
        }
        id = (id << 8) | v;
        bytes++;
        if (i < n) {
            i++;  // the ':'
            if (i == n) {
                return FW_ERR_INVAL;  // trailing ':'
            }
        }
    }
    if (bytes != 8u) {
        return FW_ERR_INVAL;
    }
    *out = id;
    return FW_OK;
}

static uint32_t field_of_key(const char *k, size_t n)
{
    static const char keys[][3] = {"VR", "ID", "SP", "DB", "DR", "TM", "TS"};
    if (n != 2u) {
        return 0u;
    }
    for (unsigned i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        if (k[0] == keys[i][0] && k[1] == keys[i][1]) {
            return 1u << i;
        }
    }
    return 0u;
}

int cricket_parse_line(const char *line, size_t len, cricket_line_t *out)
{
    FW_ASSERT(line != NULL && out != NULL);
    memset(out, 0, sizeof *out);
    size_t pos = 0;
    while (pos <= len) {
        size_t end = pos;
        while (end < len && line[end] != ',') {
            end++;
        }
        const char *f = line + pos;
        size_t fn = end - pos;
        size_t eq = 0;
        while (eq < fn && f[eq] != '=') {
            eq++;
        }
        if (eq == fn || eq == 0u) {
            return FW_ERR_INVAL;  // "KEY=VALUE" or nothing
        }
        const char *v = f + eq + 1u;
        size_t vn = fn - eq - 1u;
        uint32_t field = field_of_key(f, eq);
        if (field != 0u && (out->fields & field) != 0u) {
            return FW_ERR_INVAL;  // a key twice: which one is right?
        }
        int err = FW_OK;
        switch (field) {
        case CRICKET_FIELD_VR:
            err = vn > 0u ? FW_OK : FW_ERR_INVAL;
            break;
        case CRICKET_FIELD_ID:
            err = cricket_parse_id(v, vn, &out->id);
            break;
        case CRICKET_FIELD_SP:
            if (vn > FW_CFG_CRICKET_SPACE_MAX) {
                err = FW_ERR_INVAL;
            } else {
                memcpy(out->space, v, vn);
                out->space[vn] = '\0';
            }
            break;
        case CRICKET_FIELD_DB:
            err = parse_decimal(v, vn, &out->db);
            break;
        case CRICKET_FIELD_DR:
            err = parse_u32(v, vn, &out->dr_us);
            break;
        case CRICKET_FIELD_TM:
            err = parse_u32(v, vn, &out->tm);
            break;
        case CRICKET_FIELD_TS:
            err = parse_u32(v, vn, &out->ts);
            break;
        default:
            break;  // unknown key: ignored
        }
        if (err != FW_OK) {
            return FW_ERR_INVAL;
        }
        out->fields |= field;
        pos = end + 1u;
    }
    return FW_OK;
}

// ---- Ranges ----------------------------------------------------------------------------------------

static int beacon_index(const cricket_t *ck, uint64_t id)
{
    for (size_t i = 0; i < ck->cfg.n_beacons; i++) {
        if (ck->cfg.beacons[i].id == id) {
            return (int)i;
        }
    }
    return -1;
}

/// Returns 1 when a range was stored, else 0 (and counts why not).
static size_t take_line(cricket_t *ck, uint64_t now_us)
{
    cricket_line_t l;
    if (cricket_parse_line(ck->line, ck->len, &l) != FW_OK) {
        ck->stats.malformed++;
        return 0u;
    }
    ck->stats.lines++;
    if ((l.fields & CRICKET_FIELD_ID) == 0u ||
        (l.fields & (CRICKET_FIELD_DR | CRICKET_FIELD_DB)) == 0u) {
        ck->stats.no_range++;
        return 0u;
    }
    int b = beacon_index(ck, l.id);
    if (b < 0) {
        ck->stats.unknown_beacon++;
        return 0u;
    }
    bool from_dr = (l.fields & CRICKET_FIELD_DR) != 0u;
    // mm = µs * (m/s) * 1e-3 (1 m/s = 1e-3 mm/µs).
    float mm = from_dr ? (float)l.dr_us * ck->cfg.speed_of_sound_m_s * 1e-3f
                       : l.db * ck->cfg.db_unit_mm;
    if (!(mm > 0.0f) || mm > ck->cfg.max_range_mm) {
        ck->stats.bad_range++;
        return 0u;
    }
    cricket_range_t *r = &ck->range[b];
    r->range_mm = mm;
    r->t_us = now_us;
    r->valid = true;
    r->from_dr = from_dr;
    ck->stats.ranges++;
    return 1u;
}

size_t cricket_feed(cricket_t *ck, const uint8_t *bytes, size_t n, uint64_t now_us)
{
    FW_ASSERT(ck != NULL && (bytes != NULL || n == 0u));
    size_t stored = 0;
    for (size_t i = 0; i < n; i++) {
        uint8_t c = bytes[i];
        if (c == '\r' || c == '\n') {
            if (ck->overlong) {
                ck->stats.overlong++;
            } else if (ck->garbage) {
                ck->stats.garbage++;
            } else if (ck->len > 0u) {
                stored += take_line(ck, now_us);
            }
            ck->len = 0u;
            ck->overlong = false;
            ck->garbage = false;
        } else if (c == XON || c == XOFF) {
            continue;  // software flow control, not data
        } else if (c < 0x20u || c > 0x7Eu) {
            ck->garbage = true;
        } else if (ck->len < ck->cfg.max_line) {
            ck->line[ck->len++] = (char)c;
        } else {
            ck->overlong = true;
        }
    }
    return stored;
}

void cricket_note_motion(cricket_t *ck, uint64_t now_us)
{
    if (!ck->moved || now_us > ck->last_motion_us) {
        ck->last_motion_us = now_us;
    }
    ck->moved = true;
}

// ---- Fix -------------------------------------------------------------------------------------------

static uint64_t age_of(uint64_t t_us, uint64_t now_us)
{
    return now_us > t_us ? now_us - t_us : 0u;
}

static bool after_motion(const cricket_t *ck, const cricket_range_t *r)
{
    return !ck->moved || r->t_us > ck->last_motion_us;
}

// Why a fix from ranges at rest drops one range: a reflection, or one beacon's radio paired with
// another's ultrasound, gives a range too long by up to a metre (Priyantha et al., MobiCom 2000).
// A least-squares fit spreads such a range over the others, so a detour of 10-20 cm often keeps
// the residual under max_residual and moves the fix by as much: across a cell, and far enough
// for the application to call it a jump and stop trusting its heading. Ranges at rest that
// agree fit within CRICKET_CLEAN_SHARE * max_residual (20 mm against the Cricket's 1 cm); above
// it, the one range whose removal leaves the others agreeing that well is dropped, if exactly
// one does, else the fix is refused (the next beacon periods bring fresh ranges). Three ranges
// above it are refused. Measured on the realistic robot (docs/results/realistic-robot.md,
// "Relapses"): fixes more than 10 cm from the truth fell from 1.35 % to 0.24 %.
#define CRICKET_CLEAN_SHARE 0.34f
// Three ranges fit any one of them that is wrong (two unknowns, one range to spare, and the fit
// bends to it): at rest, a fix waits for a fourth range for up to this long after the motion
// when the room has more than three beacons.
#define CRICKET_FOURTH_WAIT_US 1500000u

static int without_outlier_(const trilat_anchor_t *all, size_t *n,
                            const struct trilat_params *params, trilat_result_t *out)
{
    struct trilat_params clean = *params;
    clean.max_residual = CRICKET_CLEAN_SHARE * params->max_residual;
    trilat_anchor_t sub[FW_CFG_CRICKET_MAX_BEACONS];
    unsigned agreeing = 0u;
    for (size_t k = 0; *n > 3u && k < *n; k++) {
        size_t m = 0;
        for (size_t i = 0; i < *n; i++) {
            if (i != k) {
                sub[m++] = all[i];
            }
        }
        trilat_result_t r;
        if (trilat_solve(sub, m, &clean, &r) == FW_OK) {
            agreeing++;
            *out = r;
        }
    }
    if (agreeing != 1u) {
        return FW_ERR_CORRUPT;
    }
    (*n)--;  // the fix's ranges
    return FW_OK;
}

/// Solves from the ranges that pass `fresh_only` (after the last motion and within max_age) or
/// else every range within lost_age. Returns the trilat_solve() result; counts refusals.
static int solve(cricket_t *ck, uint64_t now_us, bool fresh_only, cricket_fix_t *fix,
                 bool *any_before_motion, bool *any_old)
{
    trilat_anchor_t anchors[FW_CFG_CRICKET_MAX_BEACONS];
    size_t n = 0;
    uint64_t oldest = UINT64_MAX;
    *any_before_motion = false;
    *any_old = false;
    for (size_t i = 0; i < ck->cfg.n_beacons; i++) {
        const cricket_range_t *r = &ck->range[i];
        uint64_t age = age_of(r->t_us, now_us);
        if (!r->valid || age > ck->cfg.lost_age_us) {
            continue;
        }
        bool fresh = after_motion(ck, r) && age <= ck->cfg.max_age_us;
        if (fresh_only && !fresh) {
            continue;
        }
        *any_before_motion |= !after_motion(ck, r);
        *any_old |= age > ck->cfg.max_age_us;
        anchors[n].x = ck->cfg.beacons[i].x_mm;
        anchors[n].y = ck->cfg.beacons[i].y_mm;
        anchors[n].z = ck->cfg.beacons[i].z_mm;
        anchors[n].range = r->range_mm;
        oldest = r->t_us < oldest ? r->t_us : oldest;
        n++;
    }
    if (n < 3u || (fresh_only && n == 3u && ck->cfg.n_beacons > 3u && ck->moved &&
                   age_of(ck->last_motion_us, now_us) < CRICKET_FOURTH_WAIT_US)) {
        return FW_ERR_NOENT;
    }
    const struct trilat_params params = {
        .listener_z = ck->cfg.listener_z_mm,
        .min_spread = ck->cfg.min_spread_mm,
        .max_residual = ck->cfg.max_residual_mm,
        .iterations = GN_ITERATIONS,
    };
    trilat_result_t res;
    int err = trilat_solve(anchors, n, &params, &res);
    if (fresh_only && (err == FW_ERR_CORRUPT ||
                       (err == FW_OK && res.residual_rms > CRICKET_CLEAN_SHARE * params.max_residual))) {
        err = without_outlier_(anchors, &n, &params, &res);
    }
    if (err == FW_ERR_INVAL) {
        ck->stats.bad_geometry++;
    } else if (err == FW_ERR_CORRUPT) {
        ck->stats.inconsistent++;
    } else {
        fix->x_mm = res.x;
        fix->y_mm = res.y;
        fix->residual_mm = res.residual_rms;
        fix->n_ranges = (uint8_t)n;
        fix->oldest_us = oldest;
    }
    return err;
}

cricket_fix_state_t cricket_get_fix(cricket_t *ck, uint64_t now_us, cricket_fix_t *out)
{
    FW_ASSERT(ck != NULL && out != NULL);
    bool before_motion, old;
    const int fresh = solve(ck, now_us, true, out, &before_motion, &old);
    if (fresh == FW_OK) {
        return CRICKET_FIX_FRESH;
    }
    const bool fresh_refused = fresh == FW_ERR_CORRUPT;
    if (solve(ck, now_us, false, out, &before_motion, &old) != FW_OK) {
        return CRICKET_FIX_LOST;
    }
    if (before_motion) {
        return CRICKET_FIX_MOVING;
    }
    // All ranges after the motion; the fresh-only set failed, so some range is old (or the
    // fresh subset alone was refused and the old ones rescued it). Neither: the same ranges,
    // refused at rest for one that disagrees (without_outlier_()), are not a fresh fix.
    return old || fresh_refused ? CRICKET_FIX_STALE : CRICKET_FIX_FRESH;
}
