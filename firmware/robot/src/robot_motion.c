// SPDX-License-Identifier: MIT
// dynaqpc robot application: how the wheels carry out an action.
#include "robot/robot_motion.h"

#include <math.h>

#include "fw/fw_assert.h"
#include "fw/fw_util.h"

// Radians in [0, 2 pi).
static float wrap_2pi_(float a)
{
    a = fmodf(a, 2.0f * FW_PI_F);
    return a < 0.0f ? a + 2.0f * FW_PI_F : a;
}

// The signed turn from `heading` to the next multiple of `turn` counter-clockwise (left) or
// clockwise, skipping a multiple nearer than turn / 4: a robot standing 2 degrees short of a
// grid heading turns on to the one after it instead of creeping 2 degrees.
static float aligned_turn_(float heading, float turn, bool left)
{
    const float h = wrap_2pi_(heading) / turn;  // in turns
    const float k = left ? floorf(h + 0.25f) + 1.0f : ceilf(h - 0.25f) - 1.0f;
    return (k - h) * turn;
}

// Distance along `dir` (radians) from the pose to the edge of its cell, at most the cell's
// diagonal; *axis is the axis whose edge it meets first and *along dir's component on it.
static float edge_distance_(const robot_config_t *cfg, const robot_pose_t *pose, float dir, uint32_t *axis,
                            float *along)
{
    const float c = cosf(dir), s = sinf(dir);
    // The cell the state encodes (robot_grid_cell() also clamps a pose just outside the arena).
    float x0, cw, y0, ch;
    robot_grid_span(cfg, ROBOT_AXIS_X, robot_grid_cell(cfg, ROBOT_AXIS_X, pose->x), &x0, &cw);
    robot_grid_span(cfg, ROBOT_AXIS_Y, robot_grid_cell(cfg, ROBOT_AXIS_Y, pose->y), &y0, &ch);
    float tx = 1e9f, ty = 1e9f;
    if (c > 1e-3f) {
        tx = (x0 + cw - pose->x) / c;
    } else if (c < -1e-3f) {
        tx = (x0 - pose->x) / c;
    }
    if (s > 1e-3f) {
        ty = (y0 + ch - pose->y) / s;
    } else if (s < -1e-3f) {
        ty = (y0 - pose->y) / s;
    }
    *axis = ty < tx ? ROBOT_AXIS_Y : ROBOT_AXIS_X;
    *along = ty < tx ? s : c;
    // At least 0 (a pose on the edge), at most a cell's diagonal.
    return fminf(fmaxf(fminf(tx, ty), 0.0f), sqrtf(cw * cw + ch * ch));
}

// Whether an aligned step into a cell `side` wide along its axis stops at the cell's centre:
// centred actions, and a cell at least twice step_past_m wide (stop_beyond_() says why).
static bool stops_at_centre_(const robot_config_t *cfg, float side)
{
    return cfg->aligned_actions == ROBOT_ACTIONS_CENTRED && side >= 2.0f * cfg->step_past_m;
}

// How far beyond an edge at `edge_at` along `axis` a step moving towards `sign` (+1 or -1)
// stops: step_past_m, or with centred actions half the side of the cell it enters. A fitted
// cell narrower than step_past_m lies inside a partition and is stepped over, as step_past_m
// steps over it; so are two or more such cells in a row (where one partition's face cuts
// another's thickness, at a T or an L), so that the stop is the next real cell's. A cell
// narrower than twice step_past_m has no centre that clear of both faces:
// it keeps the stop step_past_m past the edge crossed (in a users' room, a 0.48 m doorway cut in
// two by another partition's face learned in 2 of 10 sets with centres, 8 with that stop).
static float stop_beyond_(const robot_config_t *cfg, uint32_t axis, float edge_at, float sign)
{
    if (cfg->aligned_actions != ROBOT_ACTIONS_CENTRED) {
        return cfg->step_past_m;
    }
    const uint32_t cells = robot_grid_cells(cfg, axis);
    float beyond = 0.0f, lo = 0.0f, side = 0.0f;
    uint32_t k = robot_grid_cell(cfg, axis, edge_at + sign * 1e-4f);
    robot_grid_span(cfg, axis, k, &lo, &side);
    while (side < cfg->step_past_m && k > 0u && k + 1u < cells) {  // at most `cells` times
        beyond += side;
        k = sign > 0.0f ? k + 1u : k - 1u;
        robot_grid_span(cfg, axis, k, &lo, &side);
    }
    return beyond + (stops_at_centre_(cfg, side) ? 0.5f * side : cfg->step_past_m);
}

