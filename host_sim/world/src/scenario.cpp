// SPDX-License-Identifier: MIT
// dynaqpc world: the scenario file parser.
//
// Why a parser of our own rather than a general format (INI, YAML, JSON): a scenario is a short
// list of `key value...` lines; a dozen lines of tokenising give exact `file:line:` errors, strict
// rules (no unknown key, no duplicate, no stray value) and no dependency. Numbers go through
// std::from_chars, which ignores the C locale, so "0.25" reads the same everywhere.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>

#include "world/scenario.h"

#include "world/grid_fit.h"
#include "fw/fw_util.h"

#ifndef DYNAQPC_SCENARIOS_DIR
#define DYNAQPC_SCENARIOS_DIR "host_sim/scenarios"
#endif

namespace world {

namespace {

constexpr double kPi = FW_PI;
constexpr double kDeg = kPi / 180.0;
constexpr double kBig = 1000.0;  // m: the largest coordinate or extent a scenario may give

using Tokens = std::vector<std::string_view>;

std::string fmt_num(double v)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

// A field of a `key name value name value ...` line.
struct Field {
    enum class Type { Real, Deg, Ms, Int, Text };
    const char *name;
    Type type;
    void *target;  // double* (Real, Deg, Ms: converted to rad / s), int* (Int), std::string* (Text)
    double lo, hi;  // allowed range in file units (Real, Deg, Ms, Int)
    bool required = false;  // a line without it is refused ("missing field")
    bool seen = false;
};

class Parser;

// A key of the scenario format (Parser::line has the table).
struct KeyRule {
    const char *key;
    bool single;
    int Parser::*line_of;
    bool (Parser::*parse)(const Tokens &t, Scenario *s);
};

class Parser {
public:
    Parser(const std::string &file, std::string *error) : file_(file), error_(error) {}

    bool run(std::string_view text, Scenario *s);

private:
    const std::string &file_;
    std::string *error_;
    int line_ = 0;
    int last_line_ = 1;
    std::map<std::string, int, std::less<>> single_seen_;  // single keys -> line
    std::vector<int> ray_lines_;
    std::vector<int> code_bit_lines_;
    std::vector<int> beacon_lines_;
    int goal_line_ = 0, arena_line_ = 0, encode_line_ = 0, actions_line_ = 0, cricket_line_ = 0, timing_line_ = 0;
    int robot_line_ = 0, ranger_line_ = 0;
    std::vector<bool> ray_has_mount_;
    bool sensor_bits_given_ = false;
    bool heading_bits_given_ = false;

    bool fail(const std::string &what) { return fail_at(line_, what); }
    bool fail_at(int line, const std::string &what)
    {
        if (error_ != nullptr) {
            *error_ = file_ + ":" + std::to_string(line) + ": " + what;
        }
        return false;
    }

