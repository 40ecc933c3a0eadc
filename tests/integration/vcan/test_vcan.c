// SPDX-License-Identifier: MIT
// Tests of the virtual CAN bus (msgpack codec against python-can's bytes, garbage rejection,
// fuzzing, a loop-back exchange over real sockets) and of the pty serial line.
//
// ctest runs this inside a private network namespace (netns.sh). The socket tests fail, never
// skip, when the bus does not carry frames.
#define _DEFAULT_SOURCE 1

#include "test_common.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "fw/fw_prng.h"
#include "fw/fw_base.h"
#include "pty.h"
#include "vcan.h"

// Bytes produced by python-can 4.6.1 + msgpack 1.1 on this machine:
//   from can.interfaces.udp_multicast.utils import pack_message
//   pack_message(can.Message(timestamp=1.5, arbitration_id=0x123, is_extended_id=False,
//                            data=bytes([1, 2, 3])))
static const uint8_t py_std_3[] = {
    0x8B, 0xA9, 0x74, 0x69, 0x6D, 0x65, 0x73, 0x74, 0x61, 0x6D, 0x70, 0xCB, 0x3F, 0xF8, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0xAE, 0x61, 0x72, 0x62, 0x69, 0x74, 0x72, 0x61, 0x74, 0x69, 0x6F, 0x6E,
    0x5F, 0x69, 0x64, 0xCD, 0x01, 0x23, 0xAE, 0x69, 0x73, 0x5F, 0x65, 0x78, 0x74, 0x65, 0x6E, 0x64,
    0x65, 0x64, 0x5F, 0x69, 0x64, 0xC2, 0xAF, 0x69, 0x73, 0x5F, 0x72, 0x65, 0x6D, 0x6F, 0x74, 0x65,
    0x5F, 0x66, 0x72, 0x61, 0x6D, 0x65, 0xC2, 0xAE, 0x69, 0x73, 0x5F, 0x65, 0x72, 0x72, 0x6F, 0x72,
    0x5F, 0x66, 0x72, 0x61, 0x6D, 0x65, 0xC2, 0xA7, 0x63, 0x68, 0x61, 0x6E, 0x6E, 0x65, 0x6C, 0xC0,
    0xA3, 0x64, 0x6C, 0x63, 0x03, 0xA4, 0x64, 0x61, 0x74, 0x61, 0xC4, 0x03, 0x01, 0x02, 0x03, 0xA5,
    0x69, 0x73, 0x5F, 0x66, 0x64, 0xC2, 0xAE, 0x62, 0x69, 0x74, 0x72, 0x61, 0x74, 0x65, 0x5F, 0x73,
    0x77, 0x69, 0x74, 0x63, 0x68, 0xC2, 0xB5, 0x65, 0x72, 0x72, 0x6F, 0x72, 0x5F, 0x73, 0x74, 0x61,
    0x74, 0x65, 0x5F, 0x69, 0x6E, 0x64, 0x69, 0x63, 0x61, 0x74, 0x6F, 0x72, 0xC2};

