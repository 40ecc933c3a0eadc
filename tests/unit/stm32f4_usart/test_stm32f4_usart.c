// SPDX-License-Identifier: MIT
// Tests of the STM32F4 USART driver (hal/ports/stm32f4/src/stm32f4_usart.c): baud-rate register,
// setup, the receive interrupt's ring buffer with its overrun and error counting, transmission.
#include "test_common.h"

#include <string.h>

#include "fw/fw_base.h"
#include "stm32f4/stm32f4_drivers.h"

static stm32f4_usart_t regs_;
static uint8_t rx_buf_[8];
static uint8_t tx_buf_[4];
static stm32f4_usart_port_t port_;

static int setup_(void **state)
{
    (void)state;
    memset(&regs_, 0, sizeof regs_);
    port_.regs = &regs_;
    stm32f4_ring_init(&port_.rx, rx_buf_, sizeof rx_buf_);
    stm32f4_ring_init(&port_.tx, tx_buf_, sizeof tx_buf_);
    assert_int_equal(stm32f4_usart_setup(&port_, 42000000u, 115200u), FW_OK);
    return 0;
}

// The hardware receiving a byte, with the status flags it would set.
static void receive_(uint8_t byte, uint32_t extra_flags)
{
    regs_.DR = byte;
    regs_.SR = USART_SR_RXNE | extra_flags;
}

static void register_layout_matches_manual(void **state)
{
    (void)state;
    assert_int_equal(offsetof(stm32f4_usart_t, BRR), 0x08);
    assert_int_equal(offsetof(stm32f4_usart_t, CR3), 0x14);
}

// 42 MHz / 115200 = 364.58 -> BRR 365 = mantissa 22, fraction 13 (0x16D): 115068 baud, 0.11 % off.
static void brr_for_115200(void **state)
{
    (void)state;
    uint32_t brr = 0;
    assert_int_equal(stm32f4_usart_brr(42000000u, 115200u, &brr), FW_OK);
    assert_int_equal(brr, 0x16D);
    assert_int_equal(stm32f4_usart_brr(84000000u, 115200u, &brr), FW_OK);
    assert_int_equal(brr, 729);  // 45 << 4 | 9 at APB2
    assert_int_equal(regs_.BRR, 0x16D);
    assert_int_equal(regs_.CR1, USART_CR1_UE | USART_CR1_RE | USART_CR1_TE | USART_CR1_RXNEIE);
    assert_int_equal(regs_.CR2, 0);  // 1 stop bit
}

static void unreachable_baud_refused(void **state)
{
    (void)state;
    uint32_t brr = 0;
    assert_int_equal(stm32f4_usart_brr(42000000u, 0u, &brr), FW_ERR_INVAL);
    assert_int_equal(stm32f4_usart_brr(42000000u, 3000000u, &brr), FW_ERR_INVAL);  // > 2 % off
    assert_int_equal(stm32f4_usart_brr(42000000u, 300u, &brr), FW_ERR_INVAL);  // BRR overflows
    assert_int_equal(stm32f4_usart_setup(&port_, 42000000u, 0u), FW_ERR_INVAL);
}

static void received_bytes_come_out_in_order(void **state)
{
    (void)state;
    const char *text = "DB=42\n";
    for (size_t i = 0; i < strlen(text); i++) {
        receive_((uint8_t)text[i], 0);
        assert_true(stm32f4_usart_irq(&port_));
    }
    uint8_t b = 0;
    for (size_t i = 0; i < strlen(text); i++) {
        assert_true(stm32f4_ring_get(&port_.rx, &b));
        assert_int_equal(b, (uint8_t)text[i]);
    }
    assert_false(stm32f4_ring_get(&port_.rx, &b));
    assert_int_equal(port_.stats.rx_bytes, strlen(text));
}

static void full_ring_counts_overruns_and_keeps_the_oldest(void **state)
{
    (void)state;
    for (uint32_t i = 0; i < 11u; i++) {
        receive_((uint8_t)i, 0);
        (void)stm32f4_usart_irq(&port_);
    }
    assert_int_equal(port_.stats.rx_bytes, 8);
    assert_int_equal(port_.stats.rx_overruns, 3);
    assert_int_equal(stm32f4_ring_count(&port_.rx), 8);
    uint8_t b = 0xFF;
    assert_true(stm32f4_ring_get(&port_.rx, &b));
    assert_int_equal(b, 0);
    // Draining makes room again; indices wrap around correctly.
    for (uint32_t i = 0; i < 100u; i++) {
        receive_((uint8_t)i, 0);
        assert_true(stm32f4_usart_irq(&port_));
        assert_true(stm32f4_ring_get(&port_.rx, &b));
    }
    assert_int_equal(stm32f4_ring_count(&port_.rx), 7);
}

