// SPDX-License-Identifier: MIT
// dynaqpc host_sim transport: the virtual CAN bus's datagram codec (python-can udp_multicast).
//
// Why a hand-written msgpack codec: the map has eleven fixed keys and scalar values, so encoding
// is a fixed sequence of ~30 byte writes, and decoding a bounded walk over a byte range. msgpack-c
// allocates (zones) and its C++ half drags in Boost; this file allocates nothing and does no I/O.
#include "vcan_codec.h"

#include <math.h>
#include <string.h>

#include "msgpack_tags.h"

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
    size_t n = strlen(key); // every key is < 32 bytes: a fixstr
    put_u8_(w, (uint8_t)(MSGPACK_FIXSTR | n));
    for (size_t i = 0; i < n; i++) {
        put_u8_(w, (uint8_t)key[i]);
    }
}

// An entry of the map: its key, then a bool.
static void put_bool_entry_(writer_t *w, const char *key, bool b)
{
    put_key_(w, key);
    put_u8_(w, b ? MSGPACK_TRUE : MSGPACK_FALSE);
}

// An entry of the map: its key, then a non-negative int in the smallest form, as msgpack-python
// packs it.
static void put_uint_entry_(writer_t *w, const char *key, uint32_t v)
{
    put_key_(w, key);
    if (v <= MSGPACK_POSFIXINT_MAX) {
        put_u8_(w, (uint8_t)v);
    } else if (v <= 0xFFu) {
        put_u8_(w, MSGPACK_UINT8);
        put_be_(w, v, 1);
    } else if (v <= 0xFFFFu) {
        put_u8_(w, MSGPACK_UINT16);
        put_be_(w, v, 2);
    } else {
        put_u8_(w, MSGPACK_UINT32);
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
    put_u8_(&w, MSGPACK_FIXMAP | 11u); // 11 entries, in python-can's pack_message() order
    put_key_(&w, "timestamp");
    put_u8_(&w, MSGPACK_FLOAT64);
    put_be_(&w, ts_bits, 8);
    put_uint_entry_(&w, "arbitration_id", frame->id);
    put_bool_entry_(&w, "is_extended_id", (frame->flags & HAL_CAN_FLAG_EXTENDED) != 0u);
    put_bool_entry_(&w, "is_remote_frame", remote);
    put_bool_entry_(&w, "is_error_frame", false);
    put_key_(&w, "channel");
    put_u8_(&w, MSGPACK_NIL);
    put_uint_entry_(&w, "dlc", frame->dlc);
    put_key_(&w, "data");
    put_u8_(&w, MSGPACK_BIN8);
    put_u8_(&w, n_data);
    for (uint8_t i = 0; i < n_data; i++) {
        put_u8_(&w, frame->data[i]);
    }
    put_bool_entry_(&w, "is_fd", false);
    put_bool_entry_(&w, "bitrate_switch", false);
    put_bool_entry_(&w, "error_state_indicator", false);
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
    if ((tag & MSGPACK_FIXSTR_MASK) == MSGPACK_FIXSTR) {
        len = tag & (uint8_t)~MSGPACK_FIXSTR_MASK;
    } else if (tag == MSGPACK_STR8 || tag == MSGPACK_STR16 || tag == MSGPACK_STR32) {
        if (!get_be_(r, 1u << (tag - MSGPACK_STR8), &len)) {
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
    if (tag <= MSGPACK_POSFIXINT_MAX) {
        *v = tag;
        return true;
    }
    if (tag >= MSGPACK_NEGFIXINT) {
        *neg = true;
        *v = 0;
        return true;
    }
    if (tag >= MSGPACK_UINT8 && tag <= MSGPACK_UINT64) {
        return get_be_(r, 1u << (tag - MSGPACK_UINT8), v);
    }
    if (tag >= MSGPACK_INT8 && tag <= MSGPACK_INT64) {
        unsigned n = 1u << (tag - MSGPACK_INT8);
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
    if (!get_tag_(r, &tag) || (tag != MSGPACK_FALSE && tag != MSGPACK_TRUE)) {
        return false;
    }
    *b = tag == MSGPACK_TRUE;
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
    if (tag == MSGPACK_FLOAT64) {
        if (!get_be_(r, 8, &bits)) {
            return false;
        }
        memcpy(d, &bits, sizeof *d);
        return true;
    }
    if (tag == MSGPACK_FLOAT32) {
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
    if ((tag & MSGPACK_FIXMAP_MASK) == MSGPACK_FIXMAP) {
        n_keys = tag & (uint8_t)~MSGPACK_FIXMAP_MASK;
    } else if (tag == MSGPACK_MAP16 || tag == MSGPACK_MAP32) {
        if (!get_be_(&r, tag == MSGPACK_MAP16 ? 2u : 4u, &n_keys)) {
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
                 (tag == MSGPACK_NIL || get_str_body_(&r, tag, &s, &n) || get_int_body_(&r, tag, &v, &neg));
            break;
        }
        case KEY_DATA: {
            uint64_t blen = 0;
            ok = get_tag_(&r, &tag);
            if (ok && tag == MSGPACK_NIL) {
                data = NULL; // data=None: empty
                n_data = 0;
            } else if (ok && tag >= MSGPACK_BIN8 && tag <= MSGPACK_BIN32) {
                ok = get_be_(&r, 1u << (tag - MSGPACK_BIN8), &blen) && blen <= r.left &&
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