//   pack_message(can.Message(timestamp=1700000000.25, arbitration_id=0x1ABCDE0,
//                            is_extended_id=True, data=bytes(range(0xA0, 0xA8))))
static const uint8_t py_ext_8[] = {
    0x8B, 0xA9, 0x74, 0x69, 0x6D, 0x65, 0x73, 0x74, 0x61, 0x6D, 0x70, 0xCB, 0x41, 0xD9, 0x54, 0xFC,
    0x40, 0x10, 0x00, 0x00, 0xAE, 0x61, 0x72, 0x62, 0x69, 0x74, 0x72, 0x61, 0x74, 0x69, 0x6F, 0x6E,
    0x5F, 0x69, 0x64, 0xCE, 0x01, 0xAB, 0xCD, 0xE0, 0xAE, 0x69, 0x73, 0x5F, 0x65, 0x78, 0x74, 0x65,
    0x6E, 0x64, 0x65, 0x64, 0x5F, 0x69, 0x64, 0xC3, 0xAF, 0x69, 0x73, 0x5F, 0x72, 0x65, 0x6D, 0x6F,
    0x74, 0x65, 0x5F, 0x66, 0x72, 0x61, 0x6D, 0x65, 0xC2, 0xAE, 0x69, 0x73, 0x5F, 0x65, 0x72, 0x72,
    0x6F, 0x72, 0x5F, 0x66, 0x72, 0x61, 0x6D, 0x65, 0xC2, 0xA7, 0x63, 0x68, 0x61, 0x6E, 0x6E, 0x65,
    0x6C, 0xC0, 0xA3, 0x64, 0x6C, 0x63, 0x08, 0xA4, 0x64, 0x61, 0x74, 0x61, 0xC4, 0x08, 0xA0, 0xA1,
    0xA2, 0xA3, 0xA4, 0xA5, 0xA6, 0xA7, 0xA5, 0x69, 0x73, 0x5F, 0x66, 0x64, 0xC2, 0xAE, 0x62, 0x69,
    0x74, 0x72, 0x61, 0x74, 0x65, 0x5F, 0x73, 0x77, 0x69, 0x74, 0x63, 0x68, 0xC2, 0xB5, 0x65, 0x72,
    0x72, 0x6F, 0x72, 0x5F, 0x73, 0x74, 0x61, 0x74, 0x65, 0x5F, 0x69, 0x6E, 0x64, 0x69, 0x63, 0x61,
    0x74, 0x6F, 0x72, 0xC2};

//   pack_message(can.Message(timestamp=2.0, arbitration_id=0x7FF, is_extended_id=False,
//                            is_remote_frame=True, dlc=4))
static const uint8_t py_remote_4[] = {
    0x8B, 0xA9, 0x74, 0x69, 0x6D, 0x65, 0x73, 0x74, 0x61, 0x6D, 0x70, 0xCB, 0x40, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0xAE, 0x61, 0x72, 0x62, 0x69, 0x74, 0x72, 0x61, 0x74, 0x69, 0x6F, 0x6E,
    0x5F, 0x69, 0x64, 0xCD, 0x07, 0xFF, 0xAE, 0x69, 0x73, 0x5F, 0x65, 0x78, 0x74, 0x65, 0x6E, 0x64,
    0x65, 0x64, 0x5F, 0x69, 0x64, 0xC2, 0xAF, 0x69, 0x73, 0x5F, 0x72, 0x65, 0x6D, 0x6F, 0x74, 0x65,
    0x5F, 0x66, 0x72, 0x61, 0x6D, 0x65, 0xC3, 0xAE, 0x69, 0x73, 0x5F, 0x65, 0x72, 0x72, 0x6F, 0x72,
    0x5F, 0x66, 0x72, 0x61, 0x6D, 0x65, 0xC2, 0xA7, 0x63, 0x68, 0x61, 0x6E, 0x6E, 0x65, 0x6C, 0xC0,
    0xA3, 0x64, 0x6C, 0x63, 0x04, 0xA4, 0x64, 0x61, 0x74, 0x61, 0xC4, 0x00, 0xA5, 0x69, 0x73, 0x5F,
    0x66, 0x64, 0xC2, 0xAE, 0x62, 0x69, 0x74, 0x72, 0x61, 0x74, 0x65, 0x5F, 0x73, 0x77, 0x69, 0x74,
    0x63, 0x68, 0xC2, 0xB5, 0x65, 0x72, 0x72, 0x6F, 0x72, 0x5F, 0x73, 0x74, 0x61, 0x74, 0x65, 0x5F,
    0x69, 0x6E, 0x64, 0x69, 0x63, 0x61, 0x74, 0x6F, 0x72, 0xC2};

static hal_can_frame_t make_frame(uint32_t id, uint8_t flags, uint8_t dlc, uint8_t first)
{
    hal_can_frame_t f;
    memset(&f, 0, sizeof f);
    f.id = id;
    f.flags = flags;
    f.dlc = dlc;
    if ((flags & HAL_CAN_FLAG_REMOTE) == 0u) {
        for (uint8_t i = 0; i < dlc; i++) {
            f.data[i] = (uint8_t)(first + i);
        }
    }
    return f;
}

