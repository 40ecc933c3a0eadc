// SPDX-License-Identifier: MIT
// dynaqpc host_sim transport: the virtual CAN bus's sockets (the datagrams: vcan_codec.c).
//
// Why two sockets: the receive socket is bound to the bus port like every other member's; the
// send socket has an ephemeral port, so the source address of a datagram tells our own frames
// (which multicast loop-back returns to us) from everybody else's.
//
// Why the send interface follows the routing table by default: python-can joins the group with
// INADDR_ANY (the interface the route for the group picks, the LAN card on a normal host) and
// sends there. A frame sent on 127.0.0.1 while the route points at eth0 never reaches a python-can
// receiver (measured). TTL 0 keeps the frame on the host on any interface: Linux delivers the
// loop-back copy and drops a TTL-0 multicast packet before it reaches a wire.
#define _DEFAULT_SOURCE 1

#include "vcan.h"

#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "fw/fw_base.h"

// ---------------------------------------------------------------------------------------------
// Sockets

static double clock_s_(clockid_t clk)
{
    struct timespec t;
    clock_gettime(clk, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

double vcan_time_now(void)
{
    return clock_s_(CLOCK_REALTIME);
}

void vcan_default_config(vcan_config_t *cfg)
{
    memset(cfg, 0, sizeof *cfg);
    cfg->group = VCAN_DEFAULT_GROUP;
    cfg->port = VCAN_DEFAULT_PORT;
    cfg->iface = NULL;
    cfg->tx_gap_us = VCAN_DEFAULT_TX_GAP_US;
    cfg->receive_own = false;
}

static int join_(int fd, uint32_t group_be, uint32_t iface_be)
{
    struct ip_mreq mreq;
    memset(&mreq, 0, sizeof mreq);
    mreq.imr_multiaddr.s_addr = group_be;
    mreq.imr_interface.s_addr = iface_be;
    if (setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) == 0 || errno == EADDRINUSE) {
        return 0; // EADDRINUSE: already a member there (the route's interface is lo)
    }
    return -1;
}

static int open_rx_(vcan_t *bus, uint32_t iface_be, bool iface_given)
{
    int one = 1;
    int rcvbuf = 1 << 20; // absorbs bursts; the kernel caps it at rmem_max
    struct sockaddr_in a;
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    if (fd < 0) {
        return -1;
    }
    bus->rx_fd = fd;
    if (setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0) {
        return -1;
    }
#ifdef SO_REUSEPORT
    if (setsockopt(fd, SOL_SOCKET, SO_REUSEPORT, &one, sizeof one) != 0) {
        return -1;
    }
#endif
    (void)setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = bus->port_be;
    a.sin_addr.s_addr = htonl(INADDR_ANY); // as python-can binds
    if (bind(fd, (const struct sockaddr *)&a, sizeof a) != 0) {
        return -1;
    }
    // Join where the senders send: the route's interface (python-can) and loopback (vcan_t
    // senders without a route). One successful join suffices.
    int joined = 0;
    joined += join_(fd, bus->group_be, iface_given ? iface_be : htonl(INADDR_ANY)) == 0;
    joined += join_(fd, bus->group_be, htonl(INADDR_LOOPBACK)) == 0;
    return joined > 0 ? 0 : -1;
}

static int open_tx_(vcan_t *bus, uint32_t iface_be, bool iface_given)
{
    unsigned char ttl = 0, loop = 1;
    struct sockaddr_in dst, own;
    socklen_t own_len = sizeof own;
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    if (fd < 0) {
        return -1;
    }
    bus->tx_fd = fd;
    if (setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl) != 0 ||
        setsockopt(fd, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof loop) != 0) {
        return -1;
    }
    struct in_addr ifa;
    ifa.s_addr = iface_be;
    if (iface_given && setsockopt(fd, IPPROTO_IP, IP_MULTICAST_IF, &ifa, sizeof ifa) != 0) {
        return -1;
    }
    memset(&dst, 0, sizeof dst);
    dst.sin_family = AF_INET;
    dst.sin_port = bus->port_be;
    dst.sin_addr.s_addr = bus->group_be;
    // connect() picks the route (and so the source address) once; it fails without a route.
    if (connect(fd, (const struct sockaddr *)&dst, sizeof dst) != 0) {
        if (iface_given || (errno != ENETUNREACH && errno != EHOSTUNREACH)) {
            return -1;
        }
        ifa.s_addr = htonl(INADDR_LOOPBACK);
        if (setsockopt(fd, IPPROTO_IP, IP_MULTICAST_IF, &ifa, sizeof ifa) != 0 ||
            connect(fd, (const struct sockaddr *)&dst, sizeof dst) != 0) {
            return -1;
        }
    }
    if (getsockname(fd, (struct sockaddr *)&own, &own_len) != 0) {
        return -1;
    }
    bus->own_addr_be = own.sin_addr.s_addr;
    bus->own_port_be = own.sin_port;
    return 0;
}

