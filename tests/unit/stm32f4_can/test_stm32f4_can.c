// SPDX-License-Identifier: MIT
// Tests of the STM32F4 bxCAN driver (hal/ports/stm32f4/src/stm32f4_bxcan.c) against a fake
// register block: a RAM struct with the controller's layout, whose acknowledge flags a poll hook
// drives the way the hardware does.
#include "test_common.h"

#include <string.h>

#include "fw/fw_base.h"
#include "stm32f4/stm32f4_drivers.h"
#include "stm32f4_fake.h"

static stm32f4_can_t can_;
static bool hw_responds_;

// The controller answers the mode handshake (stm32f4_fake_can_ack) unless the test stops it.
static void can_hw_(void)
{
    if (hw_responds_) {
        stm32f4_fake_can_ack(&can_);
    }
}

static int setup_(void **state)
{
    (void)state;
    stm32f4_fake_can_reset(&can_);
    hw_responds_ = true;
    stm32f4_poll_hook = can_hw_;
    return 0;
}

static void register_layout_matches_manual(void **state)
{
    (void)state;
    assert_int_equal(offsetof(stm32f4_can_t, BTR), 0x01C);
    assert_int_equal(offsetof(stm32f4_can_t, tx), 0x180);
    assert_int_equal(offsetof(stm32f4_can_t, rx), 0x1B0);
    assert_int_equal(offsetof(stm32f4_can_t, FMR), 0x200);
    assert_int_equal(offsetof(stm32f4_can_t, FA1R), 0x21C);
    assert_int_equal(offsetof(stm32f4_can_t, filter), 0x240);
    assert_int_equal(sizeof(stm32f4_can_t), 0x240 + 28 * 8);
}

// 42 MHz APB1, 500 kbit/s: 84 clocks a bit = prescaler 6 x 14 quanta, 1 + 11 + 2, sample
// point 12/14 = 85.7 % (no 16-quantum split divides 84).
static void bit_timing_500k_at_42mhz(void **state)
{
    (void)state;
    stm32f4_can_timing_t t;
    assert_int_equal(stm32f4_can_timing(42000000u, 500000u, &t), FW_OK);
    assert_int_equal(t.brp, 6);
    assert_int_equal(t.bs1, 11);
    assert_int_equal(t.bs2, 2);
    assert_int_equal(t.sjw, 1);
    assert_int_equal(42000000u / (t.brp * (1u + t.bs1 + t.bs2)), 500000u);
    assert_int_equal(stm32f4_can_btr(&t), (0u << 24) | (1u << 20) | (10u << 16) | 5u);
    // 1 Mbit/s: 42 clocks = 3 x 14; 250 kbit/s: 168 = 21 x 8 quanta, 1 + 6 + 1: exactly 87.5 %.
    assert_int_equal(stm32f4_can_timing(42000000u, 1000000u, &t), FW_OK);
    assert_int_equal(t.brp * (1u + t.bs1 + t.bs2), 42);
    assert_int_equal(stm32f4_can_timing(42000000u, 250000u, &t), FW_OK);
    assert_int_equal(t.brp, 21);
    assert_int_equal(t.bs1, 6);
    assert_int_equal(t.bs2, 1);
}

static void unreachable_bitrate_refused(void **state)
{
    (void)state;
    stm32f4_can_timing_t t;
    assert_int_equal(stm32f4_can_timing(42000000u, 0u, &t), FW_ERR_INVAL);
    assert_int_equal(stm32f4_can_timing(42000000u, 333333u, &t), FW_ERR_INVAL);  // not exact
    assert_int_equal(stm32f4_can_timing(42000000u, 5000000u, &t), FW_ERR_INVAL);  // too fast
    assert_int_equal(stm32f4_can_setup(&can_, 42000000u, 333333u, NULL, 0), FW_ERR_INVAL);
}