// Distance along `dir` (radians) from the pose to where an aligned step that way stops, in the
// next cell.
static float aligned_step_(const robot_config_t *cfg, const robot_pose_t *pose, float dir)
{
    uint32_t axis = ROBOT_AXIS_X;
    float along = 0.0f;
    const float t = edge_distance_(cfg, pose, dir, &axis, &along);
    const float edge_at = (axis == ROBOT_AXIS_X ? pose->x : pose->y) + t * along;
    return t + stop_beyond_(cfg, axis, edge_at, along > 0.0f ? 1.0f : -1.0f);
}

// Distance along `dir` (radians) from the pose to the edge of its cell. For stops step_past_m
// beyond the edge it is the step's distance less that margin: the arithmetic those stops were
// measured with, bit for bit.
static float to_edge_(const robot_config_t *cfg, const robot_pose_t *pose, float dir)
{
    uint32_t axis = ROBOT_AXIS_X;
    float along = 0.0f;
    if (cfg->aligned_actions == ROBOT_ACTIONS_CENTRED) {
        return edge_distance_(cfg, pose, dir, &axis, &along);
    }
    return aligned_step_(cfg, pose, dir) - cfg->step_past_m;
}

// Where along an axis of its cell, `behind` from the edge behind and `ahead` from the edge
// ahead, an aligned step leaves the robot: the nearer of its two stops step_past_m from either
// edge, or the centre (of a cell at least twice step_past_m wide).
static float stop_in_cell_(const robot_config_t *cfg, float behind, float ahead)
{
    const float len = behind + ahead;
    if (stops_at_centre_(cfg, len)) {
        return 0.5f * len;
    }
    return behind < 0.5f * len ? cfg->step_past_m : len - cfg->step_past_m;
}

// Shorter drives and turns than these are not worth a motion: the pose is already there.
#define MIN_DRIVE_M 0.01f
#define MIN_TURN_RAD 1e-3f

// Periods for a motion `ratio` times the fixed action's length: never faster than the fixed
// action (a turn must also stay inside the gyro's measuring range, which it was sized for).
static uint8_t periods_for_(const robot_config_t *cfg, float ratio)
{
    const float periods = ceilf(ratio * (float)cfg->action_periods - 1e-3f);
    return (uint8_t)(periods < 1.0f ? 1.0f : periods > 255.0f ? 255.0f : periods);
}

// Driving `d` metres (negative: backward) in `periods` control periods.
static robot_motion_t drive_motion_(const robot_config_t *cfg, float d, uint8_t periods)
{
    const float v = d / ((float)periods * ((float)cfg->period_us * 1e-6f));
    return (robot_motion_t){v, v, periods};
}

// Turning `turn` radians in place (positive: counter-clockwise, left) in `periods` control
// periods: each wheel travels turn * track / 2.
static robot_motion_t turn_motion_(const robot_config_t *cfg, float turn, uint8_t periods)
{
    const float w = fabsf(turn) * cfg->track_m * 0.5f / ((float)periods * ((float)cfg->period_us * 1e-6f));
    return turn > 0.0f ? (robot_motion_t){-w, w, periods} : (robot_motion_t){w, -w, periods};
}

bool robot_backs_off(const robot_config_t *cfg)
{
    return ROBOT_BUMP_BACKOFF != 0 && (!cfg->aligned_actions || cfg->track_m < robot_grid_min_side(cfg));
}

