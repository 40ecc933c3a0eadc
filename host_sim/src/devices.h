// SPDX-License-Identifier: MIT
// dynaqpc-sim: the simulated robot's devices on the CAN bus and its Cricket listener's serial
// line — what a real robot's motor controller, gyro, range board and GPS would send.
#ifndef DYNAQPC_SIM_DEVICES_H
#define DYNAQPC_SIM_DEVICES_H

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "drivers/can_link.h"
#include "hal/hal_can.h"

namespace world {
class World;
struct Scenario;
class CricketListener;
}  // namespace world

namespace dynaqpc {

/// Cycle times of the devices' periodic frames (docs/dynaqpc.dbc), µs.
struct DeviceCycles {
    static constexpr std::uint64_t kGyro = 16000;
    static constexpr std::uint64_t kMotorStatus = 48000;
    static constexpr std::uint64_t kIr = 48000;
    static constexpr std::uint64_t kSonar = 96000;
    static constexpr std::uint64_t kGps = 96000;
};

/// The devices of one simulated robot. Time is the world's, in µs.
class Devices {
public:
    Devices(world::World &world, std::uint32_t seed);
    ~Devices();

    /// Frames due by `t_us`, from the world's state now, appended to `frames`: each device sends
    /// at 0, one cycle, two cycles, ... of its own (DeviceCycles), whether or not a physics step
    /// falls there, one frame per cycle that has come (a caller that asks only at physics steps
    /// longer than a cycle gets the cycles it stepped over at once). Cricket listener lines heard
    /// up to t appended to `serial`.
    void emit(std::uint64_t t_us, std::vector<hal_can_frame_t> *frames, std::string *serial);

    /// When the next periodic frame is due (after the last emit()), µs: the lock-step runner
    /// delivers it then, between physics steps when a step does not fall on it.
    std::uint64_t next_due_us() const;

    /// A frame on the bus: the motor controller takes MOTOR_CMD and drives the wheels.
    void receive(const hal_can_frame_t &frame, std::uint64_t t_us);

    /// After each physics step: latches a bump for the next MOTOR_STATUS, and applies the motor
    /// controller's safety stop (no valid MOTOR_CMD for 500 ms stops the wheels).
    void check_timeouts(std::uint64_t t_us);

    /// MOTOR_CMD frames obeyed and refused (malformed, bad CRC, a repeated or jumping counter).
    std::uint32_t motor_cmds() const { return motor_cmds_; }
    std::uint32_t motor_cmds_rejected() const { return motor_rejected_; }

private:
    std::uint64_t ranges_cycle() const;  // the range board's: IR's or the sonar ring's

    world::World &world_;
    const world::Scenario &sc_;
    std::unique_ptr<world::CricketListener> cricket_;
    std::uint8_t motor_ctr_ = 0, gyro_ctr_ = 0, ir_ctr_ = 0, gps_ctr_ = 0;
    std::uint8_t sonar_ctr_ = 0;  // one rolling counter per scan (SONAR_RANGES_A, _B and _C carry it)
    // When each device's next frame is due (MOTOR_STATUS, GYRO_RATE, the range board, GPS), µs.
    std::uint64_t motor_due_ = 0, gyro_due_ = 0, ranges_due_ = 0, gps_due_ = 0;
    std::uint64_t last_cmd_us_ = 0;
    bool driving_ = false;
    bool bump_since_status_ = false;
    std::uint32_t motor_cmds_ = 0, motor_rejected_ = 0;
    can_link_rx_t cmd_rx_{};  // MOTOR_CMD's counter, as the controller checks it
    std::vector<float> ranges_;
};

}  // namespace dynaqpc

#endif  // DYNAQPC_SIM_DEVICES_H
