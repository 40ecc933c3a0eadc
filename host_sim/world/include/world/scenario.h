// SPDX-License-Identifier: MIT
// dynaqpc world: a scenario (arena, robot, sensors, task parameters) and its text file format.
//
// The format, every key, unit and default: docs/scenarios.md. Units are SI (m, s, kg, rad inside
// this struct; the file writes angles in degrees and the Cricket intervals in ms).
// Coordinates: the arena spans [0, width] x [0, height], x to the right, y up; headings are
// counter-clockwise from +x; the robot's body frame has +x forward and +y to the robot's left.
#ifndef WORLD_SCENARIO_H
#define WORLD_SCENARIO_H

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace world {

/// Limits, so that no file can make the parser or the world grow without bound.
inline constexpr int kMaxObstacles = 256;
inline constexpr int kMaxRays = 64;
inline constexpr int kMaxCodeBits = 16;
inline constexpr int kMaxBeacons = 16;
inline constexpr std::size_t kMaxFileBytes = 1u << 20;
inline constexpr std::size_t kMaxLineBytes = 1024;

struct Obstacle {
    enum class Shape { Box, Circle };
    Shape shape = Shape::Box;
    double cx = 0.0, cy = 0.0;  ///< centre, m
    double w = 0.0, h = 0.0;    ///< box: size along its own x and y before rotation, m
    double angle = 0.0;         ///< box: rotation, rad, counter-clockwise
    double radius = 0.0;        ///< circle: radius, m
    int line = 0;               ///< line of the scenario file that defined it
};

struct Goal {
    double cx = 0.0, cy = 0.0, radius = 0.0;  ///< reached when the robot's centre is inside
    /// `goal ... cells`: reached when the robot's centre is in a cell of the state grid whose
    /// centre is inside the circle (see in_goal()).
    bool cells = false;
};

/// A differential-drive robot: a rectangle centred on the wheel axle's midpoint.
struct RobotSpec {
    double length = 0.0;      ///< along the body's x (forward), m
    double width = 0.0;       ///< along the body's y, m
    double mass = 5.0;        ///< kg
    double track = 0.0;       ///< distance between the wheels' contact points, m
    double max_speed = 2.0;   ///< largest wheel speed the controller accepts, m/s
    double max_accel = 60.0;  ///< wheel speed controller's slew limit, m/s^2
    double friction = 0.3;    ///< Coulomb friction of the body against walls and obstacles
};

/// One range sensor: where it sits on the body and where it looks.
struct Ray {
    double angle = 0.0;  ///< direction in the body frame, rad (0 = forward, + = left)
    double x = 0.0;      ///< mounting point in the body frame, m (default: on the outline)
    double y = 0.0;
};

struct RangerSpec {
    enum class Kind { Sonar, Ir };
    Kind kind = Kind::Sonar;
    double min_range = 0.0;   ///< m; closer hits read min_range
    double max_range = 0.0;   ///< m; nothing within it reads exactly max_range, without noise
    double noise_prop = 0.0;  ///< sd of the noise per metre of range (proportional part)
    double noise_sd = 0.0;    ///< sd of the noise, m (constant part)
    std::vector<Ray> rays;    ///< in file order; ray i is reading i
};

/// One bit of the sensor code: set when the smallest reading among `rays` is below `threshold`.
struct CodeBit {
    double threshold = 0.0;  ///< m
    std::vector<int> rays;   ///< indices into RangerSpec::rays
    int line = 0;            ///< line of the scenario file that defined it
};

struct GyroSpec {
    double bias = 0.0;      ///< rad/s, constant
    double noise_sd = 0.0;  ///< rad/s, per reading
    /// The gyro's scale factor error: drawn once per World, uniform in [1 - scale, 1 + scale],
    /// multiplying the true rate (0: exact).
    double scale = 0.0;
};

/// How the motors carry out the wheel speed targets (`actuation`, docs/scenarios.md). Without the
/// line the robot is exact: each wheel runs at exactly its target.
struct ActuationSpec {
    bool enabled = false;  ///< the scenario has an `actuation` line
    /// Each wheel's gain is drawn once per World (once per set in `train`), uniform in
    /// [1 - gain, 1 + gain]: the wheel runs at gain x its target.
    double gain = 0.0;
    /// Each motor command's target of each wheel is multiplied by 1 + noise x N(0, 1), drawn per
    /// command and wheel.
    double noise = 0.0;
    /// m/s: a wheel whose target (after gain and noise) is smaller than this does not turn (the
    /// motor's static friction: it stalls below its breakaway torque).
    double deadband = 0.0;
    /// Tyre friction coefficient against the floor: the wheels' sideways grip is limited to
    /// slip_mu x the robot's weight (0: no limit, the ideal no-slip tyres).
    double slip_mu = 0.0;
};

struct GpsSpec {
    bool enabled = false;     ///< the scenario has a `gps` line
    double xy_sd = 0.0;       ///< m, per axis
    double heading_sd = 0.0;  ///< rad
};

struct Beacon {
    std::string id;  ///< 8 hex bytes as the listener prints them, e.g. "1:5e:3c:3c:a:0:0:ba"
    double x = 0.0, y = 0.0, z = 0.0;  ///< m; z is the height above the floor
};

struct CricketSpec {
    std::vector<Beacon> beacons;    ///< none: the scenario has no Cricket system
    std::string space = "DYNAQPC";  ///< the SP field
    double min_interval = 0.668;    ///< s, between two transmissions of one beacon
    double max_interval = 1.332;    ///< s
    double noise_sd = 0.01;         ///< m, on each range
    double listener_height = 0.1;   ///< m, the listener's height above the floor
    double speed_of_sound = 343.0;  ///< m/s, turns ranges into the DR time of flight
    /// Share of transmissions the listener misses (no line): a beacon blocked or out of its cone.
    double dropout = 0.0;
    /// Share of lines whose range is a reflection's: longer than the true range by a distance
    /// uniform in (0, outlier_max].
    double outlier = 0.0;
    double outlier_max = 1.0;  ///< m
};

struct Timing {
    double control_period = 0.192;  ///< s
    double physics_dt = 0.016;      ///< s; control_period is a whole number of them
    int substeps = 12;              ///< control_period / physics_dt, computed by the parser
};

struct SolverSpec {
    int velocity_iterations = 8;
    int position_iterations = 3;
};

struct StartSpec {
    double margin = 0.05;  ///< m of free space beyond the robot's circumscribed circle
};

/// The firmware's state encoding (bits per component); the world only carries it.
struct Encoding {
    int x_bits = 5, y_bits = 5, heading_bits = 4;
    int sensor_bits = 0;  ///< = code_bits.size()
    /// `encode auto`: the x and y cells are fitted to the room (fit_grid()); x_bits and y_bits
    /// then hold the bits their counts need. Otherwise 2^bits equal cells along each side.
    bool fitted = false;
    /// `encode auto cell M`: the largest cell side (m); 0: the robot's (fit_cell_side()).
    double max_cell = 0.0;
    /// fitted: cell k along x spans [x_edges[k], x_edges[k + 1]); from 0 to the arena's side
    std::vector<double> x_edges, y_edges;
    /// fitted: rule 7 of the fit (grid_fit.h) moved the cell side from `from` to `to` (m), because
    /// `stranded` of the `stops` at `from` reached no goal stop; `to` 0 and `from` the side when it
    /// tried every side and none freed them all; all 0 when it did not try.
    struct WalkRefit {
        double from = 0.0, to = 0.0;
        long stranded = 0, stops = 0;
    } walk_refit;
};

struct ActionSpec {
    double step = 0.25;                         ///< m, forward/backward travel per action
    double turn = 0.78539816339744830962;       ///< rad, turn per action (45 degrees)
    int aligned = 0;  ///< 1: turns end on multiples of `turn`, steps just past the next cell edge
    double past = 0.0;  ///< m an aligned step ends past the cell edge; if not given, the parser sets a fifth of the smaller cell side
    /// `stop`: where an aligned step stops in the cell it enters: "past" (`past` beyond the edge),
    /// "centre", or "auto" (the default): the centre on a fitted grid (`encode auto`) whose cells
    /// the robot turns inside, else `past` (docs/scenarios.md, "Where a step stops").
    std::string stop = "auto";
    bool centred = false;  ///< the parser's verdict: aligned steps stop at cell centres
};

struct Rewards {
    double bump = -100.0, goal = 100.0, step = -1.0;
};

struct Learning {
    /// `gamma auto` (kGammaFromRoom, the default): the firmware sets the discount and the sweep
    /// threshold from the room (robot_config_agent_params()); a number: that discount and the
    /// paper's threshold (the paper's mode: gamma 0.9).
    static constexpr double kGammaFromRoom = -1.0;
    double epsilon = 0.1, alpha = 0.9, gamma = kGammaFromRoom;
    int planning = 0;  ///< 0: as many as the MCU's idle time allows (the firmware's default)
    /// How the robot explores: "egreedy" (the default), "plan-bonus" (Dyna-Q+) or "act-bonus"
    /// (agent/explore.h); kappa scales the bonus kappa * sqrt(steps untried).
    std::string explore = "egreedy";
    double kappa = 0.0;
    int step_cap = 200;
    int sets = 5;
    int episodes = 20;
    /// Dyna-QPC's world model: "relocatable" (ours, the default) or "paper" (the paper's
    /// CMAC-Model and CMAC-R, docs/agent.md).
    std::string model = "relocatable";
    /// With the paper's model: the CMACs' tile width of x, y, heading and the range code as powers
    /// of two (`tiles 1,1,0,0`: x and y two cells wide); empty: the firmware's default.
    std::vector<int> model_tiles;
};

/// A parsed, validated scenario. Plain data: copy it freely.
struct Scenario {
    std::string name;  ///< the file's stem, e.g. "paper-sim"
    std::string path;  ///< the file it came from ("" when parsed from text)
    double arena_w = 0.0, arena_h = 0.0;  ///< m; walls surround it
    std::vector<Obstacle> obstacles;
    Goal goal;
    RobotSpec robot;
    RangerSpec ranger;
    std::vector<CodeBit> code_bits;
    ActuationSpec actuation;
    GyroSpec gyro;
    GpsSpec gps;
    CricketSpec cricket;
    Timing timing;
    SolverSpec solver;
    StartSpec start;
    Encoding encoding;
    ActionSpec actions;
    Rewards rewards;
    Learning learning;
};

/// Parses scenario text (any bytes). `file` names it in error messages.
/// Returns true with *out filled in, or false with *error = "<file>:<line>: <problem>" (for a
/// problem of the whole file, such as a missing key, the line is the file's last line).
/// Never throws on bad input.
bool parse_scenario(std::string_view text, const std::string &file, Scenario *out,
                    std::string *error);

/// Whether `changed` is a change of `base`'s room that a robot can meet during a run (`train
/// --change-at K --changed FILE`, docs/scenarios.md "Rooms that change"): only the obstacles may
/// differ. The floor, the goal (the firmware is given it), the robot, its sensors and pose
/// source, timing, solver, start margin, encoding, actions, rewards and learning (except the
/// protocol's sets and episodes) must be the same. Returns "" if so, else what differs, e.g.
/// "the goal differs (only obstacles may change)".
std::string layout_change_problem(const Scenario &base, const Scenario &changed);

/// The path a scenario argument names: a bare name without '/' and without ".scn" that matches a
/// shipped scenario ("paper-sim", "paper-lab", their "-motion" and "-real" variants) gives host_sim/scenarios/<name>.scn of this
/// source tree; anything else is returned unchanged as a path.
std::string resolve_scenario_path(const std::string &name_or_path);

/// resolve_scenario_path, read (at most kMaxFileBytes), parse_scenario. Errors as parse_scenario,
/// or "<path>: cannot open: <reason>" / "<path>: file too large".
bool load_scenario(const std::string &name_or_path, Scenario *out, std::string *error);

/// Cells of the state grid along x (axis 0) or y (axis 1): 2^bits, or the fitted count.
int grid_cells(const Scenario &s, int axis);
/// The cell along `axis` holding v, clamped to the edge cells as the firmware's encoder does.
int grid_cell(const Scenario &s, int axis, double v);
/// Where cell k along `axis` lies: [*lo, *hi), m.
void grid_span(const Scenario &s, int axis, int k, double *lo, double *hi);
/// The largest cell side along `axis`, m.
double grid_max_side(const Scenario &s, int axis);

/// Whether a robot centred at (x, y) is in the goal: inside the circle, or with `goal ... cells`
/// in a cell of the state grid (the encoding's x and y bits over the arena) whose centre is.
/// The firmware's robot_in_goal() computes the same in single precision.
bool in_goal(const Scenario &s, double x, double y);

/// An axis-aligned cell of the state grid, m.
struct CellBox {
    double x0, y0, x1, y1;
};

/// The cells of the state grid whose centres are inside the goal circle (what `goal ... cells`
/// makes the goal), whether or not the scenario says `cells`.
std::vector<CellBox> goal_cells(const Scenario &s);

/// "1,1,0,0": the paper's model's tile widths (powers of two, 0..4) of x, y, heading and the
/// range code, into `out`. False, with `problem` saying why, for another text.
bool parse_model_tiles(const std::string &text, std::vector<int> *out, std::string *problem);

/// The distance from (x, y) to the nearest of goal_cells(): 0 inside one, infinity when there
/// are none.
double goal_cells_distance(const Scenario &s, double x, double y);

/// How close any cell centre comes to the goal circle itself (|distance − radius|, m): where it
/// is tiny, double and the firmware's float can disagree about that cell.
double goal_cell_centre_margin(const Scenario &s);

/// The radius of the robot's circumscribed circle (half its diagonal), m.
double robot_radius(const RobotSpec &robot);

/// Signed distance from (x, y) to one obstacle's surface, m (negative inside it).
double obstacle_distance(const Obstacle &o, double x, double y);

/// Distance from (x, y) to the nearest of the arena's walls, m (negative outside the arena).
double wall_distance(const Scenario &s, double x, double y);

/// Distance from (x, y) to the nearest wall or obstacle surface, m (negative inside one).
double clearance(const Scenario &s, double x, double y);

/// True if a robot centred at (x, y), at any heading, keeps `margin` of clearance and its centre
/// is outside the goal: a valid start position.
bool start_position_ok(const Scenario &s, double x, double y);

/// The grid on which the parser proves there is room for a start pose (and World falls back to
/// when random draws keep missing): 2 cm, coarser in arenas above 20 m so that it has at most
/// 1000 x 1000 points. Cell centres are (step/2 + i*step, step/2 + j*step).
double start_grid_step(const Scenario &s);

/// The sensor code of a set of readings (one per ray): bit i = CodeBit i.
std::uint32_t sensor_code(const Scenario &s, const float *ranges);

/// A code bit that can never change: every reading lies in [min, max] of the ranger, so a
/// threshold above `max` is always passed (the bit always set) and one at or below `min` never
/// (compared in single precision, as the firmware compares).
struct ConstantCodeBit {
    int bit = 0, line = 0;
    bool always = false;  ///< always set; else never set
};
std::vector<ConstantCodeBit> constant_code_bits(const Scenario &s);
/// What to tell a user of it, after "<file>:<line>: warning: ": "code_bit 0.4 (bit 0) is always
/// set: its rays read 0.04 to 0.3 m ...", and what threshold to give.
std::string constant_code_bit_warning(const Scenario &s, const ConstantCodeBit &c);

}  // namespace world

#endif  // WORLD_SCENARIO_H