static void setup_lists_ids_four_per_bank(void **state)
{
    (void)state;
    const uint32_t ids[5] = {0x100, 0x101, 0x200, 0x7FF, 0x010};
    assert_int_equal(stm32f4_can_setup(&can_, 42000000u, 500000u, ids, 5), FW_OK);
    assert_int_equal(can_.BTR, (1u << 20) | (10u << 16) | 5u);
    assert_int_equal(can_.MCR & CAN_MCR_INRQ, 0);  // left initialisation mode
    assert_true(can_.MCR & CAN_MCR_ABOM);
    assert_int_equal(can_.MSR & CAN_MSR_INAK, 0);
    assert_int_equal(can_.FMR & CAN_FMR_FINIT, 0);
    assert_int_equal(can_.FA1R, 0x3);   // banks 0 and 1 active
    assert_int_equal(can_.FM1R, 0x3);   // identifier list
    assert_int_equal(can_.FS1R, 0x0);   // 16-bit scale
    assert_int_equal(can_.FFA1R, 0x0);  // FIFO 0
    assert_int_equal(can_.filter[0].FR1, (0x100u << 5) | (0x101u << 21));
    assert_int_equal(can_.filter[0].FR2, (0x200u << 5) | (0x7FFu << 21));
    // The last bank is padded with the last id.
    assert_int_equal(can_.filter[1].FR1, (0x010u << 5) | (0x010u << 21));
    assert_int_equal(can_.filter[1].FR2, (0x010u << 5) | (0x010u << 21));
    assert_true(can_.IER & CAN_IER_FMPIE0);
    assert_true(can_.IER & CAN_IER_FOVIE0);
}

static void empty_list_accepts_everything(void **state)
{
    (void)state;
    assert_int_equal(stm32f4_can_setup(&can_, 42000000u, 500000u, NULL, 0), FW_OK);
    assert_int_equal(can_.FA1R, 0x1);
    assert_int_equal(can_.FM1R & 1u, 0);  // mask mode
    assert_int_equal(can_.FS1R & 1u, 1);  // 32-bit
    assert_int_equal(can_.filter[0].FR2, 0);  // mask 0: every bit "don't care"
}

static void bad_ids_refused(void **state)
{
    (void)state;
    const uint32_t too_big[1] = {0x800};
    assert_int_equal(stm32f4_can_setup(&can_, 42000000u, 500000u, too_big, 1), FW_ERR_INVAL);
    uint32_t many[STM32F4_CAN_MAX_IDS + 1u];
    for (uint32_t i = 0; i < STM32F4_CAN_MAX_IDS + 1u; i++) {
        many[i] = i;
    }
    assert_int_equal(stm32f4_can_setup(&can_, 42000000u, 500000u, many, STM32F4_CAN_MAX_IDS + 1u),
                     FW_ERR_INVAL);
    assert_int_equal(stm32f4_can_setup(&can_, 42000000u, 500000u, many, STM32F4_CAN_MAX_IDS),
                     FW_OK);
    assert_int_equal(can_.FA1R, (1u << STM32F4_CFG_CAN1_FILTER_BANKS) - 1u);
}

static void controller_that_never_acknowledges_is_io_error(void **state)
{
    (void)state;
    hw_responds_ = false;  // e.g. no clock to the peripheral: INAK never rises
    assert_int_equal(stm32f4_can_setup(&can_, 42000000u, 500000u, NULL, 0), FW_ERR_IO);
}

static hal_can_frame_t frame_(uint32_t id, uint8_t dlc, uint8_t flags)
{
    hal_can_frame_t f;
    memset(&f, 0, sizeof f);
    f.id = id;
    f.dlc = dlc;
    f.flags = flags;
    for (uint8_t i = 0; i < 8u; i++) {
        f.data[i] = (uint8_t)(0x11u * (i + 1u));
    }
    return f;
}

static void write_fills_first_free_mailbox(void **state)
{
    (void)state;
    const hal_can_frame_t f = frame_(0x123, 8, 0);
    assert_int_equal(stm32f4_can_write(&can_, &f), 0);
    assert_int_equal(can_.tx[0].TIR, (0x123u << 21) | CAN_TIR_TXRQ);
    assert_int_equal(can_.tx[0].TDTR, 8);
    assert_int_equal(can_.tx[0].TDLR, 0x44332211u);
    assert_int_equal(can_.tx[0].TDHR, 0x88776655u);
    // Mailbox 0 busy (the hardware clears TME0 on the request): the next frame takes mailbox 1.
    can_.TSR &= ~CAN_TSR_TME0;
    const hal_can_frame_t e = frame_(0x1ABCDEF0, 2, HAL_CAN_FLAG_EXTENDED | HAL_CAN_FLAG_REMOTE);
    assert_int_equal(stm32f4_can_write(&can_, &e), 1);
    assert_int_equal(can_.tx[1].TIR,
                     (0x1ABCDEF0u << 3) | CAN_IR_IDE | CAN_IR_RTR | CAN_TIR_TXRQ);
    assert_int_equal(can_.tx[1].TDTR, 2);
}

