// SPDX-License-Identifier: MIT
// Tests of the base layer: the CRCs against their standard check values, the numeric helpers,
// and assertions reaching the one handler (and compiled out by FW_CFG_ASSERT 0).
#include "test_common.h"

#include <string.h>

#include "fw/fw_assert.h"
#include "fw/fw_crc.h"
#include "fw/fw_prng.h"
#include "fw/fw_util.h"

// assert_off.c, compiled with FW_CFG_ASSERT 0: evaluates FW_ASSERT(++*counter == 0).
void assert_off_check(int *counter);

static void crc32_check_value(void **state)
{
    (void)state;
    assert_int_equal(fw_crc32(0, "123456789", 9), 0xCBF43926u);  // zlib's crc32()
    assert_int_equal(fw_crc32(0, "", 0), 0u);
    // Chained over pieces equals one call over the whole.
    assert_int_equal(fw_crc32(fw_crc32(0, "1234", 4), "56789", 5), 0xCBF43926u);
}

// Bit-wise CRC-32, the definition the table is built from.
static uint32_t crc32_bitwise_(uint32_t crc, const uint8_t *p, uint32_t len)
{
    crc = ~crc;
    for (uint32_t i = 0; i < len; i++) {
        crc ^= p[i];
        for (int bit = 0; bit < 8; bit++) {
            crc = (crc & 1u) ? (crc >> 1) ^ 0xEDB88320u : crc >> 1;
        }
    }
    return ~crc;
}

// The tables against the definition: every byte value alone, a long buffer, every length.
static void crc32_every_byte(void **state)
{
    (void)state;
    uint8_t buf[1024];
    for (uint32_t v = 0; v < 256u; v++) {
        const uint8_t b = (uint8_t)v;
        assert_int_equal(fw_crc32(0, &b, 1), crc32_bitwise_(0, &b, 1));
        assert_int_equal(fw_crc32(0x12345678u, &b, 1), crc32_bitwise_(0x12345678u, &b, 1));
    }
    for (uint32_t i = 0; i < sizeof buf; i++) {
        buf[i] = (uint8_t)(i * 37u + (i >> 8));
    }
    assert_int_equal(fw_crc32(0, buf, sizeof buf), crc32_bitwise_(0, buf, sizeof buf));
    // Four bytes a step and the tail: every length, start alignment and split point.
    for (uint32_t start = 0; start < 4u; start++) {
        for (uint32_t len = 0; len < 24u; len++) {
            const uint32_t want = crc32_bitwise_(0, buf + start, len);
            assert_int_equal(fw_crc32(0, buf + start, len), want);
            for (uint32_t cut = 0; cut <= len; cut++) {
                assert_int_equal(fw_crc32(fw_crc32(0, buf + start, cut), buf + start + cut, len - cut), want);
            }
        }
    }
}

static void crc8_check_value(void **state)
{
    (void)state;
    assert_int_equal(fw_crc8(0, "123456789", 9), 0x4Bu);  // CRC-8/SAE-J1850
    assert_int_equal(fw_crc8(fw_crc8(0, "123", 3), "456789", 6), 0x4Bu);
    assert_int_equal(fw_crc8(0, "", 0), 0u);
    // AUTOSAR's CRC library (SWS_CRCLibrary, Crc_CalculateCRC8: SAE-J1850) check values.
    static const struct {
        uint8_t data[9];
        uint32_t len;
        uint8_t crc;
    } autosar[] = {
        {{0x00, 0x00, 0x00, 0x00}, 4, 0x59},
        {{0xF2, 0x01, 0x83}, 3, 0x37},
        {{0x0F, 0xAA, 0x00, 0x55}, 4, 0x79},
        {{0x00, 0xFF, 0x55, 0x11}, 4, 0xB8},
        {{0x33, 0x22, 0x55, 0xAA, 0xBB, 0xCC, 0xDD, 0xEE, 0xFF}, 9, 0xCB},
        {{0x92, 0x6B, 0x55}, 3, 0x8C},
        {{0xFF, 0xFF, 0xFF, 0xFF}, 4, 0x74},
    };
    for (size_t i = 0; i < sizeof autosar / sizeof autosar[0]; i++) {
        assert_int_equal(fw_crc8(0, autosar[i].data, autosar[i].len), autosar[i].crc);
    }
}

// Bit-wise CRC-8/SAE-J1850, the definition the table is built from.
static uint8_t crc8_bitwise_(uint8_t crc, const uint8_t *p, uint32_t len)
{
    crc = (uint8_t)~crc;
    for (uint32_t i = 0; i < len; i++) {
        crc ^= p[i];
        for (int bit = 0; bit < 8; bit++) {
            crc = (uint8_t)((crc & 0x80u) ? (((unsigned)crc << 1) ^ 0x1Du) : ((unsigned)crc << 1));
        }
    }
    return (uint8_t)~crc;
}