static uint32_t notified_;

static void on_rx_(void *ctx)
{
    (void)ctx;
    notified_++;
}

// The firmware's wake-up may have been lost (its event queue was full); a byte that finds the ring
// full still notifies, or the line would never be drained again.
static void full_ring_still_notifies(void **state)
{
    (void)state;
    notified_ = 0;
    port_.on_rx = on_rx_;
    for (uint32_t i = 0; i < 8u; i++) {
        receive_((uint8_t)i, 0);
        assert_true(stm32f4_usart_irq(&port_));
    }
    assert_int_equal(notified_, 8);
    receive_(99u, 0);
    assert_false(stm32f4_usart_irq(&port_));  // not stored
    assert_int_equal(notified_, 9);           // but heard
    receive_('?', USART_SR_FE);               // an errored byte is no arrival
    (void)stm32f4_usart_irq(&port_);
    assert_int_equal(notified_, 9);
    port_.on_rx = NULL;
}

static void hardware_overrun_and_framing_errors_counted(void **state)
{
    (void)state;
    receive_('A', USART_SR_ORE);  // a byte was lost before this one: this one is still good
    assert_true(stm32f4_usart_irq(&port_));
    receive_('?', USART_SR_FE);  // garbage (wrong baud, noise): dropped
    assert_false(stm32f4_usart_irq(&port_));
    receive_('?', USART_SR_NF);
    assert_false(stm32f4_usart_irq(&port_));
    regs_.SR = USART_SR_ORE;  // overrun flag alone (RXNE already taken): still read DR to clear
    assert_false(stm32f4_usart_irq(&port_));
    assert_int_equal(port_.stats.rx_overruns, 2);
    assert_int_equal(port_.stats.rx_errors, 2);
    assert_int_equal(port_.stats.rx_bytes, 1);
    uint8_t b = 0;
    assert_true(stm32f4_ring_get(&port_.rx, &b));
    assert_int_equal(b, 'A');
    assert_false(stm32f4_ring_get(&port_.rx, &b));
}

static void transmit_feeds_from_ring_then_stops(void **state)
{
    (void)state;
    const uint8_t cmd[6] = {'P', ' ', 'A', 'L', 'L', '\n'};
    assert_int_equal(stm32f4_usart_queue(&port_, cmd, sizeof cmd), 4);  // ring of 4
    assert_true(regs_.CR1 & USART_CR1_TXEIE);
    for (uint32_t i = 0; i < 4u; i++) {
        regs_.SR = USART_SR_TXE;
        (void)stm32f4_usart_irq(&port_);
        assert_int_equal(regs_.DR, cmd[i]);
    }
    regs_.SR = USART_SR_TXE;
    (void)stm32f4_usart_irq(&port_);  // nothing left: the TXE interrupt goes off
    assert_false(regs_.CR1 & USART_CR1_TXEIE);
    assert_true(regs_.CR1 & USART_CR1_RXNEIE);
}

static void polled_write_waits_for_txe_a_bounded_time(void **state)
{
    (void)state;
    const uint8_t line[3] = {'t', '1', '\r'};
    regs_.SR = USART_SR_TXE;
    assert_int_equal(stm32f4_usart_put_polled(&regs_, line, sizeof line, 10u), 3);
    assert_int_equal(regs_.DR, '\r');
    regs_.SR = 0u;  // the transmitter never empties: give up after the polls, nothing written
    regs_.DR = 0u;
    assert_int_equal(stm32f4_usart_put_polled(&regs_, line, sizeof line, 10u), 0);
    assert_int_equal(regs_.DR, 0u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(register_layout_matches_manual, setup_),
        cmocka_unit_test_setup(brr_for_115200, setup_),
        cmocka_unit_test_setup(unreachable_baud_refused, setup_),
        cmocka_unit_test_setup(received_bytes_come_out_in_order, setup_),
        cmocka_unit_test_setup(full_ring_counts_overruns_and_keeps_the_oldest, setup_),
        cmocka_unit_test_setup(full_ring_still_notifies, setup_),
        cmocka_unit_test_setup(hardware_overrun_and_framing_errors_counted, setup_),
        cmocka_unit_test_setup(transmit_feeds_from_ring_then_stops, setup_),
        cmocka_unit_test_setup(polled_write_waits_for_txe_a_bounded_time, setup_),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