static void assert_frame_equal(const hal_can_frame_t *a, const hal_can_frame_t *b)
{
    assert_int_equal(a->id, b->id);
    assert_int_equal(a->dlc, b->dlc);
    assert_int_equal(a->flags, b->flags);
    assert_memory_equal(a->data, b->data, HAL_CAN_MAX_DLC);
}

static void encode_matches_python_can_bytes(void **state)
{
    (void)state;
    uint8_t buf[VCAN_DATAGRAM_MAX];
    hal_can_frame_t f = make_frame(0x123, 0, 3, 1);
    assert_int_equal(vcan_encode(&f, 1.5, buf, sizeof buf), (int)sizeof py_std_3);
    assert_memory_equal(buf, py_std_3, sizeof py_std_3);

    f = make_frame(0x1ABCDE0, HAL_CAN_FLAG_EXTENDED, 8, 0xA0);
    assert_int_equal(vcan_encode(&f, 1700000000.25, buf, sizeof buf), (int)sizeof py_ext_8);
    assert_memory_equal(buf, py_ext_8, sizeof py_ext_8);

    f = make_frame(0x7FF, HAL_CAN_FLAG_REMOTE, 4, 0);
    assert_int_equal(vcan_encode(&f, 2.0, buf, sizeof buf), (int)sizeof py_remote_4);
    assert_memory_equal(buf, py_remote_4, sizeof py_remote_4);
}

static void decode_python_can_bytes(void **state)
{
    (void)state;
    hal_can_frame_t f, want;
    double ts = -1.0;
    assert_int_equal(vcan_decode(py_ext_8, sizeof py_ext_8, &f, &ts), FW_OK);
    want = make_frame(0x1ABCDE0, HAL_CAN_FLAG_EXTENDED, 8, 0xA0);
    assert_frame_equal(&f, &want);
    assert_true(ts == 1700000000.25);
    assert_int_equal(vcan_decode(py_remote_4, sizeof py_remote_4, &f, NULL), FW_OK);
    want = make_frame(0x7FF, HAL_CAN_FLAG_REMOTE, 4, 0);
    assert_frame_equal(&f, &want);
}

static void round_trip_every_dlc_and_id_kind(void **state)
{
    (void)state;
    static const uint32_t std_ids[] = {0, 1, 0x7F, 0x80, 0xFF, 0x100, 0x7FF};
    static const uint32_t ext_ids[] = {0, 0x7FF, 0x800, 0xFFFF, 0x10000, 0x1FFFFFFF};
    uint8_t buf[VCAN_DATAGRAM_MAX];
    for (uint8_t dlc = 0; dlc <= HAL_CAN_MAX_DLC; dlc++) {
        for (int kind = 0; kind < 3; kind++) {
            const uint32_t *ids = kind == 1 ? ext_ids : std_ids;
            size_t n_ids = kind == 1 ? sizeof ext_ids / sizeof ext_ids[0] : sizeof std_ids / sizeof std_ids[0];
            uint8_t flags = kind == 1 ? HAL_CAN_FLAG_EXTENDED : (kind == 2 ? HAL_CAN_FLAG_REMOTE : 0u);
            for (size_t i = 0; i < n_ids; i++) {
                hal_can_frame_t f = make_frame(ids[i], flags, dlc, (uint8_t)(0xF0 + i)), g;
                double ts = 12345.678 + dlc, back = 0.0;
                int n = vcan_encode(&f, ts, buf, sizeof buf);
                assert_true(n > 0 && n <= (int)VCAN_DATAGRAM_MAX);
                memset(&g, 0xEE, sizeof g);
                assert_int_equal(vcan_decode(buf, (size_t)n, &g, &back), FW_OK);
                assert_frame_equal(&f, &g);
                assert_true(back == ts);
            }
        }
    }
}

