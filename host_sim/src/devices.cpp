// SPDX-License-Identifier: MIT
// dynaqpc-sim: the simulated robot's devices.
#include "devices.h"

#include <algorithm>
#include <cmath>

#include "drivers/gps.h"
#include "dynaqpc_can.h"
#include "fw/fw_base.h"
#include "drivers/gyro.h"
#include "drivers/motor.h"
#include "drivers/ranges.h"
#include "world/cricket.h"
#include "world/scenario.h"
#include "world/world.h"
#include "fw/fw_util.h"

namespace dynaqpc {

namespace {

constexpr double kRadToCdeg = 18000.0 / FW_PI;

std::uint16_t to_mm(double m, std::uint16_t max_mm)
{
    const double mm = std::round(m * 1000.0);
    return static_cast<std::uint16_t>(std::clamp(mm, 0.0, static_cast<double>(max_mm)));
}

// Whether a frame of a device whose next frame is due at `*due` is due by t; if so the one after
// is due a cycle later.
bool take_due(std::uint64_t *due, std::uint64_t cycle, std::uint64_t t)
{
    if (*due > t) return false;
    *due += cycle;
    return true;
}

}  // namespace

Devices::Devices(world::World &world, std::uint32_t seed)
    : world_(world), sc_(world.scenario()), ranges_(static_cast<std::size_t>(world.ray_count()), 0.0f)
{
    if (!sc_.cricket.beacons.empty()) {
        cricket_ = std::make_unique<world::CricketListener>(sc_, seed ^ 0x43524943u, world.time_s());
    }
}

Devices::~Devices() = default;

void Devices::receive(const hal_can_frame_t &frame, std::uint64_t t_us)
{
    motor_cmd_t cmd;
    if (frame.id != DYNAQPC_CAN_MOTOR_CMD_FRAME_ID) {
        return;  // not for a device
    }
    if (motor_rx_cmd(&cmd_rx_, &frame, t_us, &cmd) != FW_OK) {
        motor_rejected_++;  // a real controller ignores a bad command and keeps its safety timer
        return;
    }
    motor_cmds_++;
    last_cmd_us_ = t_us;
    driving_ = cmd.enable;
    if (cmd.enable) {
        world_.set_wheel_targets(cmd.speed_left_mm_s * 0.001, cmd.speed_right_mm_s * 0.001);
    } else {
        world_.set_wheel_targets(0.0, 0.0);
    }
}

void Devices::check_timeouts(std::uint64_t t_us)
{
    bump_since_status_ = bump_since_status_ || world_.bumped();
    world_.clear_bump();
    if (driving_ && t_us - last_cmd_us_ > static_cast<std::uint64_t>(MOTOR_CMD_TIMEOUT_MS) * 1000u) {
        driving_ = false;
        world_.set_wheel_targets(0.0, 0.0);
    }
}

std::uint64_t Devices::ranges_cycle() const
{
    return sc_.ranger.kind == world::RangerSpec::Kind::Ir ? DeviceCycles::kIr : DeviceCycles::kSonar;
}

std::uint64_t Devices::next_due_us() const
{
    const std::uint64_t due = std::min({motor_due_, gyro_due_, ranges_due_});
    return sc_.gps.enabled ? std::min(due, gps_due_) : due;
}

// Why each device keeps its own clock: a real controller sends MOTOR_STATUS every 48 ms and the
// gyro every 16 ms, whatever the simulation's physics step. A device that spoke only at the
// physics steps on its cycle (t % cycle == 0) fell silent for the least common multiple of the
// two: with physics_dt 0.02 the gyro spoke every 80 ms and MOTOR_STATUS every 240 ms, while the
// gyro's counter said one 16 ms sample had passed, so the firmware turned its heading by a fifth
// of each turn and its dead reckoning called every Cricket fix a jump.
void Devices::emit(std::uint64_t t, std::vector<hal_can_frame_t> *frames, std::string *serial)
{
    hal_can_frame_t f;
    while (take_due(&motor_due_, DeviceCycles::kMotorStatus, t)) {
        const world::WheelSpeeds w = world_.wheel_speeds();
        motor_status_t st{};
        st.speed_left_mm_s = static_cast<std::int16_t>(std::lround(std::clamp(w.left * 1000.0, -2000.0, 2000.0)));
        st.speed_right_mm_s = static_cast<std::int16_t>(std::lround(std::clamp(w.right * 1000.0, -2000.0, 2000.0)));
        st.bump_front = bump_since_status_;
        st.enabled = driving_;
        st.faults = driving_ ? 0u : (last_cmd_us_ != 0 ? MOTOR_FAULT_CMD_TIMEOUT : 0u);
        bump_since_status_ = false;
        if (motor_encode_status(&motor_ctr_, &st, &f) == FW_OK) frames->push_back(f);
    }
    while (take_due(&gyro_due_, DeviceCycles::kGyro, t)) {
        const double cdeg = std::clamp(world_.gyro_rate() * kRadToCdeg, -GYRO_RANGE_DEG_S * 100.0, GYRO_RANGE_DEG_S * 100.0);
        if (gyro_encode_rate(&gyro_ctr_, static_cast<std::int16_t>(std::lround(cdeg)), 25, GYRO_STATUS_OK, &f) == FW_OK)
            frames->push_back(f);
    }
    // The frames by the firmware's rule (ranges_in_ir_frame()), the cycle by the sensors' kind: a
    // base with five ToF rangers sends sonar scans every 48 ms. (Only 3 IR or 16 sonars once
    // reached the firmware: other robots drove with no ranges at all.)
    const std::size_t n = ranges_.size();
    const bool ir = ranges_in_ir_frame(static_cast<std::uint32_t>(n));
    while (take_due(&ranges_due_, ranges_cycle(), t)) {
        world_.range_readings(ranges_.data());
        if (ir) {
            std::uint16_t mm[RANGES_IR_COUNT];
            bool valid[RANGES_IR_COUNT];
            for (unsigned i = 0; i < RANGES_IR_COUNT; i++) {
                valid[i] = ranges_[i] < sc_.ranger.max_range;  // max range: nothing in view
                mm[i] = to_mm(ranges_[i], RANGES_IR_MAX_MM);
            }
            if (ranges_encode_ir(&ir_ctr_, mm, valid, &f) == FW_OK) frames->push_back(f);
        } else {
            std::uint16_t mm[RANGES_SONAR_COUNT];
            for (unsigned i = 0; i < RANGES_SONAR_COUNT; i++) {
                mm[i] = i >= n || ranges_[i] >= sc_.ranger.max_range ? RANGES_NO_ECHO
                                                                      : to_mm(ranges_[i], RANGES_SONAR_MAX_MM);
            }
            hal_can_frame_t scan[RANGES_SONAR_PARTS];
            if (ranges_encode_sonar(&sonar_ctr_, mm, scan) == FW_OK) {
                frames->insert(frames->end(), scan, scan + RANGES_SONAR_PARTS);
            }
        }
    }
    while (sc_.gps.enabled && take_due(&gps_due_, DeviceCycles::kGps, t)) {
        const world::Pose p = world_.gps_pose();
        gps_pose_t gp{};
        gp.x_mm = static_cast<std::int16_t>(std::lround(std::clamp(p.x * 1000.0, -32000.0, 32000.0)));
        gp.y_mm = static_cast<std::int16_t>(std::lround(std::clamp(p.y * 1000.0, -32000.0, 32000.0)));
        double h = std::fmod(p.heading * kRadToCdeg, 36000.0);
        if (h < 0) h += 36000.0;
        gp.heading_cdeg = static_cast<std::uint16_t>(std::min(35999.0, std::floor(h)));
        gp.fix = GPS_FIX_GOOD;
        if (gps_encode_pose(&gps_ctr_, &gp, &f) == FW_OK) frames->push_back(f);
    }
    if (cricket_) {
        std::vector<world::CricketLine> lines;
        const world::Pose p = world_.pose();
        cricket_->advance(static_cast<double>(t) * 1e-6, p.x, p.y, &lines);
        for (const world::CricketLine &l : lines) serial->append(l.text);
    }
}

}  // namespace dynaqpc
