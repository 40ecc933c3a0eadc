// SPDX-License-Identifier: MIT
// dynaqpc world: the far-goal families, the floors and the room files' names (rooms.h).
#include "world/rooms.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "room_text.h"

namespace world {

using namespace room_text;

const char *far_family_name(FarFamily f)
{
    switch (f) {
    case FarFamily::Hall: return "hall";
    case FarFamily::Open: return "open";
    case FarFamily::CulDeSac: return "culdesac";
    case FarFamily::Serpentine: return "serpentine";
    }
    return "?";
}

bool far_family_from_name(const std::string &name, FarFamily *out)
{
    for (int k = 0; k < kFarFamilies; k++) {
        if (name == far_family_name(static_cast<FarFamily>(k))) {
            *out = static_cast<FarFamily>(k);
            return true;
        }
    }
    return false;
}

FarFamily far_family_of_index(std::uint32_t index)
{
    return static_cast<FarFamily>((index + kFarFamilies - 1) % kFarFamilies);
}

bool floor_check(const Scenario &base, double w, double h, int *x_bits, int *y_bits, std::string *error)
{
    int bits[2] = {0, 0};
    const double side[2] = {w, h}, base_side[2] = {base.arena_w, base.arena_h};
    const int base_bits[2] = {base.encoding.x_bits, base.encoding.y_bits};
    for (int a = 0; a < 2; a++) {
        const double ratio = side[a] / base_side[a];
        const int k = ratio > 0 && std::isfinite(ratio) ? static_cast<int>(std::lround(std::log2(ratio))) : 99;
        bits[a] = base_bits[a] + k;
        if (k < -2 || k > 2 || std::fabs(ratio - std::ldexp(1.0, k)) > 1e-6 * ratio || bits[a] < 1 || bits[a] > 16) {
            if (error != nullptr) {
                *error = num(w) + "x" + num(h) + ": each side must be the base's (" + num(base.arena_w) + " x " +
                         num(base.arena_h) + " m) times 1/4, 1/2, 1, 2 or 4, so that the state cells keep their size (" +
                         num(base.arena_w / (1 << base.encoding.x_bits)) + " x " +
                         num(base.arena_h / (1 << base.encoding.y_bits)) + " m)";
            }
            return false;
        }
    }
    if (bits[0] + bits[1] + base.encoding.heading_bits + base.encoding.sensor_bits > 32) {
        if (error != nullptr) *error = num(w) + "x" + num(h) + ": its encoding would need more than 32 bits";
        return false;
    }
    if (x_bits != nullptr) *x_bits = bits[0];
    if (y_bits != nullptr) *y_bits = bits[1];
    return true;
}

std::string floor_name(double w, double h)
{
    return num(w) + "x" + num(h);
}

std::string room_file_name(const std::string &prefix, const RoomSpec &spec, double floor_w, double floor_h,
                           std::uint32_t seed, std::uint32_t index)
{
    char idx[16];
    std::snprintf(idx, sizeof idx, "%03u", index);
    std::string name = prefix + "-";
    if (spec.far) {
        name += std::string(far_family_name(spec.family)) + "-" + floor_name(floor_w, floor_h) + "-";
    }
    return name + std::to_string(seed) + "-" + idx + ".scn";
}

}  // namespace world