// Why back off: a bump leaves the robot wherever the contact stopped it, and until it has stepped
// along both axes again its offset in the cell is one that aligned steps never leave. Whether a
// step along a wall bumps, and what the rangers read, depend on that offset, which the state does
// not show: in the lab robot's far-goal rooms, steps from such offsets bumped 3 to 9 times as
// often as the others, and one unlucky bump could close a passage for good (docs/results/lab-motion.md).
// Backing off to where an aligned step into the cell stops restores the offset along the step.
robot_motion_t robot_backoff_motion(const robot_config_t *cfg, uint8_t action, float heading,
                                    const robot_pose_t *pose)
{
    robot_motion_t m = {0.0f, 0.0f, 0u};
    if (action != ROBOT_FORWARD && action != ROBOT_BACKWARD) {
        return m;
    }
    const bool forward = action == ROBOT_FORWARD;
    if (!cfg->aligned_actions) {
        // Fixed steps have no stop to go back to: half a step back clears a turn in place of the
        // wall it met, where the robot stood against it and bumped again turning away. On
        // paper-lab-motion's tuning sets (docs/results/paper-motion.md) 9 of 24 learned, 7 with
        // the back-off alone and 16 with it and the start's heading settled; backing off 0.04 to
        // 0.25 m learned 11-16.
        const float d = 0.5f * cfg->step_m;
        return drive_motion_(cfg, forward ? -d : d, periods_for_(cfg, 0.5f));
    }
    // How far back along the step the edge of the pose's cell lies; the stop is where a step
    // into the cell along it ends (step_past_m past that edge, or the centre).
    const float back = heading + (forward ? FW_PI_F : 0.0f);
    const float behind = to_edge_(cfg, pose, back);
    const float len = behind + to_edge_(cfg, pose, back + FW_PI_F);
    const float d = behind - (stops_at_centre_(cfg, len) ? 0.5f * len : cfg->step_past_m);
    if (!(d > MIN_DRIVE_M)) {
        return m;
    }
    // The way the step came: backward after a forward step.
    return drive_motion_(cfg, forward ? -d : d, periods_for_(cfg, d / cfg->step_m));
}

// Whether a whole number of turns makes a full circle: the headings fixed turns reach from a
// multiple of turn_rad are then that circle's, and a heading sector can be centred on each.
static bool turns_divide_circle_(const robot_config_t *cfg)
{
    const float n = 2.0f * FW_PI_F / cfg->turn_rad;
    return fabsf(n - roundf(n)) < 1e-3f;
}

bool robot_settles(const robot_config_t *cfg)
{
    if (!cfg->aligned_actions) {
        // Fixed turns keep whatever heading a start gave, between two sectors' centres; facing a
        // multiple of the turn first puts every later heading on one (only the heading settles:
        // fixed steps have no stops to settle onto).
        return ROBOT_START_SETTLE != 0 && turns_divide_circle_(cfg);
    }
    // Headings a quarter turn apart, so that the grid of stops is one of cells' sides.
    return ROBOT_START_SETTLE != 0 && robot_backs_off(cfg) && fabsf(cfg->turn_rad - 0.5f * FW_PI_F) < MIN_TURN_RAD;
}

// The signed distance along `dir` from the pose to the nearer of the two offsets in its cell at
// which an aligned step along that axis stops (step_past_m past the edge behind, or short of the
// edge ahead); 0 when it is there already.
static float settle_distance_(const robot_config_t *cfg, const robot_pose_t *pose, float dir)
{
    const float ahead = to_edge_(cfg, pose, dir);
    const float behind = to_edge_(cfg, pose, dir + FW_PI_F);
    const float d = stop_in_cell_(cfg, behind, ahead) - behind;
    return fabsf(d) > MIN_DRIVE_M ? d : 0.0f;
}

// Why settle: a start leaves the robot anywhere in its first cell, facing anywhere, and until it
// has stepped along both axes its offsets are ones aligned steps never leave. After the back-off
// restored a bumped step's offset, starts were what remained of those offsets: settling took the
// lab robot's far-goal tuning rooms from 346 to 354 of 360 sets (docs/results/lab-motion.md).
robot_motion_t robot_settle_motion(const robot_config_t *cfg, uint8_t phase, const robot_pose_t *pose)
{
    FW_ASSERT(cfg != NULL && pose != NULL);
    robot_motion_t m = {0.0f, 0.0f, 0u};
    if (!cfg->aligned_actions && phase != ROBOT_SETTLE_FACE_GRID) {
        return m;  // fixed steps: only the heading settles (robot_settles())
    }
    const float h = wrap_2pi_(pose->heading) / cfg->turn_rad;  // in grid turns
    const float misaligned = (roundf(h) - h) * cfg->turn_rad;  // to the nearest grid heading
    float turn = 0.0f, d = 0.0f;
    switch (phase) {
    case ROBOT_SETTLE_FACE_GRID:
        turn = misaligned;
        break;
    case ROBOT_SETTLE_ALONG:
    case ROBOT_SETTLE_ACROSS:  // after the quarter turn, along the heading again
        d = settle_distance_(cfg, pose, pose->heading);
        break;
    case ROBOT_SETTLE_QUARTER_LEFT:
        if (settle_distance_(cfg, pose, pose->heading + 0.5f * FW_PI_F) != 0.0f) {
            turn = misaligned + 0.5f * FW_PI_F;
        }
        break;
    default:
        break;
    }
    if (fabsf(turn) > MIN_TURN_RAD) {
        return turn_motion_(cfg, turn, periods_for_(cfg, fabsf(turn) / cfg->turn_rad));
    }
    if (d != 0.0f) {
        return drive_motion_(cfg, d, periods_for_(cfg, fabsf(d) / cfg->step_m));
    }
    return m;
}