    bool number(std::string_view tok, const std::string &what, double lo, double hi, double *out);
    bool integer(std::string_view tok, const std::string &what, long lo, long hi, int *out);
    bool count(const Tokens &t, std::size_t lo, std::size_t hi, const char *usage);
    bool fields(const Tokens &t, std::vector<Field> &spec);
    bool single(std::string_view key);
    bool line(const Tokens &t, Scenario *s);
    // One reader a key (kKeyRules says which, and what line() checks before calling it).
    bool key_arena(const Tokens &t, Scenario *s);
    bool key_obstacle(const Tokens &t, Scenario *s);
    bool key_goal(const Tokens &t, Scenario *s);
    bool key_robot(const Tokens &t, Scenario *s);
    bool key_ranger(const Tokens &t, Scenario *s);
    bool key_ray(const Tokens &t, Scenario *s);
    bool key_code_bit(const Tokens &t, Scenario *s);
    bool key_actuation(const Tokens &t, Scenario *s);
    bool key_gyro(const Tokens &t, Scenario *s);
    bool key_gps(const Tokens &t, Scenario *s);
    bool key_cricket(const Tokens &t, Scenario *s);
    bool key_beacon(const Tokens &t, Scenario *s);
    bool key_timing(const Tokens &t, Scenario *s);
    bool key_solver(const Tokens &t, Scenario *s);
    bool key_start(const Tokens &t, Scenario *s);
    bool key_encode(const Tokens &t, Scenario *s);
    bool fit_encoding(Scenario *s);
    bool resolve_stop(Scenario *s);
    bool key_actions(const Tokens &t, Scenario *s);
    bool key_rewards(const Tokens &t, Scenario *s);
    bool key_learning(const Tokens &t, Scenario *s);
    bool validate(Scenario *s);
    bool validate_sensors(Scenario *s);
    bool validate_encoding(Scenario *s);
    bool validate_layout(const Scenario &s);
    bool validate_goal_cells(const Scenario &s);
    bool validate_beacons(const Scenario &s);
    bool validate_start_room(const Scenario &s);
};

bool Parser::number(std::string_view tok, const std::string &what, double lo, double hi,
                    double *out)
{
    double v = 0.0;
    const char *end = tok.data() + tok.size();
    auto [ptr, ec] = std::from_chars(tok.data(), end, v);
    if (ec != std::errc() || ptr != end || !std::isfinite(v)) {
        return fail("'" + std::string(tok) + "' is not a number (" + what + ")");
    }
    if (v < lo || v > hi) {
        return fail(what + " " + std::string(tok) + " out of range [" + fmt_num(lo) + ", " +
                    fmt_num(hi) + "]");
    }
    *out = v;
    return true;
}

bool Parser::integer(std::string_view tok, const std::string &what, long lo, long hi, int *out)
{
    long v = 0;
    const char *end = tok.data() + tok.size();
    auto [ptr, ec] = std::from_chars(tok.data(), end, v);
    if (ec != std::errc() || ptr != end) {
        return fail("'" + std::string(tok) + "' is not an integer (" + what + ")");
    }
    if (v < lo || v > hi) {
        return fail(what + " " + std::string(tok) + " out of range [" + std::to_string(lo) + ", " +
                    std::to_string(hi) + "]");
    }
    *out = static_cast<int>(v);
    return true;
}

bool Parser::count(const Tokens &t, std::size_t lo, std::size_t hi, const char *usage)
{
    std::size_t n = t.size() - 1;
    if (n < lo) {
        return fail("missing value: expected '" + std::string(usage) + "'");
    }
    if (n > hi) {
        return fail("extra value '" + std::string(t[hi + 1]) + "': expected '" +
                    std::string(usage) + "'");
    }
    return true;
}

bool Parser::fields(const Tokens &t, std::vector<Field> &spec)
{
    const std::string key(t[0]);
    for (std::size_t i = 1; i < t.size(); i += 2) {
        auto it = std::find_if(spec.begin(), spec.end(),
                               [&](const Field &f) { return t[i] == f.name; });
        if (it == spec.end()) {
            std::string names;
            for (const Field &f : spec) {
                names += names.empty() ? "" : ", ";
                names += f.name;
            }
            return fail("unknown field '" + std::string(t[i]) + "' for '" + key + "' (fields: " +
                        names + ")");
        }
        if (it->seen) {
            return fail("duplicate field '" + std::string(t[i]) + "' for '" + key + "'");
        }
        if (i + 1 >= t.size()) {
            return fail("missing value for '" + key + " " + it->name + "'");
        }
        it->seen = true;
        std::string_view v = t[i + 1];
        std::string what = key + " " + it->name;
        double d = 0.0;
        switch (it->type) {
        case Field::Type::Real:
            if (!number(v, what, it->lo, it->hi, static_cast<double *>(it->target))) return false;
            break;
        case Field::Type::Deg:
            if (!number(v, what, it->lo, it->hi, &d)) return false;
            *static_cast<double *>(it->target) = d * kDeg;
            break;
        case Field::Type::Ms:
            if (!number(v, what, it->lo, it->hi, &d)) return false;
            *static_cast<double *>(it->target) = d / 1000.0;
            break;
        case Field::Type::Int:
            if (!integer(v, what, static_cast<long>(it->lo), static_cast<long>(it->hi),
                         static_cast<int *>(it->target))) {
                return false;
            }
            break;
        case Field::Type::Text:
            *static_cast<std::string *>(it->target) = std::string(v);
            break;
        }
    }
    for (const Field &f : spec) {
        if (f.required && !f.seen) {
            return fail("missing field '" + key + " " + f.name + "'");
        }
    }
    return true;
}

// Whether the line gave the field `name` (a name of `spec`).
bool seen_field(const std::vector<Field> &spec, const char *name)
{
    for (const Field &f : spec) {
        if (std::strcmp(f.name, name) == 0) return f.seen;
    }
    return false;
}

bool Parser::single(std::string_view key)
{
    auto it = single_seen_.find(key);
    if (it != single_seen_.end()) {
        return fail("duplicate '" + std::string(key) + "' (first on line " +
                    std::to_string(it->second) + ")");
    }
    single_seen_.emplace(std::string(key), line_);
    return true;
}

// A beacon id, "1:5e:3c:3c:a:0:0:b1": 8 groups of 1-2 hex digits separated by ':'. *value gets its
// 8 bytes as one number, so that "1:5e:..." and "01:5E:..." are the same beacon (the firmware's
// Cricket driver compares bytes).
bool parse_beacon_id(std::string_view id, std::uint64_t *value)
{
    int groups = 0;
    std::uint64_t v = 0;
    std::size_t i = 0;
    while (i <= id.size()) {
        std::size_t j = id.find(':', i);
        if (j == std::string_view::npos) j = id.size();
        if (j - i < 1 || j - i > 2) return false;
        std::uint64_t byte = 0;
        for (std::size_t k = i; k < j; ++k) {
            const unsigned char c = static_cast<unsigned char>(id[k]);
            if (std::isxdigit(c) == 0) return false;
            byte = byte * 16 + static_cast<std::uint64_t>(std::isdigit(c) ? c - '0' : std::tolower(c) - 'a' + 10);
        }
        v = (v << 8) | byte;
        ++groups;
        i = j + 1;
    }
    *value = v;
    return groups == 8;
}

bool Parser::line(const Tokens &t, Scenario *s)
{
    // One row a key: whether it may appear once only, which member remembers its line (for the
    // checks after the last line), and the member that reads its values.
    static const KeyRule kRules[] = {
        {"arena", true, &Parser::arena_line_, &Parser::key_arena},
        {"obstacle", false, nullptr, &Parser::key_obstacle},
        {"goal", true, &Parser::goal_line_, &Parser::key_goal},
        {"robot", true, &Parser::robot_line_, &Parser::key_robot},
        {"ranger", true, &Parser::ranger_line_, &Parser::key_ranger},
        {"ray", false, nullptr, &Parser::key_ray},
        {"code_bit", false, nullptr, &Parser::key_code_bit},
        {"actuation", true, nullptr, &Parser::key_actuation},
        {"gyro", true, nullptr, &Parser::key_gyro},
        {"gps", true, nullptr, &Parser::key_gps},
        {"cricket", true, &Parser::cricket_line_, &Parser::key_cricket},
        {"beacon", false, nullptr, &Parser::key_beacon},
        {"timing", true, &Parser::timing_line_, &Parser::key_timing},
        {"solver", true, nullptr, &Parser::key_solver},
        {"start", true, nullptr, &Parser::key_start},
        {"encode", true, &Parser::encode_line_, &Parser::key_encode},
        {"actions", true, &Parser::actions_line_, &Parser::key_actions},
        {"rewards", true, nullptr, &Parser::key_rewards},
        {"learning", true, nullptr, &Parser::key_learning},
    };
    const std::string_view key = t[0];
    for (const KeyRule &rule : kRules) {
        if (key != rule.key) continue;
        if (rule.single && !single(key)) return false;
        if (rule.line_of != nullptr) this->*rule.line_of = line_;
        return (this->*rule.parse)(t, s);
    }
    return fail("unknown key '" + std::string(key) + "'");
}

bool Parser::key_arena(const Tokens &t, Scenario *s)
{
    if (!count(t, 2, 2, "arena <width m> <height m>")) return false;
    return number(t[1], "arena width", 0.5, kBig, &s->arena_w) &&
           number(t[2], "arena height", 0.5, kBig, &s->arena_h);
}

bool Parser::key_obstacle(const Tokens &t, Scenario *s)
{
    if (t.size() < 2) {
        return fail("missing value: expected 'obstacle box|circle ...'");
    }
    if (static_cast<int>(s->obstacles.size()) >= kMaxObstacles) {
        return fail("too many obstacles (at most " + std::to_string(kMaxObstacles) + ")");
    }
    Obstacle o;
    o.line = line_;
    if (t[1] == "box") {
        const char *usage = "obstacle box <cx m> <cy m> <w m> <h m> [angle deg]";
        if (!count(t, 5, 6, usage)) return false;
        o.shape = Obstacle::Shape::Box;
        if (!number(t[2], "box cx", -kBig, kBig, &o.cx) ||
            !number(t[3], "box cy", -kBig, kBig, &o.cy) ||
            !number(t[4], "box width", 0.01, kBig, &o.w) ||
            !number(t[5], "box height", 0.01, kBig, &o.h)) {
            return false;
        }
        if (t.size() == 7) {
            double deg = 0.0;
            if (!number(t[6], "box angle", -360.0, 360.0, &deg)) return false;
            o.angle = deg * kDeg;
        }
    } else if (t[1] == "circle") {
        if (!count(t, 4, 4, "obstacle circle <cx m> <cy m> <radius m>")) return false;
        o.shape = Obstacle::Shape::Circle;
        if (!number(t[2], "circle cx", -kBig, kBig, &o.cx) ||
            !number(t[3], "circle cy", -kBig, kBig, &o.cy) ||
            !number(t[4], "circle radius", 0.01, kBig, &o.radius)) {
            return false;
        }
    } else {
        return fail("unknown obstacle shape '" + std::string(t[1]) + "' (box or circle)");
    }
    s->obstacles.push_back(o);
    return true;
}

bool Parser::key_goal(const Tokens &t, Scenario *s)
{
    if (!count(t, 3, 4, "goal <cx m> <cy m> <radius m> [cells]")) return false;
    if (t.size() == 5) {
        if (t[4] != "cells") {
            return fail("goal: '" + std::string(t[4]) + "' after the radius (only 'cells')");
        }
        s->goal.cells = true;
    }
    return number(t[1], "goal cx", -kBig, kBig, &s->goal.cx) &&
           number(t[2], "goal cy", -kBig, kBig, &s->goal.cy) &&
           number(t[3], "goal radius", 0.01, kBig, &s->goal.radius);
}

bool Parser::key_robot(const Tokens &t, Scenario *s)
{
    using T = Field::Type;
    RobotSpec &r = s->robot;
    std::vector<Field> f = {
        {"length", T::Real, &r.length, 0.05, 5.0, true},
        {"width", T::Real, &r.width, 0.05, 5.0, true},
        {"mass", T::Real, &r.mass, 0.1, 1000.0},  // has a default
        {"track", T::Real, &r.track, 0.02, 5.0, true},
        {"max_speed", T::Real, &r.max_speed, 0.01, 20.0},
        {"max_accel", T::Real, &r.max_accel, 0.1, 1000.0},
        {"friction", T::Real, &r.friction, 0.0, 2.0},
    };
    if (!fields(t, f)) return false;
    if (r.track > r.width) {
        return fail("robot track " + fmt_num(r.track) + " wider than the body (" +
                    fmt_num(r.width) + ")");
    }
    return true;
}

bool Parser::key_ranger(const Tokens &t, Scenario *s)
{
    using T = Field::Type;
    RangerSpec &g = s->ranger;
    std::string kind;
    std::vector<Field> f = {
        {"kind", T::Text, &kind, 0, 0, true},
        {"min", T::Real, &g.min_range, 0.0, 100.0, true},
        {"max", T::Real, &g.max_range, 0.01, 100.0, true},
        {"noise_prop", T::Real, &g.noise_prop, 0.0, 1.0},
        {"noise_sd", T::Real, &g.noise_sd, 0.0, 10.0},
    };
    if (!fields(t, f)) return false;
    if (kind == "sonar") {
        g.kind = RangerSpec::Kind::Sonar;
    } else if (kind == "ir") {
        g.kind = RangerSpec::Kind::Ir;
    } else {
        return fail("unknown ranger kind '" + kind + "' (sonar or ir)");
    }
    if (g.min_range >= g.max_range) {
        return fail("ranger min " + fmt_num(g.min_range) + " not below max " +
                    fmt_num(g.max_range));
    }
    return true;
}

bool Parser::key_ray(const Tokens &t, Scenario *s)
{
    if (!count(t, 1, 3, "ray <angle deg> [<x m> <y m>]")) return false;
    if (t.size() == 3) {
        return fail("missing value: expected 'ray <angle deg> [<x m> <y m>]'");
    }
    if (static_cast<int>(s->ranger.rays.size()) >= kMaxRays) {
        return fail("too many rays (at most " + std::to_string(kMaxRays) + ")");
    }
    Ray r;
    double deg = 0.0;
    if (!number(t[1], "ray angle", -360.0, 360.0, &deg)) return false;
    r.angle = deg * kDeg;
    if (t.size() == 4 && (!number(t[2], "ray x", -5.0, 5.0, &r.x) ||
                          !number(t[3], "ray y", -5.0, 5.0, &r.y))) {
        return false;
    }
    s->ranger.rays.push_back(r);
    ray_lines_.push_back(line_);
    ray_has_mount_.push_back(t.size() == 4);
    return true;
}

bool Parser::key_code_bit(const Tokens &t, Scenario *s)
{
    if (!count(t, 2, 1 + kMaxRays, "code_bit <threshold m> <ray index>...")) return false;
    if (static_cast<int>(s->code_bits.size()) >= kMaxCodeBits) {
        return fail("too many code bits (at most " + std::to_string(kMaxCodeBits) + ")");
    }
    CodeBit b;
    if (!number(t[1], "code_bit threshold", 0.0, 100.0, &b.threshold)) return false;
    for (std::size_t i = 2; i < t.size(); ++i) {
        int idx = 0;
        if (!integer(t[i], "code_bit ray index", 0, kMaxRays - 1, &idx)) return false;
        b.rays.push_back(idx);
    }
    b.line = line_;
    s->code_bits.push_back(b);
    code_bit_lines_.push_back(line_);
    return true;
}

bool Parser::key_actuation(const Tokens &t, Scenario *s)
{
    using T = Field::Type;
    ActuationSpec &a = s->actuation;
    a.enabled = true;
    std::vector<Field> f = {
        {"gain", T::Real, &a.gain, 0.0, 0.5},
        {"noise", T::Real, &a.noise, 0.0, 0.5},
        {"deadband", T::Real, &a.deadband, 0.0, 1.0},
        {"slip_mu", T::Real, &a.slip_mu, 0.0, 2.0},
    };
    return fields(t, f);
}

bool Parser::key_gyro(const Tokens &t, Scenario *s)
{
    using T = Field::Type;
    std::vector<Field> f = {
        {"bias", T::Real, &s->gyro.bias, -1.0, 1.0},
        {"noise_sd", T::Real, &s->gyro.noise_sd, 0.0, 10.0},
        {"scale", T::Real, &s->gyro.scale, 0.0, 0.2},
    };
    return fields(t, f);
}

bool Parser::key_gps(const Tokens &t, Scenario *s)
{
    using T = Field::Type;
    s->gps.enabled = true;
    std::vector<Field> f = {
        {"xy_sd", T::Real, &s->gps.xy_sd, 0.0, 10.0},
        {"heading_sd_deg", T::Deg, &s->gps.heading_sd, 0.0, 90.0},
    };
    return fields(t, f);
}

bool Parser::key_cricket(const Tokens &t, Scenario *s)
{
    using T = Field::Type;
    CricketSpec &c = s->cricket;
    std::vector<Field> f = {
        {"space", T::Text, &c.space, 0, 0},
        {"min_interval_ms", T::Ms, &c.min_interval, 10.0, 60000.0},
        {"max_interval_ms", T::Ms, &c.max_interval, 10.0, 60000.0},
        {"noise_sd", T::Real, &c.noise_sd, 0.0, 1.0},
        {"listener_height", T::Real, &c.listener_height, 0.0, 10.0},
        {"speed_of_sound", T::Real, &c.speed_of_sound, 300.0, 400.0},
        {"dropout", T::Real, &c.dropout, 0.0, 0.9},
        {"outlier", T::Real, &c.outlier, 0.0, 0.9},
        {"outlier_max", T::Real, &c.outlier_max, 0.01, 10.0},
    };
    if (!fields(t, f)) return false;
    if (c.space.empty() || c.space.size() > 16 ||
        c.space.find_first_of(",=") != std::string::npos) {
        return fail("cricket space '" + c.space + "': 1 to 16 characters, no ',' or '='");
    }
    if (c.min_interval > c.max_interval) {
        return fail("cricket min_interval_ms above max_interval_ms");
    }
    return true;
}

bool Parser::key_beacon(const Tokens &t, Scenario *s)
{
    if (!count(t, 4, 4, "beacon <id> <x m> <y m> <z m>")) return false;
    if (static_cast<int>(s->cricket.beacons.size()) >= kMaxBeacons) {
        return fail("too many beacons (at most " + std::to_string(kMaxBeacons) + ")");
    }
    Beacon b;
    std::uint64_t value = 0;
    if (!parse_beacon_id(t[1], &value)) {
        return fail("beacon id '" + std::string(t[1]) +
                    "': expected 8 hex bytes separated by ':' (e.g. 1:5e:3c:3c:a:0:0:ba)");
    }
    b.id = std::string(t[1]);
    for (const Beacon &o : s->cricket.beacons) {
        std::uint64_t other = 0;
        if (parse_beacon_id(o.id, &other) && other == value) {
            return fail("duplicate beacon id '" + b.id + "'" + (o.id == b.id ? "" : " (the same 8 bytes as '" + o.id + "')"));
        }
    }
    if (!number(t[2], "beacon x", -kBig, kBig, &b.x) ||
        !number(t[3], "beacon y", -kBig, kBig, &b.y) ||
        !number(t[4], "beacon z", 0.0, 100.0, &b.z)) {
        return false;
    }
    s->cricket.beacons.push_back(b);
    beacon_lines_.push_back(line_);
    return true;
}

bool Parser::key_timing(const Tokens &t, Scenario *s)
{
    using T = Field::Type;
    std::vector<Field> f = {
        {"control_period", T::Real, &s->timing.control_period, 0.001, 10.0},
        {"physics_dt", T::Real, &s->timing.physics_dt, 0.0001, 0.1},
    };
    if (!fields(t, f)) return false;
    double n = s->timing.control_period / s->timing.physics_dt;
    double r = std::round(n);
    if (r < 1.0 || r > 1000.0 || std::fabs(n - r) > 1e-6 * r) {
        return fail("timing control_period " + fmt_num(s->timing.control_period) +
                    " is not a whole number (1..1000) of physics_dt " +
                    fmt_num(s->timing.physics_dt));
    }
    s->timing.substeps = static_cast<int>(r);
    return true;
}

bool Parser::key_solver(const Tokens &t, Scenario *s)
{
    using T = Field::Type;
    std::vector<Field> f = {
        {"velocity_iterations", T::Int, &s->solver.velocity_iterations, 1, 100},
        {"position_iterations", T::Int, &s->solver.position_iterations, 1, 100},
    };
    return fields(t, f);
}

bool Parser::key_start(const Tokens &t, Scenario *s)
{
    using T = Field::Type;
    std::vector<Field> f = {{"margin", T::Real, &s->start.margin, 0.0, 10.0}};
    return fields(t, f);
}

bool Parser::key_encode(const Tokens &t, Scenario *s)
{
    using T = Field::Type;
    Encoding &e = s->encoding;
    // `encode auto [cell M] [heading H] [sensor S]`: x and y cells fitted to the room.
    if (t.size() > 1 && t[1] == "auto") {
        Tokens rest(t.begin() + 1, t.end());
        rest[0] = t[0];
        std::vector<Field> f = {
            {"cell", T::Real, &e.max_cell, 0.05, 100.0},
            {"heading", T::Int, &e.heading_bits, 1, 16},
            {"sensor", T::Int, &e.sensor_bits, 0, kMaxCodeBits},
        };
        if (!fields(rest, f)) return false;
        e.fitted = true;
        sensor_bits_given_ = seen_field(f, "sensor");
        heading_bits_given_ = seen_field(f, "heading");
        return true;
    }
    std::vector<Field> f = {
        {"x", T::Int, &e.x_bits, 1, 16},
        {"y", T::Int, &e.y_bits, 1, 16},
        {"heading", T::Int, &e.heading_bits, 1, 16},
        {"sensor", T::Int, &e.sensor_bits, 0, kMaxCodeBits},
    };
    if (!fields(t, f)) return false;
    sensor_bits_given_ = seen_field(f, "sensor");
    return true;
}

// Whether aligned steps stop at cell centres (`stop centre`, or `auto` on a fitted grid the robot
// turns inside): what resolve_stop() records and rule 5 of the fit asks before it is recorded.
static bool stops_at_centres(const Scenario &s, bool fitted)
{
    const ActionSpec &a = s.actions;
    return a.aligned != 0 && (a.stop == "centre" || (a.stop == "auto" && fitted && turns_inside_cells(s)));
}

// How far inside a plain goal circle a centred stop must lie to count: a stop settles within about
// 2 cm of its centre (the lab robot's position error, 0.018 m), so a centre on the circle's edge
// would end the episode one time in two.
constexpr double kCentredStopMargin = 0.02;

// Whether an aligned step can end in the goal. A `cells` goal is its cells: the firmware steps over
// a fitted cell narrower than `past` (a partition's), so a goal whose cells are all that narrow is
// never reached (a goal drawn above the end of a thin wall, on the wall's column of cells). A plain
// circle is reached where a step ends in it: for a robot that stops at its cells' centres, some
// centre of a cell it stops in must lie inside, by kCentredStopMargin (a hand-drawn dining room
// whose 0.25 m goal lay between two centres learned 0 of 20 sets); a `past` stop lands along the
// whole cell across its step. Fixed steps land anywhere.
bool goal_has_a_stop(const Scenario &s)
{
    const bool plain = !s.goal.cells;
    if (plain && !stops_at_centres(s, s.encoding.fitted)) return true;  // fixed or `past` stops
    if (!s.actions.aligned) return !goal_cells(s).empty();
    // A circle that holds a whole cell around its centre holds that cell's centre: decided without
    // walking the cells under it (an equal grid may have 2^16 a side).
    const double half_diagonal = 0.5 * std::hypot(grid_max_side(s, 0), grid_max_side(s, 1));
    if (plain && !s.encoding.fitted && s.goal.radius - kCentredStopMargin >= half_diagonal) return true;
    for (const CellBox &c : goal_cells(s)) {
        if (!(c.x1 - c.x0 > s.actions.past && c.y1 - c.y0 > s.actions.past)) continue;
        const double d = std::hypot(0.5 * (c.x0 + c.x1) - s.goal.cx, 0.5 * (c.y0 + c.y1) - s.goal.cy);
        if (!plain || d <= s.goal.radius - kCentredStopMargin) return true;
    }
    return false;
}

// Rule 7 (grid_fit.h): when a quarter or more of the stops of the fit at `max_side` reach no goal
// stop, the first side of kWalkSideFactors whose fit has stops that all reach the goal. Why a
// quarter: there furniture cuts a region of the room off (34 of a generated room's 44 stops; its
// relapses went from 36 % and 24 % to 0 % and 2 % over two seeds), where a few tight stops in a
// corner cost nothing, and refitting those raised relapses in two tuning rooms of fifteen (docs/agent.md).
template <typename Fit>
static void refit_for_the_walk(Scenario *s, double max_side, Fit &&fit_side, bool *goal_reached)
{
    Encoding &e = s->encoding;
    struct Walked {
        long stranded, stops;
    };
    auto walk = [s]() {
        const bool centred = s->actions.centred;
        s->actions.centred = true;  // as resolve_stop() records it after the fit
        const StopWalkReport w = stop_walk(*s);
        s->actions.centred = centred;
        return Walked{w.stranded, w.cells};
    };
    const Walked first = walk();
    if (first.stranded == 0 || first.stranded * kWalkStrandedShare < first.stops) return;
    const std::vector<double> x = e.x_edges, y = e.y_edges;
    for (double f : kWalkSideFactors) {
        const double side = f * max_side;
        if (!(s->actions.past < side) || !fit_side(side) || !*goal_reached) continue;
        // Some stop, too: a fit whose every stop an obstacle crowds has none stranded either.
        if (const Walked w = walk(); w.stops > 0 && w.stranded == 0) {
            e.walk_refit = {max_side, side, first.stranded, first.stops};
            return;
        }
    }
    e.x_edges = x;
    e.y_edges = y;
    e.walk_refit = {max_side, 0.0, first.stranded, first.stops};
    *goal_reached = goal_has_a_stop(*s);
}

// `encode auto`: the x and y cells fitted to the room (grid_fit.h), the bits their counts need,
// and `past` (when not given) a fifth of the largest cell side, which the fit keeps clear of
// every cell a step stops in.
bool Parser::fit_encoding(Scenario *s)
{
    Encoding &e = s->encoding;
    const double max_side = fit_cell_side(*s);
    if (s->actions.past == 0.0) s->actions.past = 0.2 * max_side;
    if (s->actions.past >= max_side) {
        return fail_at(actions_line_, "actions past " + fmt_num(s->actions.past) +
                                          " is not inside the next cell (encode auto's cells are at most " +
                                          fmt_num(max_side) + " m)");
    }
    // Rule 5 is for centred stops: resolve_stop()'s answer on a fitted grid, which the edges do not change.
    const bool centred = stops_at_centres(*s, true);
    std::string problem;
    bool goal_reached = false;
    auto fit_side = [&](double side) {
        for (GoalCut cut : {GoalCut::None, GoalCut::Square, GoalCut::WholeSquare}) {
            if (!fit_grid(*s, side, cut, centred, &e.x_edges, &e.y_edges, &problem)) return false;
            goal_reached = goal_has_a_stop(*s);
            if (goal_reached) break;  // else: a cell centred on the goal
        }
        return true;
    };
    if (!fit_side(max_side)) return fail_at(encode_line_ != 0 ? encode_line_ : last_line_, problem);
    if (centred && e.max_cell == 0.0) refit_for_the_walk(s, max_side, fit_side, &goal_reached);
    // No cell at all, or a plain goal no stop reaches, is validate_goal_cells()'s to say; `cells`
    // no step ends in, this one's.
    if (!goal_reached && s->goal.cells && !goal_cells(*s).empty()) {
        return fail_at(goal_line_, "goal ... cells: every cell of the fitted grid with its centre in the "
                                   "circle is narrower than 'past' (" + fmt_num(s->actions.past) +
                                       " m), and aligned steps pass over such a cell: the goal could "
                                       "never be reached (move it into the open, or make it larger)");
    }
    auto bits_for = [](std::size_t cells) {
        int b = 1;
        while ((std::size_t{1} << b) < cells) b++;
        return b;
    };
    e.x_bits = bits_for(e.x_edges.size() - 1);
    e.y_bits = bits_for(e.y_edges.size() - 1);
    // Fixed turns (`aligned 0`) keep the robot on the headings its settled start and whole turns
    // reach (robot_settles()): one sector each when they are a power of two, as 45-degree turns'
    // 8 are. Sectors between them only split the same motion by how far the gyro drifted
    // (paper-lab-motion's tuning sets: 16 of 24 learned on 8 sectors, 11 on 16).
    const double turns = 2.0 * kPi / s->actions.turn;
    const long whole = std::lround(turns);
    if (!heading_bits_given_ && s->actions.aligned == 0 && std::fabs(turns - static_cast<double>(whole)) < 1e-6 &&
        whole >= 2 && (whole & (whole - 1)) == 0) {
        e.heading_bits = bits_for(static_cast<std::size_t>(whole));
    }
    return true;
}

bool Parser::key_actions(const Tokens &t, Scenario *s)
{
    using T = Field::Type;
    std::vector<Field> f = {
        {"step", T::Real, &s->actions.step, 0.001, 10.0},
        {"turn_deg", T::Deg, &s->actions.turn, 0.1, 180.0},
        {"aligned", T::Int, &s->actions.aligned, 0, 1},
        {"past", T::Real, &s->actions.past, 0.001, 10.0},
        {"stop", T::Text, &s->actions.stop, 0, 0},
    };
    if (!fields(t, f)) return false;
    if (s->actions.stop != "auto" && s->actions.stop != "past" && s->actions.stop != "centre") {
        return fail("actions stop '" + s->actions.stop + "': unknown (auto, past, centre)");
    }
    return true;
}

bool Parser::key_rewards(const Tokens &t, Scenario *s)
{
    using T = Field::Type;
    std::vector<Field> f = {
        {"bump", T::Real, &s->rewards.bump, -1e6, 1e6},
        {"goal", T::Real, &s->rewards.goal, -1e6, 1e6},
        {"step", T::Real, &s->rewards.step, -1e6, 1e6},
    };
    return fields(t, f);
}

bool Parser::key_learning(const Tokens &t, Scenario *s)
{
    using T = Field::Type;
    Learning &l = s->learning;
    std::string gamma = "auto";
    std::string tiles;
    std::vector<Field> f = {
        {"epsilon", T::Real, &l.epsilon, 0.0, 1.0},
        {"alpha", T::Real, &l.alpha, 0.0, 1.0},
        {"gamma", T::Text, &gamma, 0.0, 1.0},
        {"planning", T::Int, &l.planning, 0, 1000000},
        {"step_cap", T::Int, &l.step_cap, 1, 100000000},
        {"sets", T::Int, &l.sets, 1, 1000000},
        {"episodes", T::Int, &l.episodes, 1, 1000000},
        {"explore", T::Text, &l.explore, 0.0, 0.0},
        {"kappa", T::Real, &l.kappa, 0.0, 1000.0},
        {"model", T::Text, &l.model, 0, 0},
        {"tiles", T::Text, &tiles, 0, 0},
    };
    if (!fields(t, f)) {
        return false;
    }
    if (l.explore != "egreedy" && l.explore != "plan-bonus" && l.explore != "act-bonus") {
        return fail("learning explore: '" + l.explore + "' is not egreedy, plan-bonus or act-bonus");
    }
    if (l.model != "relocatable" && l.model != "paper") {
        return fail("learning model '" + l.model + "': unknown (relocatable, paper)");
    }
    if (!tiles.empty()) {
        std::string problem;
        if (!parse_model_tiles(tiles, &l.model_tiles, &problem)) {
            return fail("learning tiles '" + tiles + "': " + problem);
        }
    }
    if (gamma == "auto") {
        l.gamma = Learning::kGammaFromRoom;
        return true;
    }
    return number(gamma, "learning gamma", 0.0, 1.0, &l.gamma);
}

// Where a ray from the body's centre at `angle` leaves the rectangle: the default mount point.
Ray on_outline(const RobotSpec &r, double angle)
{
    double c = std::cos(angle), s = std::sin(angle);
    double hx = r.length / 2.0, hy = r.width / 2.0;
    double tx = std::fabs(c) > 1e-12 ? hx / std::fabs(c) : 1e300;
    double ty = std::fabs(s) > 1e-12 ? hy / std::fabs(s) : 1e300;
    double t = std::min(tx, ty);
    Ray out;
    out.angle = angle;
    out.x = t * c;
    out.y = t * s;
    return out;
}

bool Parser::validate(Scenario *s)
{
    line_ = last_line_;
    const char *required[] = {"arena", "goal", "robot", "ranger"};
    for (const char *k : required) {
        if (single_seen_.find(k) == single_seen_.end()) {
            return fail(std::string("missing required key '") + k + "'");
        }
    }
    if (s->ranger.rays.empty()) {
        return fail("missing required key 'ray' (at least one)");
    }
    return validate_sensors(s) && validate_encoding(s) && validate_layout(*s) && validate_goal_cells(*s) &&
           validate_beacons(*s) && validate_start_room(*s);
}

// The rays' mounts (on the outline where not given) and the code bits' rays.
bool Parser::validate_sensors(Scenario *s)
{
    const RobotSpec &r = s->robot;
    for (std::size_t i = 0; i < s->ranger.rays.size(); ++i) {
        Ray &ray = s->ranger.rays[i];
        if (!ray_has_mount_[i]) {
            ray = on_outline(r, ray.angle);
        } else if (std::fabs(ray.x) > r.length / 2.0 + 1e-9 ||
                   std::fabs(ray.y) > r.width / 2.0 + 1e-9) {
            return fail_at(ray_lines_[i], "ray mount point outside the robot's body");
        }
    }
    for (std::size_t i = 0; i < s->code_bits.size(); ++i) {
        for (int idx : s->code_bits[i].rays) {
            if (idx >= static_cast<int>(s->ranger.rays.size())) {
                return fail_at(code_bit_lines_[i],
                               "code_bit ray index " + std::to_string(idx) + " but only " +
                                   std::to_string(s->ranger.rays.size()) + " rays");
            }
        }
    }
    return true;
}

// The state bits: the code bits counted, the cells fitted or equal, `actions past` inside the next.
bool Parser::validate_encoding(Scenario *s)
{
    Encoding &e = s->encoding;
    int n_bits = static_cast<int>(s->code_bits.size());
    if (sensor_bits_given_ && e.sensor_bits != n_bits) {
        return fail_at(encode_line_, "encode sensor " + std::to_string(e.sensor_bits) +
                                         " but the file has " + std::to_string(n_bits) +
                                         " code_bit lines");
    }
    e.sensor_bits = n_bits;
    if (e.fitted) {
        if (!fit_encoding(s)) return false;
    } else {
        const double cell_side = std::min(s->arena_w / (1 << e.x_bits), s->arena_h / (1 << e.y_bits));
        if (s->actions.past == 0.0) {  // not given
            s->actions.past = 0.2 * cell_side;
        } else if (s->actions.past >= cell_side) {
            return fail_at(actions_line_, "actions past " + fmt_num(s->actions.past) +
                                              " is not inside the next cell (cells are " + fmt_num(cell_side) +
                                              " m on their smaller side)");
        }
    }
    if (e.x_bits + e.y_bits + e.heading_bits + e.sensor_bits > 32) {
        return fail_at(encode_line_ != 0 ? encode_line_ : last_line_,
                       "encode: more than 32 state bits in all");
    }
    return resolve_stop(s);
}

// Why centres on a fitted grid: its edges lie on the room's faces, and a stop `past` beyond the
// edge crossed is one of two per axis, `past` from either edge. The rangers read different codes
// from the two, and a turn at the one beside a wall sweeps the robot's corner to it (the lab
// robot's half-diagonal is 0.160 m, its `past` 0.16 m). The centre is one stop, as far from both
// faces as the cell allows. A robot too large to turn inside a cell (the sonar robot: 0.78 m
// across its corners, cells of 0.5 m) gains no clearance from it and keeps `past`. Measured on
// the tuning rooms: docs/agent.md, "A stop at the cell's centre".
bool Parser::resolve_stop(Scenario *s)
{
    ActionSpec &a = s->actions;
    if (a.stop != "auto" && a.aligned == 0) {
        return fail_at(actions_line_, "actions stop " + a.stop + " needs aligned 1 (fixed steps have no stops)");
    }
    a.centred = stops_at_centres(*s, s->encoding.fitted);
    return true;
}

// Obstacles and the goal inside the arena, the goal clear of every obstacle.
bool Parser::validate_layout(const Scenario &s)
{
    for (const Obstacle &o : s.obstacles) {
        double ex = 0.0, ey = 0.0;  // half extents of the bounding box
        if (o.shape == Obstacle::Shape::Box) {
            double c = std::fabs(std::cos(o.angle)), sn = std::fabs(std::sin(o.angle));
            ex = (o.w * c + o.h * sn) / 2.0;
            ey = (o.w * sn + o.h * c) / 2.0;
        } else {
            ex = ey = o.radius;
        }
        const double eps = 1e-9;
        // The first side it crosses, and how far it reaches: what a user moves or shrinks.
        const struct {
            bool out;
            const char *axis;
            double reach;
            const char *wall;
            double at;
        } sides[] = {{o.cx - ex < -eps, "x", o.cx - ex, "west", 0.0},
                     {o.cx + ex > s.arena_w + eps, "x", o.cx + ex, "east", s.arena_w},
                     {o.cy - ey < -eps, "y", o.cy - ey, "south", 0.0},
                     {o.cy + ey > s.arena_h + eps, "y", o.cy + ey, "north", s.arena_h}};
        for (const auto &side : sides) {
            if (side.out) {
                return fail_at(o.line, std::string("obstacle outside the arena: it reaches ") + side.axis + " = " +
                                           fmt_num(side.reach) + " m, past the " + side.wall + " wall at " +
                                           fmt_num(side.at) + " m");
            }
        }
    }
    const Goal &g = s.goal;
    if (g.cx - g.radius < 0.0 || g.cx + g.radius > s.arena_w || g.cy - g.radius < 0.0 ||
        g.cy + g.radius > s.arena_h) {
        return fail_at(goal_line_, "goal outside the arena");
    }
    // The obstacles' own distance: a circle that touches a wall is inside the arena (above), and
    // the arena's walls are not an obstacle to name (a goal drawn against the east wall was
    // refused as overlapping the file's first obstacle).
    for (const Obstacle &o : s.obstacles) {
        if (obstacle_distance(o, g.cx, g.cy) < g.radius) {
            return fail_at(goal_line_, "goal overlaps the obstacle on line " + std::to_string(o.line));
        }
    }
    return true;
}

// `goal ... cells`: some cell of the state grid has its centre in the circle.
bool Parser::validate_goal_cells(const Scenario &s)
{
    const Goal &g = s.goal;
    if (g.cells) {  // some cell of the state grid must have its centre in the circle
        // Bounded work for every start drawn later: at most 64 x 64 cells under the circle.
        const double cw = s.arena_w / std::ldexp(1.0, s.encoding.x_bits);
        const double ch = s.arena_h / std::ldexp(1.0, s.encoding.y_bits);
        if (!s.encoding.fitted && (2.0 * g.radius / cw > 63.0 || 2.0 * g.radius / ch > 63.0)) {
            return fail_at(goal_line_, "goal ... cells: the circle spans more than 64 cells of the "
                                       "state grid (fewer bits, or drop 'cells')");
        }
        // The firmware decides in single precision: a centre on the circle could be the goal
        // here and not there.
        if (goal_cell_centre_margin(s) < 1e-4) {
            return fail_at(goal_line_, "goal ... cells: a cell centre lies on the circle "
                                       "(within 0.1 mm), where the firmware's single "
                                       "precision may disagree; change the radius");
        }
        if (goal_cells(s).empty()) {
            return fail_at(goal_line_, std::string("goal ... cells: no cell of the state grid has its centre "
                                                   "in the circle (make it larger") +
                                           (s.actions.centred ? ")" : ", or drop 'cells')"));
        }
    } else if (!goal_has_a_stop(s)) {  // a robot that stops at its cells' centres
        return fail_at(goal_line_, "goal: no step ends in the circle: this robot's steps stop at its cells' "
                                   "centres, and no centre lies " + fmt_num(kCentredStopMargin) +
                                       " m inside it (make it larger or move it, or say 'actions ... "
                                       "stop past')");
    }
    return true;
}

// GPS's range, the beacons above the listener and inside the arena.
bool Parser::validate_beacons(const Scenario &s)
{
    // GPS_POSE carries x and y in int16 millimetres (docs/can-protocol.md): a larger arena would
    // have its poses clamped at 32.767 m.
    if (s.gps.enabled && (s.arena_w > 32.767 || s.arena_h > 32.767)) {
        return fail_at(arena_line_, "arena larger than 32.767 m with gps: GPS_POSE carries int16 mm");
    }
    for (std::size_t i = 0; i < s.cricket.beacons.size(); ++i) {
        const Beacon &b = s.cricket.beacons[i];
        if (b.x < 0.0 || b.x > s.arena_w || b.y < 0.0 || b.y > s.arena_h) {
            return fail_at(beacon_lines_[i], "beacon outside the arena");
        }
        if (b.z <= s.cricket.listener_height) {
            return fail_at(beacon_lines_[i], "beacon not above the listener (listener_height " +
                                                 fmt_num(s.cricket.listener_height) + ")");
        }
    }
    if (cricket_line_ != 0 && s.cricket.beacons.empty()) {
        return fail_at(cricket_line_, "cricket without any beacon line");
    }
    return true;
}

// Room for a start pose: some point of the start grid must be a valid start.
bool Parser::validate_start_room(const Scenario &s)
{
    const RobotSpec &r = s.robot;
    const double step = start_grid_step(s);
    bool room = false;
    for (double y = step / 2; y < s.arena_h && !room; y += step) {
        for (double x = step / 2; x < s.arena_w && !room; x += step) {
            room = start_position_ok(s, x, y);
        }
    }
    if (!room) {
        return fail_at(arena_line_, "no room for a start pose: nowhere keeps the robot's radius " +
                                        fmt_num(robot_radius(r)) + " m + margin " +
                                        fmt_num(s.start.margin) + " m clear of walls, "
                                        "obstacles and the goal");
    }
    return true;
}

bool Parser::run(std::string_view text, Scenario *s)
{
    *s = Scenario{};
    if (text.size() > kMaxFileBytes) {
        line_ = 1;
        return fail("file too large (more than " + std::to_string(kMaxFileBytes) + " bytes)");
    }
    std::size_t pos = 0;
    int number_of_line = 0;
    while (pos < text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view raw = text.substr(pos, end - pos);
        pos = end + 1;
        line_ = ++number_of_line;
        last_line_ = line_;
        if (!raw.empty() && raw.back() == '\r') raw.remove_suffix(1);
        for (unsigned char c : raw) {  // before the length: a file of CR-ended lines is one long line
            if ((c < 0x20 && c != '\t') || c >= 0x7f) {
                char buf[64];
                std::snprintf(buf, sizeof buf, "not a text file (byte 0x%02x)", c);
                return fail(c == '\r' ? "a carriage return inside the line: lines that end in CR alone; save the "
                                        "file with LF (or CR LF) line endings"
                                      : buf);
            }
        }
        if (raw.size() > kMaxLineBytes) {
            return fail("line longer than " + std::to_string(kMaxLineBytes) + " bytes");
        }
        std::size_t hash = raw.find('#');
        if (hash != std::string_view::npos) raw = raw.substr(0, hash);
        Tokens t;
        std::size_t i = 0;
        while (i < raw.size()) {
            while (i < raw.size() && (raw[i] == ' ' || raw[i] == '\t')) ++i;
            std::size_t j = i;
            while (j < raw.size() && raw[j] != ' ' && raw[j] != '\t') ++j;
            if (j > i) t.push_back(raw.substr(i, j - i));
            i = j;
        }
        if (t.empty()) continue;
        if (!line(t, s)) return false;
    }
    if (number_of_line == 0) last_line_ = 1;
    return validate(s);
}

std::string stem_of(const std::string &path)
{
    std::size_t slash = path.find_last_of('/');
    std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
    std::size_t dot = base.rfind(".scn");
    if (dot != std::string::npos && dot + 4 == base.size()) base.resize(dot);
    return base;
}

}  // namespace

bool parse_scenario(std::string_view text, const std::string &file, Scenario *out,
                    std::string *error)
{
    Parser p(file, error);
    if (!p.run(text, out)) return false;
    out->name = stem_of(file);
    return true;
}

namespace {

// Doubles are compared exactly: both files are parsed by this parser, so the same text gives the
// same value, and a different value is a different robot or task.
bool rays_same(const std::vector<Ray> &x, const std::vector<Ray> &y)
{
    if (x.size() != y.size()) return false;
    for (std::size_t i = 0; i < x.size(); ++i) {
        if (x[i].angle != y[i].angle || x[i].x != y[i].x || x[i].y != y[i].y) return false;
    }
    return true;
}

bool bits_same(const std::vector<CodeBit> &x, const std::vector<CodeBit> &y)
{
    if (x.size() != y.size()) return false;
    for (std::size_t i = 0; i < x.size(); ++i) {
        if (x[i].threshold != y[i].threshold || x[i].rays != y[i].rays) return false;
    }
    return true;
}

bool beacons_same(const std::vector<Beacon> &x, const std::vector<Beacon> &y)
{
    if (x.size() != y.size()) return false;
    for (std::size_t i = 0; i < x.size(); ++i) {
        if (x[i].id != y[i].id || x[i].x != y[i].x || x[i].y != y[i].y || x[i].z != y[i].z) return false;
    }
    return true;
}

}  // namespace

std::string layout_change_problem(const Scenario &a, const Scenario &b)
{
    const struct {
        bool same;
        const char *what;
    } checks[] = {
        {a.arena_w == b.arena_w && a.arena_h == b.arena_h, "the arena"},
        {a.goal.cx == b.goal.cx && a.goal.cy == b.goal.cy && a.goal.radius == b.goal.radius &&
             a.goal.cells == b.goal.cells,
         "the goal (the firmware is given it)"},
        {a.robot.length == b.robot.length && a.robot.width == b.robot.width && a.robot.mass == b.robot.mass &&
             a.robot.track == b.robot.track && a.robot.max_speed == b.robot.max_speed &&
             a.robot.max_accel == b.robot.max_accel && a.robot.friction == b.robot.friction,
         "the robot"},
        {a.ranger.kind == b.ranger.kind && a.ranger.min_range == b.ranger.min_range &&
             a.ranger.max_range == b.ranger.max_range && a.ranger.noise_prop == b.ranger.noise_prop &&
             a.ranger.noise_sd == b.ranger.noise_sd && rays_same(a.ranger.rays, b.ranger.rays),
         "the ranger or its rays"},
        {bits_same(a.code_bits, b.code_bits), "the code bits"},
        {a.actuation.enabled == b.actuation.enabled && a.actuation.gain == b.actuation.gain &&
             a.actuation.noise == b.actuation.noise && a.actuation.deadband == b.actuation.deadband &&
             a.actuation.slip_mu == b.actuation.slip_mu,
         "the actuation"},
        {a.gyro.bias == b.gyro.bias && a.gyro.noise_sd == b.gyro.noise_sd && a.gyro.scale == b.gyro.scale,
         "the gyro"},
        {a.gps.enabled == b.gps.enabled && a.gps.xy_sd == b.gps.xy_sd && a.gps.heading_sd == b.gps.heading_sd,
         "the gps"},
        {beacons_same(a.cricket.beacons, b.cricket.beacons) && a.cricket.space == b.cricket.space &&
             a.cricket.min_interval == b.cricket.min_interval && a.cricket.max_interval == b.cricket.max_interval &&
             a.cricket.noise_sd == b.cricket.noise_sd && a.cricket.listener_height == b.cricket.listener_height &&
             a.cricket.speed_of_sound == b.cricket.speed_of_sound && a.cricket.dropout == b.cricket.dropout &&
             a.cricket.outlier == b.cricket.outlier && a.cricket.outlier_max == b.cricket.outlier_max,
         "the Cricket system or its beacons"},
        {a.timing.control_period == b.timing.control_period && a.timing.physics_dt == b.timing.physics_dt,
         "the timing"},
        {a.solver.velocity_iterations == b.solver.velocity_iterations &&
             a.solver.position_iterations == b.solver.position_iterations,
         "the solver"},
        {a.start.margin == b.start.margin, "the start margin"},
        {a.encoding.x_bits == b.encoding.x_bits && a.encoding.y_bits == b.encoding.y_bits &&
             a.encoding.fitted == b.encoding.fitted && a.encoding.max_cell == b.encoding.max_cell &&
             a.encoding.heading_bits == b.encoding.heading_bits && a.encoding.sensor_bits == b.encoding.sensor_bits,
         "the encoding"},
        {a.actions.step == b.actions.step && a.actions.turn == b.actions.turn && a.actions.aligned == b.actions.aligned && a.actions.centred == b.actions.centred &&
             a.actions.past == b.actions.past,
         "the actions"},
        {a.rewards.bump == b.rewards.bump && a.rewards.goal == b.rewards.goal && a.rewards.step == b.rewards.step,
         "the rewards"},
        {a.learning.epsilon == b.learning.epsilon && a.learning.alpha == b.learning.alpha &&
             a.learning.gamma == b.learning.gamma && a.learning.planning == b.learning.planning &&
             a.learning.step_cap == b.learning.step_cap && a.learning.explore == b.learning.explore &&
             a.learning.kappa == b.learning.kappa,
         "the learning line (epsilon, alpha, gamma, planning, step_cap, explore or kappa)"},
    };
    for (const auto &c : checks) {
        if (!c.same) return std::string(c.what) + " differs (only obstacles may change)";
    }
    return "";
}

namespace {

// The scenarios shipped in host_sim/scenarios, which --scenario takes by name.
const char *const kShippedScenarios[] = {"paper-lab", "paper-lab-motion", "paper-lab-real", "paper-sim", "paper-sim-motion",
                                         "paper-sim-real"};

// Edit distance (insertions, deletions, substitutions), for "did you mean".
std::size_t edit_distance(const std::string &a, const std::string &b)
{
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); j++) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); i++) {
        std::size_t diag = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); j++) {
            const std::size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0u : 1u)});
            diag = up;
        }
    }
    return row[b.size()];
}

