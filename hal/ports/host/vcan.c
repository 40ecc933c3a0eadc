// SPDX-License-Identifier: MIT
// dynaqpc host port: the virtual CAN bus (python-can udp_multicast wire format).
//
// Why a hand-written msgpack codec: the map has eleven fixed keys and scalar values, so encoding
// is a fixed sequence of ~30 byte writes, and decoding a bounded walk over a byte range. msgpack-c
// allocates (zones) and its C++ half drags in Boost; this file allocates nothing.
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

FW_STATIC_ASSERT(VCAN_DATAGRAM_MAX >= 164u, datagram_max_holds_a_frame);

// ---------------------------------------------------------------------------------------------
// msgpack encoder

typedef struct writer {
    uint8_t *buf;
    size_t cap;
    size_t len;
    bool overflow;
} writer_t;

static void put_u8_(writer_t *w, uint8_t b)
{
    if (w->len < w->cap) {
        w->buf[w->len++] = b;
    } else {
        w->overflow = true;
    }
}

static void put_be_(writer_t *w, uint64_t v, unsigned bytes)
{
    while (bytes-- > 0u) {
        put_u8_(w, (uint8_t)(v >> (8u * bytes)));
    }
}

static void put_key_(writer_t *w, const char *key)
{
    size_t n = strlen(key); // every key is < 32 bytes: fixstr
    put_u8_(w, (uint8_t)(0xA0u | n));
    for (size_t i = 0; i < n; i++) {
        put_u8_(w, (uint8_t)key[i]);
    }
}

static void put_bool_(writer_t *w, bool b)
{
    put_u8_(w, b ? 0xC3u : 0xC2u);
}

// msgpack-python packs a non-negative int in the smallest form.
static void put_uint_(writer_t *w, uint32_t v)
{
    if (v <= 0x7Fu) {
        put_u8_(w, (uint8_t)v);
    } else if (v <= 0xFFu) {
        put_u8_(w, 0xCCu);
        put_be_(w, v, 1);
    } else if (v <= 0xFFFFu) {
        put_u8_(w, 0xCDu);
        put_be_(w, v, 2);
    } else {
        put_u8_(w, 0xCEu);
        put_be_(w, v, 4);
    }
}

static bool frame_is_valid_(const hal_can_frame_t *f)
{
    uint32_t max = (f->flags & HAL_CAN_FLAG_EXTENDED) ? HAL_CAN_EXT_ID_MAX : HAL_CAN_STD_ID_MAX;
    return f->dlc <= HAL_CAN_MAX_DLC && f->id <= max &&
           (f->flags & ~(HAL_CAN_FLAG_EXTENDED | HAL_CAN_FLAG_REMOTE)) == 0u;
}

int vcan_encode(const hal_can_frame_t *frame, double timestamp, uint8_t *buf, size_t cap)
{
    if (frame == NULL || buf == NULL || !frame_is_valid_(frame) || !isfinite(timestamp) ||
        timestamp < 0.0) {
        return FW_ERR_INVAL;
    }
    bool remote = (frame->flags & HAL_CAN_FLAG_REMOTE) != 0u;
    uint8_t n_data = remote ? 0u : frame->dlc; // python-can: remote frames carry no data
    uint64_t ts_bits;
    memcpy(&ts_bits, &timestamp, sizeof ts_bits);

    writer_t w = {buf, cap, 0u, false};
    put_u8_(&w, 0x80u | 11u); // fixmap, 11 entries, in python-can's pack_message() order
    put_key_(&w, "timestamp");
    put_u8_(&w, 0xCBu); // float64
    put_be_(&w, ts_bits, 8);
    put_key_(&w, "arbitration_id");
    put_uint_(&w, frame->id);
    put_key_(&w, "is_extended_id");
    put_bool_(&w, (frame->flags & HAL_CAN_FLAG_EXTENDED) != 0u);
    put_key_(&w, "is_remote_frame");
    put_bool_(&w, remote);
    put_key_(&w, "is_error_frame");
    put_bool_(&w, false);
    put_key_(&w, "channel");
    put_u8_(&w, 0xC0u); // nil
    put_key_(&w, "dlc");
    put_uint_(&w, frame->dlc);
    put_key_(&w, "data");
    put_u8_(&w, 0xC4u); // bin 8
    put_u8_(&w, n_data);
    for (uint8_t i = 0; i < n_data; i++) {
        put_u8_(&w, frame->data[i]);
    }
    put_key_(&w, "is_fd");
    put_bool_(&w, false);
    put_key_(&w, "bitrate_switch");
    put_bool_(&w, false);
    put_key_(&w, "error_state_indicator");
    put_bool_(&w, false);
    return w.overflow ? FW_ERR_NOMEM : (int)w.len;
}