robot_motion_t robot_action_motion(const robot_config_t *cfg, uint8_t action, const robot_pose_t *pose)
{
    FW_ASSERT(cfg != NULL && pose != NULL);
    float dist = cfg->step_m, turn = cfg->turn_rad;
    uint8_t periods = cfg->action_periods;
    if (cfg->aligned_actions) {
        // Never faster than the fixed action: a longer step or turn takes more periods (a turn
        // must also stay inside the gyro's measuring range, which the fixed turn was sized for).
        float ratio = 1.0f;  // of this motion to the fixed one
        switch (action) {
        case ROBOT_FORWARD:
        case ROBOT_BACKWARD:
            dist = aligned_step_(cfg, pose, pose->heading + (action == ROBOT_BACKWARD ? FW_PI_F : 0.0f));
            ratio = dist / cfg->step_m;
            break;
        case ROBOT_TURN_LEFT:
        case ROBOT_TURN_RIGHT:  // both positive: the cases below give the direction
            turn = fabsf(aligned_turn_(pose->heading, cfg->turn_rad, action == ROBOT_TURN_LEFT));
            ratio = turn / cfg->turn_rad;
            break;
        default:
            break;
        }
        periods = periods_for_(cfg, ratio);
    }
    switch (action) {
    case ROBOT_FORWARD: return drive_motion_(cfg, dist, periods);
    case ROBOT_BACKWARD: return drive_motion_(cfg, -dist, periods);
    case ROBOT_TURN_LEFT: return turn_motion_(cfg, turn, periods);
    case ROBOT_TURN_RIGHT: return turn_motion_(cfg, -turn, periods);
    default: return (robot_motion_t){0.0f, 0.0f, periods};
    }
}

// ---- Closed loop --------------------------------------------------------------------------------

// How much of what one motion measured goes into the trim and the turn gain: a gain mismatch is
// the robot's own and stays, a command's noise is not and averages out.
#define RUN_LEARN_RATE 0.3f
// The trim and the turn gain stay within what a working robot could need.
#define RUN_TRIM_MAX 0.3f
#define RUN_TURN_GAIN_MIN 0.7f
#define RUN_TURN_GAIN_MAX 1.3f

bool robot_closes_loop(const robot_config_t *cfg)
{
    return ROBOT_CLOSED_LOOP != 0 && cfg->pose_source == ROBOT_POSE_CRICKET;
}

void robot_run_init(robot_run_t *r)
{
    FW_ASSERT(r != NULL);
    *r = (robot_run_t){0};
    r->turn_gain = 1.0f;
}

// Radians in (-pi, pi].
static float wrap_pi_(float a)
{
    a = wrap_2pi_(a);
    return a > FW_PI_F ? a - 2.0f * FW_PI_F : a;
}

static float period_s_(const robot_config_t *cfg)
{
    return (float)cfg->period_us * 1e-6f;
}

// The heading a drive holds: the nearest grid heading when it is within an eighth of a turn of
// one and the grid is one of quarter turns (robot_settles(): the robot keeps to it), else `hold`.
static float drive_hold_(const robot_config_t *cfg, float hold)
{
    if (!robot_settles(cfg)) {
        return hold;
    }
    const float k = roundf(wrap_2pi_(hold) / cfg->turn_rad);
    const float grid = k * cfg->turn_rad;
    return fabsf(wrap_pi_(grid - hold)) < 0.25f * cfg->turn_rad ? grid : hold;
}

// The next period of a drive along r->m's speed: the differential turns the robot back onto its
// heading over the periods left, and the trim cancels the wheels' mismatch.
static void drive_period_(robot_run_t *r, const robot_config_t *cfg, float heading, float *vl, float *vr)
{
    const float t = period_s_(cfg);
    const float w = wrap_pi_(r->hold - heading) / ((float)r->periods_left * t);
    const float v = 0.5f * (r->m.v_left + r->m.v_right);
    const float h = 0.5f * cfg->track_m;
    r->commanded_turn += w * t;
    *vl = v * (1.0f - r->trim) - w * h;
    *vr = v * (1.0f + r->trim) + w * h;
}