// The table against the definition: every byte value from every starting CRC, and every split
// of a longer buffer.
static void crc8_every_byte(void **state)
{
    (void)state;
    for (uint32_t c = 0; c < 256u; c++) {
        for (uint32_t v = 0; v < 256u; v++) {
            const uint8_t b = (uint8_t)v;
            assert_int_equal(fw_crc8((uint8_t)c, &b, 1), crc8_bitwise_((uint8_t)c, &b, 1));
        }
    }
    uint8_t buf[64];
    for (uint32_t i = 0; i < sizeof buf; i++) {
        buf[i] = (uint8_t)(i * 37u + 11u);
    }
    const uint8_t want = crc8_bitwise_(0, buf, sizeof buf);
    for (uint32_t cut = 0; cut <= sizeof buf; cut++) {
        assert_int_equal(fw_crc8(fw_crc8(0, buf, cut), buf + cut, sizeof buf - cut), want);
    }
}

static void log2_ceil(void **state)
{
    (void)state;
    assert_int_equal(fw_log2_ceil(0), 0);
    assert_int_equal(fw_log2_ceil(1), 0);
    assert_int_equal(fw_log2_ceil(2), 1);
    assert_int_equal(fw_log2_ceil(3), 2);
    assert_int_equal(fw_log2_ceil(1024), 10);
    assert_int_equal(fw_log2_ceil(1025), 11);
    assert_int_equal(fw_log2_ceil(0x80000000u), 31);
    assert_int_equal(fw_log2_ceil(0x80000001u), 32);
}

static void fib_hash_spreads_and_stays_in_range(void **state)
{
    (void)state;
    assert_int_equal(fw_fib_mix(1u), FW_FIB_HASH_MUL);
    // Consecutive keys into 16 slots: each slot gets one of the first 16 (Fibonacci hashing's
    // three-distance property keeps them apart).
    unsigned hits[16] = {0};
    for (uint32_t k = 0; k < 16u; k++) {
        const uint32_t h = fw_fib_hash(k, 4);
        assert_true(h < 16u);
        hits[h]++;
    }
    for (unsigned i = 0; i < 16u; i++) {
        assert_true(hits[i] <= 2u);
    }
}

static void clamps(void **state)
{
    (void)state;
    assert_int_equal(fw_clamp_i32(-5, -2, 3), -2);
    assert_int_equal(fw_clamp_i32(7, -2, 3), 3);
    assert_int_equal(fw_clamp_i32(1, -2, 3), 1);
    assert_true(fw_clamp_f(2.5f, 0.0f, 1.0f) == 1.0f);
    assert_true(fw_clamp_f(-0.5f, 0.0f, 1.0f) == 0.0f);
    assert_true(fw_clamp_f(0.25f, 0.0f, 1.0f) == 0.25f);
    assert_int_equal(fw_sat_u32(5u), 5u);
    assert_int_equal(fw_sat_u32(0x100000000ull), UINT32_MAX);
    assert_true((float)FW_PI == FW_PI_F);
}

static jmp_buf jump_;
static int fired_line_;
static const char *fired_file_;

static void catch_(const char *file, int line)
{
    fired_file_ = file;
    fired_line_ = line;
    longjmp(jump_, 1);
}

static void assertion_reaches_the_handler(void **state)
{
    (void)state;
    fw_assert_handler_t old = fw_assert_set_handler(catch_);
    fired_line_ = 0;
    int line = 0;
    if (setjmp(jump_) == 0) {
        FW_ASSERT(1 + 1 == 2);  // true: no call
        line = __LINE__ + 1;
        FW_ASSERT(1 + 1 == 3);
        fail_msg("FW_ASSERT(false) returned");
    }
    assert_int_equal(fired_line_, line);
    assert_non_null(strstr(fired_file_, "test_base.c"));
    (void)fw_assert_set_handler(old);
}

static void prng_below_zero_asserts(void **state)
{
    (void)state;
    fw_assert_handler_t old = fw_assert_set_handler(catch_);
    fired_file_ = NULL;
    prng_t rng;
    prng_seed(&rng, 1);
    if (setjmp(jump_) == 0) {
        (void)prng_below(&rng, 0u);
        fail_msg("prng_below(0) returned");
    }
    assert_non_null(strstr(fired_file_, "fw_prng.c"));
    (void)fw_assert_set_handler(old);
}

static void assert_compiled_out_evaluates_nothing(void **state)
{
    (void)state;
    fw_assert_handler_t old = fw_assert_set_handler(catch_);
    int counter = 0;
    if (setjmp(jump_) == 0) {
        assert_off_check(&counter);
    } else {
        fail_msg("an FW_ASSERT compiled out fired");
    }
    assert_int_equal(counter, 0);  // the condition was not evaluated either
    (void)fw_assert_set_handler(old);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(crc32_check_value),
        cmocka_unit_test(crc32_every_byte),
        cmocka_unit_test(crc8_check_value),
        cmocka_unit_test(crc8_every_byte),
        cmocka_unit_test(log2_ceil),
        cmocka_unit_test(fib_hash_spreads_and_stays_in_range),
        cmocka_unit_test(clamps),
        cmocka_unit_test(assertion_reaches_the_handler),
        cmocka_unit_test(prng_below_zero_asserts),
        cmocka_unit_test(assert_compiled_out_evaluates_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
