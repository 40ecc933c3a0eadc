// SPDX-License-Identifier: MIT
// dynaqpc-sim / dynaqpc-fw: one program's end of the virtual CAN bus.
#include "bus_link.h"

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

namespace dynaqpc {

BusLink::~BusLink()
{
    close();
}

void BusLink::open()
{
    vcan_config_t cfg;
    vcan_default_config(&cfg);
    if (vcan_open(&tx_, &cfg) != FW_OK) {
        throw std::runtime_error(std::string("virtual CAN bus: cannot open (") + std::strerror(errno) +
                                 "); in a network namespace, route 224.0.0.0/4 to lo");
    }
    vcan_close_rx(&tx_);  // tx_ only sends: unread, its socket would queue and drop the whole bus
    if (vcan_open(&rx_, &cfg) != FW_OK) {
        const int e = errno;
        vcan_close(&tx_);
        throw std::runtime_error(std::string("virtual CAN bus: cannot open (") + std::strerror(e) + ")");
    }
    // The receiving vcan_t skips datagrams from its own send socket; ours leave from tx_'s, so it
    // takes tx_'s address as "own" (vcan.h's own-frame filter fields).
    rx_.own_addr_be = tx_.own_addr_be;
    rx_.own_port_be = tx_.own_port_be;
    open_ = true;
}

void BusLink::close()
{
    if (open_) {
        vcan_close(&tx_);
        vcan_close(&rx_);
        open_ = false;
    }
}

int BusLink::send(const hal_can_frame_t &frame)
{
    const int rc = vcan_send(&tx_, &frame, vcan_time_now());
    if (rc == FW_OK) {
        sent_++;
    } else {
        send_errors_++;
    }
    return rc;
}

int BusLink::recv(hal_can_frame_t *frame, int timeout_ms)
{
    const int rc = vcan_recv(&rx_, frame, timeout_ms);
    if (rc == 1) {
        received_++;
    }
    vcan_stats_t st;
    vcan_get_stats(&rx_, &st);
    malformed_.store(st.rx_malformed + st.rx_unsupported);
    return rc;
}

}  // namespace dynaqpc