static void encode_refuses_bad_frames(void **state)
{
    (void)state;
    uint8_t buf[VCAN_DATAGRAM_MAX];
    hal_can_frame_t f = make_frame(0x800, 0, 1, 0);
    assert_int_equal(vcan_encode(&f, 0.0, buf, sizeof buf), FW_ERR_INVAL); // 12-bit std id
    f = make_frame(0x20000000, HAL_CAN_FLAG_EXTENDED, 1, 0);
    assert_int_equal(vcan_encode(&f, 0.0, buf, sizeof buf), FW_ERR_INVAL);
    f = make_frame(1, 0, 8, 0);
    f.dlc = 9;
    assert_int_equal(vcan_encode(&f, 0.0, buf, sizeof buf), FW_ERR_INVAL);
    f = make_frame(1, 0x80, 1, 0);
    assert_int_equal(vcan_encode(&f, 0.0, buf, sizeof buf), FW_ERR_INVAL);
    f = make_frame(1, 0, 1, 0);
    assert_int_equal(vcan_encode(&f, -1.0, buf, sizeof buf), FW_ERR_INVAL);
    assert_int_equal(vcan_encode(&f, NAN, buf, sizeof buf), FW_ERR_INVAL);
    assert_int_equal(vcan_encode(&f, INFINITY, buf, sizeof buf), FW_ERR_INVAL);
    assert_int_equal(vcan_encode(&f, 0.0, buf, 100), FW_ERR_NOMEM);
}

// A map holding only arbitration_id and data: python-can's defaults fill the rest
// (is_extended_id True, dlc = len(data), timestamp 0).
static void decode_applies_python_can_defaults(void **state)
{
    (void)state;
    static const uint8_t dgram[] = {0x82, 0xA4, 'd', 'a', 't', 'a', 0xC4, 0x02, 0x11, 0x22, 0xAE,
                                    'a', 'r', 'b', 'i', 't', 'r', 'a', 't', 'i', 'o', 'n', '_', 'i',
                                    'd', 0xD2, 0x00, 0x01, 0x00, 0x00};
    hal_can_frame_t f;
    double ts = -1.0;
    assert_int_equal(vcan_decode(dgram, sizeof dgram, &f, &ts), FW_OK);
    assert_int_equal(f.id, 0x10000);
    assert_int_equal(f.flags, HAL_CAN_FLAG_EXTENDED);
    assert_int_equal(f.dlc, 2);
    assert_int_equal(f.data[0], 0x11);
    assert_int_equal(f.data[1], 0x22);
    assert_true(ts == 0.0);
}

// Patches py_std_3 at `offset` with `bytes` and expects `rc`.
static void expect_patched(size_t offset, const uint8_t *bytes, size_t n, int rc)
{
    uint8_t buf[sizeof py_std_3];
    hal_can_frame_t f;
    memcpy(buf, py_std_3, sizeof buf);
    memcpy(buf + offset, bytes, n);
    assert_int_equal(vcan_decode(buf, sizeof buf, &f, NULL), rc);
}

// Offsets in py_std_3.
enum { OFF_TS = 12, OFF_ID = 35, OFF_EXT = 53, OFF_REMOTE = 70, OFF_ERROR = 86, OFF_CHANNEL = 95,
       OFF_DLC = 100, OFF_FD = 117, OFF_BRS = 133, OFF_ESI = 156 };

