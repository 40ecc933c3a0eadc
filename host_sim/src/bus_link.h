// SPDX-License-Identifier: MIT
// dynaqpc-sim / dynaqpc-fw: one program's end of the virtual CAN bus (host_sim/transport/vcan.h), for
// a sender thread and a receiver thread at once, with the counts the bus benchmark compares.
#ifndef DYNAQPC_SIM_BUS_LINK_H
#define DYNAQPC_SIM_BUS_LINK_H

#include <atomic>
#include <cstdint>

#include "hal/hal_can.h"
#include "vcan.h"

namespace dynaqpc {

/// Two vcan_t (vcan.h: one per thread): `tx` used only by the sending thread, `rx` only by the
/// receiving thread. The receive side skips this program's own frames (the send socket's
/// address), so frames_received() counts only what other programs sent. Frames stay on this host
/// (vcan's TTL 0) and sends are paced (vcan's default 50 us gap: UDP has no flow control).
class BusLink {
public:
    BusLink() = default;
    ~BusLink();
    BusLink(const BusLink &) = delete;
    BusLink &operator=(const BusLink &) = delete;

    /// Opens both ends on the default group and port. Throws std::runtime_error saying why (no
    /// route for multicast, ...).
    void open();
    void close();

    /// Sends one frame. Returns FW_OK, FW_ERR_FULL (socket buffer full) or FW_ERR_IO.
    /// Context: the sending thread only.
    int send(const hal_can_frame_t &frame);

    /// Waits up to `timeout_ms` (0: poll) for a frame from another program. Returns 1 (a frame),
    /// 0 (timeout) or FW_ERR_IO. Context: the receiving thread only.
    int recv(hal_can_frame_t *frame, int timeout_ms);

    /// The receive socket (poll it, then recv(…, 0)).
    int rx_fd() const { return vcan_fileno(&rx_); }

    /// Counts, readable from any thread.
    std::uint64_t frames_sent() const { return sent_.load(); }
    std::uint64_t send_errors() const { return send_errors_.load(); }
    std::uint64_t frames_received() const { return received_.load(); }
    std::uint64_t frames_malformed() const { return malformed_.load(); }

private:
    vcan_t tx_{};
    vcan_t rx_{};
    bool open_ = false;
    std::atomic<std::uint64_t> sent_{0}, send_errors_{0}, received_{0}, malformed_{0};
};

}  // namespace dynaqpc

#endif  // DYNAQPC_SIM_BUS_LINK_H