static void all_mailboxes_busy_is_full(void **state)
{
    (void)state;
    can_.TSR = 0;  // no TME bit: three frames waiting for the bus
    const hal_can_frame_t f = frame_(0x10, 1, 0);
    assert_int_equal(stm32f4_can_write(&can_, &f), FW_ERR_FULL);
    assert_int_equal(can_.tx[0].TIR | can_.tx[1].TIR | can_.tx[2].TIR, 0);  // nothing written
    can_.TSR = CAN_TSR_TME0 << 2;
    assert_int_equal(stm32f4_can_write(&can_, &f), 2);
}

static void bad_frames_refused(void **state)
{
    (void)state;
    hal_can_frame_t f = frame_(0x800, 1, 0);
    assert_int_equal(stm32f4_can_write(&can_, &f), FW_ERR_INVAL);  // 12-bit standard id
    f = frame_(0x20000000, 1, HAL_CAN_FLAG_EXTENDED);
    assert_int_equal(stm32f4_can_write(&can_, &f), FW_ERR_INVAL);
    f = frame_(0x10, 9, 0);
    assert_int_equal(stm32f4_can_write(&can_, &f), FW_ERR_INVAL);
    f = frame_(0x10, 1, 0x80);
    assert_int_equal(stm32f4_can_write(&can_, &f), FW_ERR_INVAL);
    assert_int_equal(can_.tx[0].TIR, 0);
}

static void read_takes_frame_and_releases_slot(void **state)
{
    (void)state;
    hal_can_frame_t f;
    bool overrun = true;
    assert_false(stm32f4_can_read(&can_, &f, &overrun));  // FIFO empty
    assert_false(overrun);

    can_.RF0R = 2;  // two frames pending
    can_.rx[0].RIR = 0x321u << 21;
    can_.rx[0].RDTR = 5 | (3u << 8);  // DLC 5, filter match index 3
    can_.rx[0].RDLR = 0x04030201u;
    can_.rx[0].RDHR = 0x00000005u;
    assert_true(stm32f4_can_read(&can_, &f, &overrun));
    assert_false(overrun);
    assert_int_equal(f.id, 0x321);
    assert_int_equal(f.dlc, 5);
    assert_int_equal(f.flags, 0);
    assert_memory_equal(f.data, ((const uint8_t[]){1, 2, 3, 4, 5}), 5);
    assert_int_equal(can_.RF0R, CAN_RF0R_RFOM0);  // released

    can_.RF0R = 1 | CAN_RF0R_FOVR0 | CAN_RF0R_FULL0;  // overflowed: a frame was lost
    can_.rx[0].RIR = (0x1234567u << 3) | CAN_IR_IDE | CAN_IR_RTR;
    can_.rx[0].RDTR = 15;  // classic CAN: DLC codes above 8 mean 8 bytes
    assert_true(stm32f4_can_read(&can_, &f, &overrun));
    assert_true(overrun);
    assert_int_equal(f.id, 0x1234567);
    assert_int_equal(f.flags, HAL_CAN_FLAG_EXTENDED | HAL_CAN_FLAG_REMOTE);
    assert_int_equal(f.dlc, 8);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(register_layout_matches_manual, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(bit_timing_500k_at_42mhz, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(unreachable_bitrate_refused, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(setup_lists_ids_four_per_bank, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(empty_list_accepts_everything, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(bad_ids_refused, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(controller_that_never_acknowledges_is_io_error, setup_,
                                        stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(write_fills_first_free_mailbox, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(all_mailboxes_busy_is_full, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(bad_frames_refused, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(read_takes_frame_and_releases_slot, setup_, stm32f4_fake_teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