static void decode_rejects_bad_values(void **state)
{
    (void)state;
    hal_can_frame_t f;
    // Sanity of the offsets: the original decodes.
    assert_int_equal(vcan_decode(py_std_3, sizeof py_std_3, &f, NULL), FW_OK);
    static const uint8_t neg_ts[] = {0xBF, 0xF8}; // -1.5
    expect_patched(OFF_TS, neg_ts, 2, FW_ERR_CORRUPT);
    static const uint8_t nan_ts[] = {0x7F, 0xF8}; // NaN
    expect_patched(OFF_TS, nan_ts, 2, FW_ERR_CORRUPT);
    static const uint8_t id_12bit[] = {0xCD, 0x08, 0x00}; // 0x800 with is_extended_id false
    expect_patched(OFF_ID - 0, id_12bit, 3, FW_ERR_CORRUPT);
    static const uint8_t id_as_str[] = {0xA2, 'a', 'b'};
    expect_patched(OFF_ID, id_as_str, 3, FW_ERR_CORRUPT);
    static const uint8_t id_neg[] = {0xD1, 0xFF, 0xFF}; // int16 -1
    expect_patched(OFF_ID, id_neg, 3, FW_ERR_CORRUPT);
    static const uint8_t int_not_bool[] = {0x01};
    expect_patched(OFF_EXT, int_not_bool, 1, FW_ERR_CORRUPT);
    static const uint8_t dlc2[] = {0x02};
    expect_patched(OFF_DLC, dlc2, 1, FW_ERR_CORRUPT); // dlc != data length
    static const uint8_t remote_with_data[] = {0xC3};
    expect_patched(OFF_REMOTE, remote_with_data, 1, FW_ERR_CORRUPT);
    static const uint8_t brs_without_fd[] = {0xC3};
    expect_patched(OFF_BRS, brs_without_fd, 1, FW_ERR_CORRUPT);
    expect_patched(OFF_ESI, brs_without_fd, 1, FW_ERR_CORRUPT);
    static const uint8_t channel_bool[] = {0xC3};
    expect_patched(OFF_CHANNEL, channel_bool, 1, FW_ERR_CORRUPT);
    static const uint8_t unknown_key[] = {'X'}; // "timestamp" -> "Ximestamp"
    expect_patched(2, unknown_key, 1, FW_ERR_CORRUPT);
    static const uint8_t not_a_map[] = {0x9B}; // fixarray
    expect_patched(0, not_a_map, 1, FW_ERR_CORRUPT);
    static const uint8_t twelve_keys[] = {0x8C};
    expect_patched(0, twelve_keys, 1, FW_ERR_CORRUPT);
    // Valid but not classic: an error frame, a CAN FD frame.
    static const uint8_t yes[] = {0xC3};
    expect_patched(OFF_ERROR, yes, 1, FW_ERR_NOSYS);
    expect_patched(OFF_FD, yes, 1, FW_ERR_NOSYS);
}

