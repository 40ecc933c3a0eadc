// SPDX-License-Identifier: MIT
// dynaqpc world: how generated rooms are written (room_text.h).
#include "room_text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <vector>

namespace world::room_text {

// Positions on a 1 mm grid, sizes on 2 mm (so that a box pushed against a wall has its centre on
// the 1 mm grid too): what the file says is what was checked.
double q_pos(double v) { return std::round(v * 1000.0) / 1000.0; }

double q_size(double v) { return std::max(0.01, std::round(v * 500.0) / 500.0); }

// A room's stream: (seed, index) mixed as the train command mixes (seed, set), so that
// neighbouring seeds and indices give unrelated rooms.
std::uint32_t room_seed(std::uint32_t seed, std::uint32_t index)
{
    std::uint64_t z = (static_cast<std::uint64_t>(seed) << 32) + index + 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return static_cast<std::uint32_t>((z ^ (z >> 31)) >> 16);
}

// A number as the file writes it: at most 4 decimals, no trailing zeros.
std::string num(double v)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4f", v);
    std::string s = buf;
    while (!s.empty() && s.back() == '0') s.pop_back();
    if (!s.empty() && s.back() == '.') s.pop_back();
    if (s == "-0") s = "0";
    return s;
}

std::string with_comment(std::string line, const std::string &comment)
{
    if (line.size() < 36) line.resize(36, ' ');
    else line += ' ';
    return line + "# " + comment + "\n";
}

// The base file without its layout: every line but `obstacle` and `goal`, and without the
// comments and blank lines that lead up to a dropped line or to the first key (the base's
// header, which describes the base). `before` gets the lines up to and with `arena`, `after` the
// rest.
void base_without_layout(std::string_view text, std::string *before, std::string *after)
{
    std::vector<std::string_view> run;  // comments and blank lines not yet placed
    bool seen_key = false, seen_arena = false;
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view line = text.substr(pos, end - pos);
        pos = end + 1;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        std::string_view body = line.substr(0, std::min(line.size(), line.find('#')));
        const std::size_t k0 = body.find_first_not_of(" \t");
        if (k0 == std::string_view::npos) {
            run.push_back(line);
            continue;
        }
        const std::size_t k1 = body.find_first_of(" \t", k0);
        const std::string_view key = body.substr(k0, k1 == std::string_view::npos ? k1 : k1 - k0);
        const bool layout = key == "obstacle" || key == "goal";
        std::string *to = seen_arena ? after : before;
        if (!layout && seen_key) {
            for (std::string_view r : run) *to += std::string(r) + "\n";
        }
        run.clear();
        seen_key = true;
        if (!layout) *to += std::string(line) + "\n";
        if (key == "arena") seen_arena = true;
    }
}

std::string stem(const std::string &file)
{
    std::size_t slash = file.find_last_of('/');
    std::string base = slash == std::string::npos ? file : file.substr(slash + 1);
    if (base.size() > 4 && base.compare(base.size() - 4, 4, ".scn") == 0) base.resize(base.size() - 4);
    return base;
}

// `text` with the first line whose key is `key` replaced by `lines` (any number of lines, each
// ending in a newline) and every later line of that key dropped.
std::string replace_key(const std::string &text, const std::string &key, const std::string &lines)
{
    std::string out;
    bool done = false;
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string::npos) end = text.size();
        const std::string line = text.substr(pos, end - pos);
        pos = end + 1;
        std::istringstream ss(line.substr(0, line.find('#')));
        std::string k;
        ss >> k;
        if (k != key) {
            out += line + "\n";
        } else if (!done) {
            out += lines;
            done = true;
        }
    }
    return out;
}

// Beacons for a floor other than the base's: eight (the firmware's most) on the base's
// ceiling height, two rows min(0.5 m, H/4) in from the long walls, four columns 0.5 m in from
// the ends and evenly between; their ids the base's first with the last byte counted on.
std::string beacon_lines(const Scenario &base, double w, double h)
{
    const Beacon &b0 = base.cricket.beacons.front();
    const std::size_t colon = b0.id.find_last_of(':');
    const std::string prefix = b0.id.substr(0, colon + 1);
    const unsigned long last = std::strtoul(b0.id.c_str() + colon + 1, nullptr, 16);
    std::string out;
    const double inset = std::min(0.5, h / 4), ix = std::min(0.5, w / 4);
    for (int k = 0; k < 8; k++) {
        const int col = k / 2, row = k % 2;
        const double x = q_pos(ix + (w - 2 * ix) * col / 3.0), y = row == 0 ? inset : h - inset;
        char id[16];
        std::snprintf(id, sizeof id, "%lx", (last + static_cast<unsigned long>(k)) & 0xffu);
        out += "beacon " + prefix + id + " " + num(x) + " " + num(q_pos(y)) + " " + num(b0.z) + "\n";
    }
    return out;
}

bool check_drawn_room(Room *room, const std::string &file, std::string *problem)
{
    if (!parse_scenario(room->text, file, &room->scenario, problem)) return false;
    room->passages = check_passages(room->scenario);
    if (!room->passages.ok) {
        *problem = room->passages.problem;
        return false;
    }
    room->path = longest_path(room->scenario);
    return true;
}

void extents(const Obstacle &o, double *ex, double *ey)
{
    if (o.shape == Obstacle::Shape::Circle) {
        *ex = *ey = o.radius;
        return;
    }
    const double c = std::fabs(std::cos(o.angle)), s = std::fabs(std::sin(o.angle));
    *ex = (o.w * c + o.h * s) / 2.0;
    *ey = (o.w * s + o.h * c) / 2.0;
}

}  // namespace world::room_text