// What to say when NAME is neither a shipped scenario nor a file: the shipped names, and the
// nearest of them when it is a letter or two away. A name with a '/' or a '.' was meant as a path.
std::string unknown_scenario_message(const std::string &name)
{
    std::string names, nearest;
    std::size_t best = 3;
    for (const char *s : kShippedScenarios) {
        names += names.empty() ? s : std::string(", ") + s;
        const std::size_t d = edit_distance(name, s);
        if (d < best) {
            best = d;
            nearest = s;
        }
    }
    const bool a_path = name.find('/') != std::string::npos || name.find('.') != std::string::npos;
    std::string msg = a_path ? std::string("cannot open: ") + std::strerror(ENOENT) : "not a shipped scenario";
    if (!nearest.empty()) msg += " (did you mean " + nearest + "?)";
    return msg + "; the shipped scenarios are " + names + (a_path ? "" : ", or give a scenario file's path");
}

}  // namespace

std::string resolve_scenario_path(const std::string &name_or_path)
{
    for (const char *s : kShippedScenarios) {
        if (name_or_path == s) return std::string(DYNAQPC_SCENARIOS_DIR) + "/" + name_or_path + ".scn";
    }
    return name_or_path;
}

bool load_scenario(const std::string &name_or_path, Scenario *out, std::string *error)
{
    std::string path = resolve_scenario_path(name_or_path);
    auto report = [&](const std::string &what) {
        if (error != nullptr) *error = path + ": " + what;
        return false;
    };
    std::FILE *f = std::fopen(path.c_str(), "rb");
    if (f == nullptr) {
        if (errno == ENOENT) return report(unknown_scenario_message(name_or_path));
        return report(std::string("cannot open: ") + std::strerror(errno));
    }
    std::string text;
    char buf[65536];
    std::size_t n = 0;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0 && text.size() <= kMaxFileBytes) {
        text.append(buf, n);
    }
    const int read_errno = errno;
    const bool failed = std::ferror(f) != 0;
    std::fclose(f);
    if (failed) return report(std::string("cannot read: ") + std::strerror(read_errno));
    if (text.size() > kMaxFileBytes) return report("file too large");
    if (!parse_scenario(text, path, out, error)) return false;
    out->path = path;
    return true;
}

bool parse_model_tiles(const std::string &text, std::vector<int> *out, std::string *problem)
{
    std::vector<int> v;
    std::size_t at = 0;
    while (at <= text.size()) {
        const std::size_t comma = std::min(text.find(',', at), text.size());
        const std::string word = text.substr(at, comma - at);
        int n = -1;
        const auto r = std::from_chars(word.data(), word.data() + word.size(), n);
        if (word.empty() || r.ec != std::errc() || r.ptr != word.data() + word.size() || n < 0 || n > 4) {
            *problem = "each width a power of two's exponent 0..4, four of them: x,y,heading,code (e.g. 1,1,0,0)";
            return false;
        }
        v.push_back(n);
        at = comma + 1;
    }
    if (v.size() != 4) {
        *problem = "four widths, x,y,heading,code (e.g. 1,1,0,0)";
        return false;
    }
    *out = v;
    return true;
}

}  // namespace world