static void decode_rejects_structure_errors(void **state)
{
    (void)state;
    hal_can_frame_t f;
    uint8_t buf[sizeof py_std_3 + 4];
    // Every truncation.
    for (size_t n = 0; n < sizeof py_std_3; n++) {
        assert_int_equal(vcan_decode(py_std_3, n, &f, NULL), FW_ERR_CORRUPT);
    }
    // Trailing bytes.
    memcpy(buf, py_std_3, sizeof py_std_3);
    buf[sizeof py_std_3] = 0xC0;
    assert_int_equal(vcan_decode(buf, sizeof py_std_3 + 1, &f, NULL), FW_ERR_CORRUPT);
    // A repeated key: {"dlc": 0, "dlc": 0}.
    static const uint8_t twice[] = {0x82, 0xA3, 'd', 'l', 'c', 0x00, 0xA3, 'd', 'l', 'c', 0x00};
    assert_int_equal(vcan_decode(twice, sizeof twice, &f, NULL), FW_ERR_CORRUPT);
    // A key that is not a string.
    static const uint8_t int_key[] = {0x81, 0x01, 0x00};
    assert_int_equal(vcan_decode(int_key, sizeof int_key, &f, NULL), FW_ERR_CORRUPT);
    // bin length beyond the datagram.
    static const uint8_t long_bin[] = {0x81, 0xA4, 'd', 'a', 't', 'a', 0xC6, 0xFF, 0xFF, 0xFF, 0xFF, 0x00};
    assert_int_equal(vcan_decode(long_bin, sizeof long_bin, &f, NULL), FW_ERR_CORRUPT);
    // Nine data bytes on a classic frame.
    static const uint8_t nine[] = {0x81, 0xA4, 'd', 'a', 't', 'a', 0xC4, 0x09, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    assert_int_equal(vcan_decode(nine, sizeof nine, &f, NULL), FW_ERR_CORRUPT);
    // A map32 header claiming four billion entries.
    static const uint8_t huge_map[] = {0xDF, 0xFF, 0xFF, 0xFF, 0xFF};
    assert_int_equal(vcan_decode(huge_map, sizeof huge_map, &f, NULL), FW_ERR_CORRUPT);
    // The empty map is python-can's Message(): extended id 0, no data.
    static const uint8_t empty_map[] = {0x80};
    assert_int_equal(vcan_decode(empty_map, sizeof empty_map, &f, NULL), FW_OK);
    assert_int_equal(f.flags, HAL_CAN_FLAG_EXTENDED);
    assert_int_equal(f.dlc, 0);
}

// Mutated and random datagrams: the decoder returns one of its three answers, never reads out of
// bounds (ASan build), and what it accepts is a valid frame that survives a round trip.
static void decode_fuzz(void **state)
{
    (void)state;
    prng_t rng;
    prng_seed(&rng, 2024);
    uint8_t buf[256], again[VCAN_DATAGRAM_MAX];
    const uint8_t *seeds[] = {py_std_3, py_ext_8, py_remote_4};
    const size_t seed_len[] = {sizeof py_std_3, sizeof py_ext_8, sizeof py_remote_4};
    int accepted = 0, rejected = 0;
    for (int iter = 0; iter < 200000; iter++) {
        size_t len;
        uint32_t s = prng_below(&rng, 3);
        if (iter % 10 == 9) { // pure noise
            len = prng_below(&rng, sizeof buf);
            for (size_t i = 0; i < len; i++) {
                buf[i] = (uint8_t)prng_next(&rng);
            }
        } else {
            len = seed_len[s];
            memcpy(buf, seeds[s], len);
            uint32_t edits = 1 + prng_below(&rng, 4);
            for (uint32_t e = 0; e < edits; e++) {
                buf[prng_below(&rng, (uint32_t)len)] = (uint8_t)prng_next(&rng);
            }
            if (prng_below(&rng, 4) == 0) {
                len = prng_below(&rng, (uint32_t)len + 1);
            }
        }
        // Decode from an exactly sized copy so ASan catches any over-read.
        uint8_t *exact = (uint8_t *)buf + (sizeof buf - len);
        memmove(exact, buf, len);
        hal_can_frame_t f;
        double ts;
        int rc = vcan_decode(exact, len, &f, &ts);
        assert_true(rc == FW_OK || rc == FW_ERR_CORRUPT || rc == FW_ERR_NOSYS);
        if (rc == FW_OK) {
            accepted++;
            hal_can_frame_t g;
            int n = vcan_encode(&f, ts, again, sizeof again);
            assert_true(n > 0);
            assert_int_equal(vcan_decode(again, (size_t)n, &g, NULL), FW_OK);
            assert_frame_equal(&f, &g);
        } else {
            rejected++;
        }
    }
    // Both outcomes occur, so the fuzzer reaches past the first checks.
    assert_true(accepted > 1000);
    assert_true(rejected > 1000);
}

// ---------------------------------------------------------------------------------------------
// Sockets: two members of one bus. No skips: a bus that carries nothing fails the test.

static uint16_t test_port(void)
{
    return (uint16_t)(50000 + getpid() % 10000); // its own port: never another run's bus
}

static void open_pair(vcan_t *a, vcan_t *b, bool b_own)
{
    vcan_config_t cfg;
    vcan_default_config(&cfg);
    cfg.port = test_port();
    assert_int_equal(vcan_open(a, &cfg), FW_OK);
    cfg.receive_own = b_own;
    assert_int_equal(vcan_open(b, &cfg), FW_OK);
}

static void send_raw(const uint8_t *bytes, size_t n)
{
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    unsigned char ttl = 0;
    struct sockaddr_in dst;
    assert_true(fd >= 0);
    struct in_addr lo;
    lo.s_addr = htonl(INADDR_LOOPBACK); // works with and without a route for the group
    assert_int_equal(setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl), 0);
    assert_int_equal(setsockopt(fd, IPPROTO_IP, IP_MULTICAST_IF, &lo, sizeof lo), 0);
    memset(&dst, 0, sizeof dst);
    dst.sin_family = AF_INET;
    dst.sin_port = htons(test_port());
    dst.sin_addr.s_addr = inet_addr(VCAN_DEFAULT_GROUP);
    assert_int_equal(sendto(fd, bytes, n, 0, (const struct sockaddr *)&dst, sizeof dst), (ssize_t)n);
    close(fd);
}