// ---------------------------------------------------------------------------------------------
// msgpack decoder: every read checks the bytes left; any surprise rejects the datagram.

typedef struct reader {
    const uint8_t *p;
    size_t left;
} reader_t;

static bool get_bytes_(reader_t *r, size_t n, const uint8_t **out)
{
    if (n > r->left) {
        return false;
    }
    *out = r->p;
    r->p += n;
    r->left -= n;
    return true;
}

static bool get_be_(reader_t *r, unsigned n, uint64_t *v)
{
    const uint8_t *b;
    if (!get_bytes_(r, n, &b)) {
        return false;
    }
    *v = 0;
    for (unsigned i = 0; i < n; i++) {
        *v = (*v << 8) | b[i];
    }
    return true;
}

static bool get_tag_(reader_t *r, uint8_t *tag)
{
    const uint8_t *b;
    if (!get_bytes_(r, 1, &b)) {
        return false;
    }
    *tag = *b;
    return true;
}

/// A str's bytes, given its tag.
static bool get_str_body_(reader_t *r, uint8_t tag, const uint8_t **s, size_t *n)
{
    uint64_t len;
    if ((tag & 0xE0u) == 0xA0u) {
        len = tag & 0x1Fu;
    } else if (tag == 0xD9u || tag == 0xDAu || tag == 0xDBu) {
        if (!get_be_(r, tag == 0xD9u ? 1u : (tag == 0xDAu ? 2u : 4u), &len)) {
            return false;
        }
    } else {
        return false;
    }
    if (len > r->left) {
        return false;
    }
    *n = (size_t)len;
    return get_bytes_(r, *n, s);
}

/// An integer, given its tag: *neg set for negative values (magnitude irrelevant to callers).
static bool get_int_body_(reader_t *r, uint8_t tag, uint64_t *v, bool *neg)
{
    *neg = false;
    if (tag <= 0x7Fu) {
        *v = tag;
        return true;
    }
    if (tag >= 0xE0u) { // negative fixint
        *neg = true;
        *v = 0;
        return true;
    }
    if (tag >= 0xCCu && tag <= 0xCFu) { // uint 8/16/32/64
        return get_be_(r, 1u << (tag - 0xCCu), v);
    }
    if (tag >= 0xD0u && tag <= 0xD3u) { // int 8/16/32/64
        unsigned n = 1u << (tag - 0xD0u);
        if (!get_be_(r, n, v)) {
            return false;
        }
        *neg = ((*v >> (8u * n - 1u)) & 1u) != 0u;
        return true;
    }
    return false;
}

static bool get_uint_(reader_t *r, uint64_t *v)
{
    uint8_t tag;
    bool neg;
    return get_tag_(r, &tag) && get_int_body_(r, tag, v, &neg) && !neg;
}

static bool get_bool_(reader_t *r, bool *b)
{
    uint8_t tag;
    if (!get_tag_(r, &tag) || (tag != 0xC2u && tag != 0xC3u)) {
        return false;
    }
    *b = tag == 0xC3u;
    return true;
}

static bool get_number_(reader_t *r, double *d)
{
    uint8_t tag;
    uint64_t bits;
    bool neg;
    if (!get_tag_(r, &tag)) {
        return false;
    }
    if (tag == 0xCBu) {
        if (!get_be_(r, 8, &bits)) {
            return false;
        }
        memcpy(d, &bits, sizeof *d);
        return true;
    }
    if (tag == 0xCAu) {
        float f;
        uint32_t b32;
        if (!get_be_(r, 4, &bits)) {
            return false;
        }
        b32 = (uint32_t)bits;
        memcpy(&f, &b32, sizeof f);
        *d = (double)f;
        return true;
    }
    if (!get_int_body_(r, tag, &bits, &neg)) {
        return false;
    }
    *d = neg ? -1.0 : (double)bits; // negative timestamps are rejected later
    return true;
}

enum {
    KEY_TIMESTAMP,
    KEY_ID,
    KEY_EXTENDED,
    KEY_REMOTE,
    KEY_ERROR,
    KEY_CHANNEL,
    KEY_DLC,
    KEY_DATA,
    KEY_FD,
    KEY_BRS,
    KEY_ESI,
    KEY_COUNT
};

static const char *const key_names[KEY_COUNT] = {
    "timestamp", "arbitration_id", "is_extended_id", "is_remote_frame",
    "is_error_frame", "channel", "dlc", "data", "is_fd", "bitrate_switch",
    "error_state_indicator"};

static int key_lookup_(const uint8_t *s, size_t n)
{
    for (int k = 0; k < KEY_COUNT; k++) {
        if (strlen(key_names[k]) == n && memcmp(key_names[k], s, n) == 0) {
            return k;
        }
    }
    return -1;
}

