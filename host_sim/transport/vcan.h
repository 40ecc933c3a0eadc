// SPDX-License-Identifier: MIT
// dynaqpc host_sim transport: the virtual CAN bus, in python-can's `udp_multicast` wire format.
//
// Every frame is one UDP datagram to the group 239.74.163.2, port 43113, holding a msgpack map
// with python-can's keys (timestamp, arbitration_id, is_extended_id, is_remote_frame,
// is_error_frame, channel, dlc, data, is_fd, bitrate_switch, error_state_indicator). Any number
// of processes join: the simulator, the firmware's host build, `dynaqpc-monitor`, and python-can's
// own `can.viewer` / `can.logger` (`-i udp_multicast -c 239.74.163.2`, with hop_limit 0).
//
// Frames never leave the host: the TTL is 0 (the kernel delivers the local loop-back copy and
// drops the packet before any wire), and multicast loop-back is on.
//
// No heap: a vcan_t holds two sockets and counters. One vcan_t per thread (no locking inside).
// The datagrams themselves are vcan_codec.h's (pure functions, no sockets).
#ifndef VCAN_H
#define VCAN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "fw/fw_base.h"
#include "hal/hal_can.h"
#include "vcan_codec.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VCAN_DEFAULT_GROUP "239.74.163.2"
#define VCAN_DEFAULT_PORT 43113u
/// Default pause between two sends: UDP has no flow control, and a burst of back-to-back
/// datagrams overruns the receivers' socket buffers (20,000 frames unpaced: ~6,300 arrive;
/// paced at 50 us: all of them).
#define VCAN_DEFAULT_TX_GAP_US 50u
typedef struct vcan_config {
    const char *group;  ///< IPv4 multicast group; NULL: VCAN_DEFAULT_GROUP
    uint16_t port;      ///< UDP port; 0: VCAN_DEFAULT_PORT
    /// IPv4 address of the interface to send on. NULL: the interface the routing table picks for
    /// the group, as python-can does (so python-can's receivers, which join there, see our
    /// frames), or 127.0.0.1 when there is no route for the group. The receive side joins the
    /// group on both that interface and on 127.0.0.1.
    const char *iface;
    uint32_t tx_gap_us; ///< minimum time between two vcan_send() calls; 0: no pacing
    bool receive_own;   ///< deliver this vcan_t's own frames back to it (default false)
} vcan_config_t;

typedef struct vcan_stats {
    uint32_t tx_frames;     ///< frames sent
    uint32_t tx_errors;     ///< vcan_send() failures (bad frame or socket error)
    uint32_t rx_frames;     ///< frames delivered by vcan_recv()
    uint32_t rx_malformed;  ///< datagrams rejected: not a well-formed python-can message
    uint32_t rx_unsupported; ///< well-formed but not a classic data/remote frame (CAN FD, error frame)
    uint32_t rx_own;        ///< own frames skipped (receive_own false)
} vcan_stats_t;

typedef struct vcan {
    int rx_fd;
    int tx_fd;
    uint32_t group_be;  ///< group address, network byte order
    uint16_t port_be;   ///< port, network byte order
    uint32_t own_addr_be; ///< source address and port our frames carry (own-frame filter)
    uint16_t own_port_be;
    uint32_t tx_gap_us;
    bool receive_own;
    bool sent_once;
    double last_tx_s;   ///< CLOCK_MONOTONIC time of the last send (pacing)
    vcan_stats_t stats;
} vcan_t;

/// Fills `cfg` with the defaults above (group, port, route-chosen interface, 50 us pacing).
void vcan_default_config(vcan_config_t *cfg);

/// Opens the bus: a receive socket bound to the port (SO_REUSEADDR and SO_REUSEPORT, so several
/// processes join) and a send socket with TTL 0. `cfg` NULL means the defaults.
/// Returns FW_OK, FW_ERR_INVAL (bad group or interface address, or not a multicast group), or
/// FW_ERR_IO (a socket call failed; errno tells which). On failure nothing stays open.
/// Context: thread.
int vcan_open(vcan_t *bus, const vcan_config_t *cfg);

/// Sends one frame stamped `timestamp` (seconds, >= 0 and finite; python-can uses the Unix
/// time, see vcan_time_now()). Sleeps first when the previous send is less than tx_gap_us ago.
/// Returns FW_OK, FW_ERR_INVAL (id or dlc out of range, bad timestamp) or FW_ERR_IO.
/// Context: thread; blocks at most tx_gap_us plus a non-blocking UDP send.
int vcan_send(vcan_t *bus, const hal_can_frame_t *frame, double timestamp);

/// Waits up to `timeout_ms` (0: poll, negative: forever) for one frame. Datagrams that are not
/// well-formed python-can messages, CAN FD and error frames, and (unless receive_own) our own
/// frames are counted and skipped.
/// Returns 1 (a frame in *frame), 0 (timeout) or FW_ERR_IO. Context: thread.
int vcan_recv(vcan_t *bus, hal_can_frame_t *frame, int timeout_ms);

/// vcan_recv() that also gives the sender's timestamp (may be NULL).
int vcan_recv_stamped(vcan_t *bus, hal_can_frame_t *frame, double *timestamp, int timeout_ms);

/// The receive socket, for callers that multiplex with poll()/select(). -1 when closed.
int vcan_fileno(const vcan_t *bus);

void vcan_get_stats(const vcan_t *bus, vcan_stats_t *out);

/// Closes the receive socket of a vcan_t that will only send (BusLink's sender: it receives on
/// another vcan_t). Left open and unread, the kernel queues every frame of the bus on it until
/// its buffer is full (the 1 MB asked) and then drops each one, counted among the host's UDP
/// receive-buffer errors, which then say nothing of the sockets that are read. vcan_recv() then
/// fails with FW_ERR_IO and vcan_fileno() gives -1; vcan_send() is unchanged.
void vcan_close_rx(vcan_t *bus);

/// Closes both sockets. Safe to call twice and on a vcan_t whose open failed.
void vcan_close(vcan_t *bus);

/// The Unix time in seconds (CLOCK_REALTIME), the clock python-can stamps frames with.
double vcan_time_now(void);

#ifdef __cplusplus
}
#endif

#endif // VCAN_H