static void loopback_between_two_members(void **state)
{
    (void)state;
    vcan_t a, b;
    vcan_stats_t st;
    hal_can_frame_t f, got;
    double ts;
    open_pair(&a, &b, false);
    for (uint8_t i = 0; i < 50; i++) {
        f = make_frame(0x100u + i, (i & 1u) ? HAL_CAN_FLAG_EXTENDED : 0u, (uint8_t)(i % 9u), i);
        assert_int_equal(vcan_send(&a, &f, 100.0 + i), FW_OK);
    }
    for (uint8_t i = 0; i < 50; i++) {
        f = make_frame(0x100u + i, (i & 1u) ? HAL_CAN_FLAG_EXTENDED : 0u, (uint8_t)(i % 9u), i);
        assert_int_equal(vcan_recv_stamped(&b, &got, &ts, 2000), 1);
        assert_frame_equal(&got, &f);
        assert_true(ts == 100.0 + i);
    }
    // The other way round; the sender does not hear itself.
    f = make_frame(0x7E0, 0, 2, 7);
    assert_int_equal(vcan_send(&b, &f, vcan_time_now()), FW_OK);
    assert_int_equal(vcan_recv(&a, &got, 2000), 1);
    assert_frame_equal(&got, &f);
    assert_int_equal(vcan_recv(&b, &got, 50), 0);
    vcan_get_stats(&b, &st);
    assert_int_equal(st.rx_frames, 50);
    assert_int_equal(st.rx_own, 1);
    vcan_get_stats(&a, &st);
    assert_int_equal(st.tx_frames, 50);
    assert_int_equal(st.rx_own, 50);
    assert_int_equal(st.rx_frames, 1);

    // Garbage on the bus is counted and skipped; the next good frame still arrives.
    static const uint8_t junk[] = {0xFF, 0x00, 0x13};
    send_raw(junk, sizeof junk);
    send_raw(py_std_3, 40);                 // truncated
    send_raw(py_std_3, sizeof py_std_3);    // python-can's own bytes
    assert_int_equal(vcan_recv(&b, &got, 2000), 1);
    f = make_frame(0x123, 0, 3, 1);
    assert_frame_equal(&got, &f);
    vcan_get_stats(&b, &st);
    assert_int_equal(st.rx_malformed, 2);
    vcan_close(&a);
    vcan_close(&b);
    vcan_close(&b); // twice is fine
}

static void receive_own_when_asked(void **state)
{
    (void)state;
    vcan_t a, b;
    hal_can_frame_t f = make_frame(0x55, 0, 1, 9), got;
    open_pair(&a, &b, true);
    assert_int_equal(vcan_send(&b, &f, 1.0), FW_OK);
    assert_int_equal(vcan_recv(&b, &got, 2000), 1);
    assert_frame_equal(&got, &f);
    assert_int_equal(vcan_recv(&a, &got, 2000), 1);
    assert_frame_equal(&got, &f);
    vcan_close(&a);
    vcan_close(&b);
}

// A sender's receive socket closed (BusLink's tx_): it still sends, receives nothing, and
// vcan_recv() says so at once instead of waiting on no socket.
static void send_only_member_closes_its_receive_socket(void **state)
{
    (void)state;
    vcan_t a, b;
    hal_can_frame_t f = make_frame(0x56, 0, 2, 7), got;
    open_pair(&a, &b, false);
    vcan_close_rx(&a);
    vcan_close_rx(&a);  // twice: harmless
    assert_int_equal(vcan_fileno(&a), -1);
    assert_int_equal(vcan_recv(&a, &got, 2000), FW_ERR_IO);
    assert_int_equal(vcan_send(&a, &f, 1.0), FW_OK);
    assert_int_equal(vcan_recv(&b, &got, 2000), 1);
    assert_frame_equal(&got, &f);
    vcan_close(&a);
    vcan_close(&b);
}