// A turn at `w` rad/s (as an exact robot would turn at these wheel speeds... before the gain).
static void turn_period_(robot_run_t *r, const robot_config_t *cfg, float w, float *vl, float *vr)
{
    const float wc = w / r->turn_gain;
    r->commanded_turn += wc * period_s_(cfg);
    *vr = wc * 0.5f * cfg->track_m;
    *vl = -*vr;
}

static bool is_turn_(const robot_motion_t *m)
{
    return m->v_left != m->v_right;
}

void robot_run_start(robot_run_t *r, const robot_config_t *cfg, const robot_motion_t *m, float heading,
                     float hold, float odom, bool odom_ok, float *vl, float *vr)
{
    FW_ASSERT(r != NULL && cfg != NULL && m != NULL);
    r->m = *m;
    r->turn = is_turn_(m);
    r->periods_left = m->periods;
    r->corrections = 0u;
    r->start_heading = heading;
    r->odom0 = odom;
    r->odom_ok = odom_ok;
    r->commanded_turn = 0.0f;
    const float t = period_s_(cfg) * (float)m->periods;
    if (r->turn) {
        const float w = (m->v_right - m->v_left) / cfg->track_m;  // an exact robot's turn rate
        r->hold = heading + w * t;
        r->dist = 0.0f;
        turn_period_(r, cfg, w, vl, vr);
    } else {
        r->hold = drive_hold_(cfg, hold);
        r->dist = 0.5f * (m->v_left + m->v_right) * t;
        drive_period_(r, cfg, heading, vl, vr);
    }
}

bool robot_run_period(robot_run_t *r, const robot_config_t *cfg, float heading, float odom, float *vl, float *vr)
{
    FW_ASSERT(r != NULL && cfg != NULL && vl != NULL && vr != NULL);
    (void)odom;  // a drive's distance is checked when it stands (robot_run_t)
    if (r->periods_left > 0u) {
        r->periods_left--;
    }
    if (r->periods_left == 0u) {
        return false;
    }
    if (is_turn_(&r->m)) {
        // The rest of the turn as commanded: mid-turn the gyro lags what the turn still does.
        turn_period_(r, cfg, (r->m.v_right - r->m.v_left) / cfg->track_m, vl, vr);
    } else {
        drive_period_(r, cfg, heading, vl, vr);
    }
    return true;
}

// What the planned motion that just ended says about the robot's wheels.
static void learn_(robot_run_t *r, const robot_config_t *cfg, float heading, float odom)
{
    const float turned = wrap_pi_(heading - r->start_heading);
    if (r->turn) {
        if (fabsf(r->commanded_turn) > 0.3f) {
            const float k = turned / r->commanded_turn;  // the gyro's turn per commanded turn
            if (k > RUN_TURN_GAIN_MIN && k < RUN_TURN_GAIN_MAX) {
                r->turn_gain += RUN_LEARN_RATE * (k - r->turn_gain);
            }
        }
        return;
    }
    const float d = r->odom_ok ? odom - r->odom0 : r->dist;
    if (fabsf(d) > 0.05f) {
        // The turn the commands did not ask for, as the share of the speed by which the wheels
        // differ: what is left of the mismatch after the trim.
        const float left = (turned - r->commanded_turn) * cfg->track_m / (2.0f * d);
        r->trim = fminf(fmaxf(r->trim - RUN_LEARN_RATE * left, -RUN_TRIM_MAX), RUN_TRIM_MAX);
    }
}

bool robot_run_correction(robot_run_t *r, const robot_config_t *cfg, float heading, float odom, bool learn,
                          float *vl, float *vr)
{
    if (r->corrections == 0u && learn) {
        learn_(r, cfg, heading, odom);
    }
    if (r->corrections >= ROBOT_RUN_MAX_CORRECTIONS) {
        return false;
    }
    const float e = wrap_pi_(r->hold - heading);
    const float t = period_s_(cfg);
    float rest = 0.0f;
    if (fabsf(e) > ROBOT_RUN_HEADING_TOL) {
        r->m = turn_motion_(cfg, e, 1u);
        r->periods_left = 1u;
        r->corrections++;
        turn_period_(r, cfg, e / t, vl, vr);
        return true;
    }
    if (!r->turn && r->odom_ok) {
        rest = r->dist - (odom - r->odom0);
    }
    if (fabsf(rest) > ROBOT_RUN_DIST_TOL) {
        r->m = drive_motion_(cfg, rest, 1u);
        r->periods_left = 1u;
        r->corrections++;
        drive_period_(r, cfg, heading, vl, vr);
        return true;
    }
    return false;
}