int vcan_decode(const uint8_t *buf, size_t len, hal_can_frame_t *frame, double *timestamp)
{
    if (buf == NULL || frame == NULL) {
        return FW_ERR_INVAL;
    }
    reader_t r = {buf, len};
    uint8_t tag;
    uint64_t n_keys;
    if (!get_tag_(&r, &tag)) {
        return FW_ERR_CORRUPT;
    }
    if ((tag & 0xF0u) == 0x80u) {
        n_keys = tag & 0x0Fu;
    } else if (tag == 0xDEu || tag == 0xDFu) {
        if (!get_be_(&r, tag == 0xDEu ? 2u : 4u, &n_keys)) {
            return FW_ERR_CORRUPT;
        }
    } else {
        return FW_ERR_CORRUPT;
    }
    if (n_keys > KEY_COUNT) { // more keys than names: a repeat or an unknown key
        return FW_ERR_CORRUPT;
    }

    // python-can's Message() defaults for missing keys.
    double ts = 0.0;
    uint64_t id = 0, dlc = 0;
    bool flag[KEY_COUNT] = {false};
    bool seen[KEY_COUNT] = {false};
    flag[KEY_EXTENDED] = true;
    const uint8_t *data = NULL;
    size_t n_data = 0;

    for (uint64_t i = 0; i < n_keys; i++) {
        const uint8_t *s;
        size_t n;
        if (!get_tag_(&r, &tag) || !get_str_body_(&r, tag, &s, &n)) {
            return FW_ERR_CORRUPT;
        }
        int key = key_lookup_(s, n);
        if (key < 0 || seen[key]) {
            return FW_ERR_CORRUPT;
        }
        seen[key] = true;
        bool ok;
        switch (key) {
        case KEY_TIMESTAMP:
            ok = get_number_(&r, &ts);
            break;
        case KEY_ID:
            ok = get_uint_(&r, &id);
            break;
        case KEY_DLC:
            ok = get_uint_(&r, &dlc);
            break;
        case KEY_CHANNEL: { // nil, a name or a number; ignored
            uint64_t v;
            bool neg;
            ok = get_tag_(&r, &tag) &&
                 (tag == 0xC0u || get_str_body_(&r, tag, &s, &n) || get_int_body_(&r, tag, &v, &neg));
            break;
        }
        case KEY_DATA: {
            uint64_t blen = 0;
            ok = get_tag_(&r, &tag);
            if (ok && tag == 0xC0u) {
                data = NULL; // data=None: empty
                n_data = 0;
            } else if (ok && tag >= 0xC4u && tag <= 0xC6u) {
                ok = get_be_(&r, 1u << (tag - 0xC4u), &blen) && blen <= r.left &&
                     get_bytes_(&r, (size_t)blen, &data);
                n_data = (size_t)blen;
            } else {
                ok = false;
            }
            break;
        }
        default:
            ok = get_bool_(&r, &flag[key]);
            break;
        }
        if (!ok) {
            return FW_ERR_CORRUPT;
        }
    }
    if (r.left != 0u) {
        return FW_ERR_CORRUPT; // trailing bytes: msgpack.unpackb() raises ExtraData too
    }
    if (!seen[KEY_DLC]) {
        dlc = n_data;
    }

    // python-can's Message._check(), in its order.
    bool fd = flag[KEY_FD], remote = flag[KEY_REMOTE], ext = flag[KEY_EXTENDED];
    if (!isfinite(ts) || ts < 0.0) {
        return FW_ERR_CORRUPT;
    }
    if (remote && (flag[KEY_ERROR] || fd)) {
        return FW_ERR_CORRUPT;
    }
    if (id > (ext ? HAL_CAN_EXT_ID_MAX : HAL_CAN_STD_ID_MAX)) {
        return FW_ERR_CORRUPT;
    }
    if (dlc > (fd ? 64u : HAL_CAN_MAX_DLC)) {
        return FW_ERR_CORRUPT;
    }
    if (remote ? n_data != 0u : dlc != n_data) {
        return FW_ERR_CORRUPT;
    }
    if (!fd && (flag[KEY_BRS] || flag[KEY_ESI])) {
        return FW_ERR_CORRUPT;
    }
    if (fd || flag[KEY_ERROR]) {
        return FW_ERR_NOSYS; // valid, but not a classic data or remote frame
    }

    memset(frame, 0, sizeof *frame);
    frame->id = (uint32_t)id;
    frame->dlc = (uint8_t)dlc;
    frame->flags = (uint8_t)((ext ? HAL_CAN_FLAG_EXTENDED : 0u) | (remote ? HAL_CAN_FLAG_REMOTE : 0u));
    if (n_data > 0u) {
        memcpy(frame->data, data, n_data);
    }
    if (timestamp != NULL) {
        *timestamp = ts;
    }
    return FW_OK;
}

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