static void open_refuses_bad_config(void **state)
{
    (void)state;
    vcan_t bus;
    vcan_config_t cfg;
    vcan_default_config(&cfg);
    cfg.group = "10.0.0.1"; // unicast
    assert_int_equal(vcan_open(&bus, &cfg), FW_ERR_INVAL);
    cfg.group = "not an address";
    assert_int_equal(vcan_open(&bus, &cfg), FW_ERR_INVAL);
    vcan_default_config(&cfg);
    cfg.iface = "nope";
    assert_int_equal(vcan_open(&bus, &cfg), FW_ERR_INVAL);
    vcan_close(&bus);
}

// ---------------------------------------------------------------------------------------------
// pty

static int read_with_timeout(int fd, char *buf, size_t cap, int timeout_ms)
{
    struct pollfd p = {fd, POLLIN, 0};
    if (poll(&p, 1, timeout_ms) <= 0) {
        return -1;
    }
    return (int)read(fd, buf, cap);
}

static void pty_carries_bytes_both_ways(void **state)
{
    (void)state;
    pty_t pty;
    char path[64], buf[128];
    static const char line[] = "VR=2.0,ID=01:02:03:04:05:06:07:08,SP=A1,DB=140,DR=4082,TM=0,TS=77\r\n";
    assert_int_equal(pty_open(&pty, path, sizeof path), FW_OK);
    assert_true(strncmp(path, "/dev/pts/", 9) == 0);
    assert_false(pty_peer_hung_up(&pty));
    int slave = open(path, O_RDWR | O_NOCTTY);
    assert_true(slave >= 0);
    assert_false(pty_peer_hung_up(&pty));

    assert_int_equal(pty_write(&pty, line, strlen(line)), (int)strlen(line));
    size_t got = 0;
    while (got < strlen(line)) { // raw mode: no echo, \r\n unchanged
        int n = read_with_timeout(slave, buf + got, sizeof buf - got, 2000);
        assert_true(n > 0);
        got += (size_t)n;
    }
    assert_int_equal(got, strlen(line));
    assert_memory_equal(buf, line, got);

    assert_int_equal(write(slave, "AB\n", 3), 3);
    struct pollfd p = {pty.master_fd, POLLIN, 0};
    assert_int_equal(poll(&p, 1, 2000), 1);
    assert_int_equal(pty_read(&pty, buf, sizeof buf), 3);
    assert_memory_equal(buf, "AB\n", 3);
    assert_int_equal(pty_read(&pty, buf, sizeof buf), 0); // nothing more, no blocking

    // The reader goes away and comes back.
    close(slave);
    assert_true(pty_peer_hung_up(&pty));
    assert_int_equal(pty_read(&pty, buf, sizeof buf), FW_ERR_IO);
    slave = open(path, O_RDWR | O_NOCTTY);
    assert_true(slave >= 0);
    assert_false(pty_peer_hung_up(&pty));

    // Closing the master ends the slave's stream.
    pty_close(&pty);
    pty_close(&pty);
    int n = read_with_timeout(slave, buf, sizeof buf, 2000);
    assert_true(n <= 0);
    close(slave);
}

static void pty_open_refuses_small_buffer(void **state)
{
    (void)state;
    pty_t pty;
    char path[4];
    assert_int_equal(pty_open(&pty, path, sizeof path), FW_ERR_INVAL);
    assert_int_equal(pty.master_fd, -1);
    assert_int_equal(pty_open(&pty, NULL, 10), FW_ERR_INVAL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(encode_matches_python_can_bytes),
        cmocka_unit_test(decode_python_can_bytes),
        cmocka_unit_test(round_trip_every_dlc_and_id_kind),
        cmocka_unit_test(encode_refuses_bad_frames),
        cmocka_unit_test(decode_applies_python_can_defaults),
        cmocka_unit_test(decode_rejects_bad_values),
        cmocka_unit_test(decode_rejects_structure_errors),
        cmocka_unit_test(decode_fuzz),
        cmocka_unit_test(loopback_between_two_members),
        cmocka_unit_test(receive_own_when_asked),
        cmocka_unit_test(send_only_member_closes_its_receive_socket),
        cmocka_unit_test(open_refuses_bad_config),
        cmocka_unit_test(pty_carries_bytes_both_ways),
        cmocka_unit_test(pty_open_refuses_small_buffer),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