int vcan_open(vcan_t *bus, const vcan_config_t *cfg)
{
    vcan_config_t defaults;
    struct in_addr group, iface;
    if (bus == NULL) {
        return FW_ERR_INVAL;
    }
    memset(bus, 0, sizeof *bus);
    bus->rx_fd = -1;
    bus->tx_fd = -1;
    if (cfg == NULL) {
        vcan_default_config(&defaults);
        cfg = &defaults;
    }
    if (inet_pton(AF_INET, cfg->group != NULL ? cfg->group : VCAN_DEFAULT_GROUP, &group) != 1 ||
        !IN_MULTICAST(ntohl(group.s_addr))) {
        return FW_ERR_INVAL;
    }
    bool iface_given = cfg->iface != NULL;
    iface.s_addr = htonl(INADDR_ANY);
    if (iface_given && inet_pton(AF_INET, cfg->iface, &iface) != 1) {
        return FW_ERR_INVAL;
    }
    bus->group_be = group.s_addr;
    bus->port_be = htons(cfg->port != 0u ? cfg->port : (uint16_t)VCAN_DEFAULT_PORT);
    bus->tx_gap_us = cfg->tx_gap_us;
    bus->receive_own = cfg->receive_own;
    if (open_rx_(bus, iface.s_addr, iface_given) != 0 || open_tx_(bus, iface.s_addr, iface_given) != 0) {
        int saved = errno;
        vcan_close(bus);
        errno = saved;
        return FW_ERR_IO;
    }
    return FW_OK;
}

int vcan_send(vcan_t *bus, const hal_can_frame_t *frame, double timestamp)
{
    uint8_t buf[VCAN_DATAGRAM_MAX];
    int n = vcan_encode(frame, timestamp, buf, sizeof buf);
    if (n < 0) {
        bus->stats.tx_errors++;
        return FW_ERR_INVAL;
    }
    if (bus->tx_gap_us > 0u && bus->sent_once) {
        double wait = bus->last_tx_s + (double)bus->tx_gap_us * 1e-6 - clock_s_(CLOCK_MONOTONIC);
        if (wait > 0.0) {
            struct timespec ts;
            ts.tv_sec = (time_t)wait;
            ts.tv_nsec = (long)((wait - (double)ts.tv_sec) * 1e9);
            while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
            }
        }
    }
    ssize_t sent;
    do {
        sent = send(bus->tx_fd, buf, (size_t)n, MSG_DONTWAIT);
    } while (sent < 0 && errno == EINTR);
    bus->last_tx_s = clock_s_(CLOCK_MONOTONIC);
    bus->sent_once = true;
    if (sent != (ssize_t)n) {
        bus->stats.tx_errors++;
        return (sent < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS)) ? FW_ERR_FULL
                                                                                           : FW_ERR_IO;
    }
    bus->stats.tx_frames++;
    return FW_OK;
}

int vcan_recv_stamped(vcan_t *bus, hal_can_frame_t *frame, double *timestamp, int timeout_ms)
{
    // Large enough for any python-can message (CAN FD with 64 bytes and a channel name), so a
    // longer datagram is garbage by definition.
    uint8_t buf[512];
    if (bus->rx_fd < 0) {
        return FW_ERR_IO; // vcan_close_rx(): poll() would ignore the descriptor and wait
    }
    double deadline = clock_s_(CLOCK_MONOTONIC) + (double)timeout_ms * 1e-3;
    for (;;) {
        int wait_ms = timeout_ms;
        if (timeout_ms > 0) {
            double left = deadline - clock_s_(CLOCK_MONOTONIC);
            wait_ms = left > 0.0 ? (int)ceil(left * 1e3) : 0;
        }
        struct pollfd p = {bus->rx_fd, POLLIN, 0};
        int ready = poll(&p, 1, wait_ms);
        if (ready < 0) {
            if (errno == EINTR) {
                continue;
            }
            return FW_ERR_IO;
        }
        if (ready == 0) {
            return 0;
        }
        struct sockaddr_in src;
        socklen_t src_len = sizeof src;
        ssize_t n = recvfrom(bus->rx_fd, buf, sizeof buf, MSG_DONTWAIT | MSG_TRUNC,
                             (struct sockaddr *)&src, &src_len);
        if (n < 0) {
            if (errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK) {
                continue;
            }
            return FW_ERR_IO;
        }
        if (!bus->receive_own && src.sin_addr.s_addr == bus->own_addr_be &&
            src.sin_port == bus->own_port_be) {
            bus->stats.rx_own++;
        } else if ((size_t)n > sizeof buf) { // MSG_TRUNC: n is the datagram's real length
            bus->stats.rx_malformed++;
        } else {
            int rc = vcan_decode(buf, (size_t)n, frame, timestamp);
            if (rc == FW_OK) {
                bus->stats.rx_frames++;
                return 1;
            }
            if (rc == FW_ERR_NOSYS) {
                bus->stats.rx_unsupported++;
            } else {
                bus->stats.rx_malformed++;
            }
        }
        // Skipped: wait again for what is left of the timeout (0: drain what is queued).
    }
}

int vcan_recv(vcan_t *bus, hal_can_frame_t *frame, int timeout_ms)
{
    return vcan_recv_stamped(bus, frame, NULL, timeout_ms);
}

int vcan_fileno(const vcan_t *bus)
{
    return bus->rx_fd;
}

void vcan_get_stats(const vcan_t *bus, vcan_stats_t *out)
{
    *out = bus->stats;
}

void vcan_close_rx(vcan_t *bus)
{
    if (bus != NULL && bus->rx_fd >= 0) {
        close(bus->rx_fd);
        bus->rx_fd = -1;
    }
}

void vcan_close(vcan_t *bus)
{
    if (bus == NULL) {
        return;
    }
    if (bus->rx_fd >= 0) {
        close(bus->rx_fd);
    }
    if (bus->tx_fd >= 0) {
        close(bus->tx_fd);
    }
    bus->rx_fd = -1;
    bus->tx_fd = -1;
}
