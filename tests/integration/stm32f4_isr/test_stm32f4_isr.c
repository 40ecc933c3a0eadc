// SPDX-License-Identifier: MIT
// The STM32F4 port's interrupt handlers' work (stm32f4_can_rx_irq, stm32f4_can_sce_irq,
// stm32f4_can_send, stm32f4_usart_irq: what CAN1_RX0_IRQHandler, CAN1_SCE_IRQHandler,
// hal_can_send and USART2_IRQHandler call in hal_stm32f4.c) against fake register blocks, with
// the receive handlers posting into the real scheduler's event queue, as the robot application
// does. The fake bxCAN models receive FIFO 0: three slots, FMP0, the output mailbox, the release
// (RFOM0) taking a number of polls, FULL0 and FOVR0, and overwriting the newest frame when a
// fourth arrives (MCR.RFLM = 0, RM0090 32.7.5).
#include "test_common.h"

#include <string.h>

#include "fw/fw_base.h"
#include "hal/hal_time.h"
#include "hal_host/hal_host.h"
#include "sched/sched.h"
#include "stm32f4/stm32f4_drivers.h"
#include "stm32f4_fake.h"

enum { EV_CAN = 1, EV_UART = 2 };

static sched_t sched_;

// ---- Fake bxCAN receive FIFO 0 ----------------------------------------------------------------

static stm32f4_can_t can_;
static hal_can_frame_t fifo_[3];
static uint32_t fifo_count_;
static bool fovr_;
static bool release_pending_;
static uint32_t release_polls_left_;
static uint32_t release_delay_;   // polls a release takes
static uint32_t published_rf0r_;  // what the fake last put in RF0R (anything else was written)

static void can_publish_(void)
{
    uint32_t rf0r = fifo_count_;
    rf0r |= fifo_count_ == 3u ? CAN_RF0R_FULL0 : 0u;
    rf0r |= fovr_ ? CAN_RF0R_FOVR0 : 0u;
    rf0r |= release_pending_ ? CAN_RF0R_RFOM0 : 0u;
    can_.RF0R = rf0r;
    published_rf0r_ = rf0r;
    memset((void *)&can_.rx[0], 0, sizeof can_.rx[0]);
    if (fifo_count_ > 0u) {
        const hal_can_frame_t *f = &fifo_[0];
        const bool ext = (f->flags & HAL_CAN_FLAG_EXTENDED) != 0u;
        can_.rx[0].RIR = (ext ? (f->id << CAN_IR_EXID_SHIFT) | CAN_IR_IDE
                              : f->id << CAN_IR_STID_SHIFT) |
                         ((f->flags & HAL_CAN_FLAG_REMOTE) ? CAN_IR_RTR : 0u);
        can_.rx[0].RDTR = f->dlc;
        can_.rx[0].RDLR = (uint32_t)f->data[0] | (uint32_t)f->data[1] << 8 |
                          (uint32_t)f->data[2] << 16 | (uint32_t)f->data[3] << 24;
        can_.rx[0].RDHR = (uint32_t)f->data[4] | (uint32_t)f->data[5] << 8 |
                          (uint32_t)f->data[6] << 16 | (uint32_t)f->data[7] << 24;
    }
}

// One step of the controller: takes what software wrote into RF0R (FOVR0 is write-1-to-clear,
// RFOM0 starts a release), advances a release in progress, shows the FIFO's state.
static void can_hw_(void)
{
    const uint32_t written = can_.RF0R;
    if (written != published_rf0r_) {
        if (written & CAN_RF0R_FOVR0) {
            fovr_ = false;
        }
        if ((written & CAN_RF0R_RFOM0) && fifo_count_ > 0u && !release_pending_) {
            release_pending_ = true;
            release_polls_left_ = release_delay_;
        }
    }
    if (release_pending_) {
        if (release_polls_left_ == 0u) {
            memmove(&fifo_[0], &fifo_[1], 2u * sizeof fifo_[0]);
            fifo_count_--;
            release_pending_ = false;
        } else {
            release_polls_left_--;
        }
    }
    can_publish_();
}

// A frame from the bus that passed the filters.
static void bus_receive_(uint32_t id, uint8_t first_byte)
{
    can_hw_();
    hal_can_frame_t f;
    memset(&f, 0, sizeof f);
    f.id = id;
    f.dlc = 8;
    for (uint8_t i = 0; i < 8u; i++) {
        f.data[i] = (uint8_t)(first_byte + i);
    }
    if (fifo_count_ < 3u) {
        fifo_[fifo_count_++] = f;
    } else {
        fifo_[2] = f;  // FIFO full, not locked: the newest stored frame is overwritten
        fovr_ = true;
    }
    can_publish_();
}

// The NVIC: FIFO 0's interrupt is pending while FMP0 != 0 or FOVR0 is set (FMPIE0, FOVIE0).
static bool can_rx_irq_pending_(void)
{
    can_hw_();
    return fifo_count_ > 0u || fovr_;
}

// ---- The firmware side: the scheduler and what its handlers saw ------------------------------

static stm32f4_can_port_t can_port_;
static hal_can_frame_t seen_[64];
static uint32_t seen_n_;
static uint32_t uart_events_;

static void on_can_isr_(const hal_can_frame_t *frame, void *ctx)
{
    (void)ctx;
    sched_event_t ev;
    memset(&ev, 0, sizeof ev);
    ev.type = EV_CAN;
    ev.u.can = *frame;
    (void)sched_post(&sched_, &ev);  // a full queue counts the drop (events_dropped)
}

static void on_can_event_(const sched_event_t *ev, void *ctx)
{
    (void)ctx;
    if (seen_n_ < 64u) {
        seen_[seen_n_] = ev->u.can;
    }
    seen_n_++;
}

static void on_uart_isr_(void *ctx)
{
    (void)ctx;
    sched_event_t ev;
    memset(&ev, 0, sizeof ev);
    ev.type = EV_UART;
    (void)sched_post(&sched_, &ev);
}

static void on_uart_event_(const sched_event_t *ev, void *ctx)
{
    (void)ev;
    (void)ctx;
    uart_events_++;
}

static int setup_(void **state)
{
    (void)state;
    hal_host_reset();
    assert_int_equal(hal_time_init(), FW_OK);
    const sched_config_t sc = {NULL, NULL, 0u, 0u, 0u};
    assert_int_equal(sched_init(&sched_, &sc), FW_OK);
    assert_int_equal(sched_on_event(&sched_, EV_CAN, on_can_event_, NULL), FW_OK);
    assert_int_equal(sched_on_event(&sched_, EV_UART, on_uart_event_, NULL), FW_OK);
    seen_n_ = 0;
    uart_events_ = 0;

    stm32f4_fake_can_reset(&can_);
    can_.MCR = 0;  // as the driver left it: running
    can_.MSR = 0;
    memset(fifo_, 0, sizeof fifo_);
    fifo_count_ = 0;
    fovr_ = false;
    release_pending_ = false;
    release_delay_ = 2;
    can_publish_();
    can_port_ = (stm32f4_can_port_t){&can_, on_can_isr_, NULL, {0}};
    stm32f4_poll_hook = can_hw_;
    return 0;
}

static uint32_t events_dropped_(void)
{
    sched_stats_t st;
    sched_get_stats(&sched_, &st);
    return st.events_dropped;
}

// ---- bxCAN receive --------------------------------------------------------------------------

static void frames_read_out_released_and_posted_in_order(void **state)
{
    (void)state;
    bus_receive_(0x101, 0x10);
    bus_receive_(0x102, 0x20);
    bus_receive_(0x103, 0x30);
    assert_int_equal(can_.RF0R & (CAN_RF0R_FMP0_MASK | CAN_RF0R_FULL0), 3u | CAN_RF0R_FULL0);
    assert_true(can_rx_irq_pending_());
    stm32f4_can_rx_irq(&can_port_);
    assert_false(can_rx_irq_pending_());  // FIFO empty, every slot released
    assert_int_equal(can_port_.stats.rx_frames, 3);
    assert_int_equal(can_port_.stats.rx_overruns, 0);
    assert_int_equal(sched_pending_events(&sched_), 3);

    sched_step(&sched_);  // the main loop dispatches what the interrupt posted
    assert_int_equal(seen_n_, 3);
    for (uint32_t i = 0; i < 3u; i++) {
        assert_int_equal(seen_[i].id, 0x101 + i);
        assert_int_equal(seen_[i].dlc, 8);
        assert_int_equal(seen_[i].flags, 0);
        for (uint32_t b = 0; b < 8u; b++) {
            assert_int_equal(seen_[i].data[b], 0x10u * (i + 1u) + b);
        }
    }
}

// A release that takes longer than the handler waits: the handler stops, the interrupt stays
// pending, the next entry continues. No frame twice, none lost.
static void slow_release_never_delivers_a_frame_twice(void **state)
{
    (void)state;
    release_delay_ = STM32F4_CFG_CAN_RELEASE_POLLS + 5u;
    bus_receive_(0x201, 1);
    bus_receive_(0x202, 2);
    bus_receive_(0x203, 3);
    uint32_t entries = 0;
    while (can_rx_irq_pending_()) {
        stm32f4_can_rx_irq(&can_port_);
        assert_true(++entries < 100u);
    }
    assert_true(entries > 1u);
    assert_int_equal(can_port_.stats.rx_frames, 3);
    sched_step(&sched_);
    assert_int_equal(seen_n_, 3);
    assert_int_equal(seen_[0].id, 0x201);
    assert_int_equal(seen_[1].id, 0x202);
    assert_int_equal(seen_[2].id, 0x203);
}

// The handler entered while a release is still in progress (RFOM0 set): FMP0 and the output
// mailbox still show the frame already taken, so nothing is read.
static void nothing_read_while_release_in_progress(void **state)
{
    (void)state;
    bus_receive_(0x301, 1);
    bus_receive_(0x302, 2);
    release_delay_ = 1000u;
    hal_can_frame_t f;
    bool overrun = false;
    assert_true(stm32f4_can_read(&can_, &f, &overrun));
    assert_int_equal(f.id, 0x301);
    can_hw_();  // the release has started
    assert_true(can_.RF0R & CAN_RF0R_RFOM0);
    assert_int_equal(can_.RF0R & CAN_RF0R_FMP0_MASK, 2);  // still counts the frame taken
    assert_false(stm32f4_can_read(&can_, &f, &overrun));
    assert_int_equal(f.id, 0x301);  // untouched
}

// Five frames on a 3-deep FIFO before the handler runs: two are lost (the newest slot was
// overwritten twice), the overrun is counted once per FOVR0 (the hardware flags that frames were
// lost, not how many), and the flag is cleared so the next burst counts again.
static void overrun_counted_and_cleared(void **state)
{
    (void)state;
    for (uint32_t i = 0; i < 5u; i++) {
        bus_receive_(0x400 + i, (uint8_t)i);
    }
    assert_true(can_.RF0R & CAN_RF0R_FOVR0);
    stm32f4_can_rx_irq(&can_port_);
    assert_false(can_rx_irq_pending_());
    assert_false(can_.RF0R & CAN_RF0R_FOVR0);
    assert_int_equal(can_port_.stats.rx_frames, 3);
    assert_int_equal(can_port_.stats.rx_overruns, 1);
    sched_step(&sched_);
    assert_int_equal(seen_n_, 3);
    assert_int_equal(seen_[0].id, 0x400);
    assert_int_equal(seen_[1].id, 0x401);
    assert_int_equal(seen_[2].id, 0x404);  // the latest one is kept

    bus_receive_(0x500, 0);
    stm32f4_can_rx_irq(&can_port_);
    assert_int_equal(can_port_.stats.rx_overruns, 1);
    for (uint32_t i = 0; i < 4u; i++) {
        bus_receive_(0x600 + i, 0);
    }
    stm32f4_can_rx_irq(&can_port_);
    assert_int_equal(can_port_.stats.rx_overruns, 2);
    assert_int_equal(can_port_.stats.rx_frames, 7);
}

// The main loop stalls (a flash erase, a long task): the scheduler's queue fills and refuses
// the rest, counting each refusal; the controller's FIFO is still drained every time.
static void full_event_queue_drops_are_counted(void **state)
{
    (void)state;
    const uint32_t frames = FW_CFG_SCHED_EVENT_CAPACITY + 7u;
    for (uint32_t i = 0; i < frames; i++) {
        bus_receive_(0x100 + (i & 0xFFu), (uint8_t)i);
        stm32f4_can_rx_irq(&can_port_);
        assert_false(can_rx_irq_pending_());
    }
    assert_int_equal(can_port_.stats.rx_frames, frames);
    assert_int_equal(sched_pending_events(&sched_), FW_CFG_SCHED_EVENT_CAPACITY);
    assert_int_equal(events_dropped_(), 7);
    sched_step(&sched_);
    assert_int_equal(seen_n_, FW_CFG_SCHED_EVENT_CAPACITY);
    assert_int_equal(seen_[0].id, 0x100);  // the oldest were kept
}

static void no_handler_still_drains_and_counts(void **state)
{
    (void)state;
    can_port_.on_rx = NULL;
    bus_receive_(0x10, 0);
    bus_receive_(0x11, 0);
    stm32f4_can_rx_irq(&can_port_);
    assert_false(can_rx_irq_pending_());
    assert_int_equal(can_port_.stats.rx_frames, 2);
    assert_int_equal(sched_pending_events(&sched_), 0);
}

// ---- bxCAN errors and transmit ---------------------------------------------------------------

static void error_interrupt_counts_and_clears(void **state)
{
    (void)state;
    can_.ESR = CAN_ESR_BOFF | CAN_ESR_EPVF | CAN_ESR_EWGF | (255u << 16);  // bus-off, TEC 255
    can_.MSR = CAN_MSR_ERRI;
    stm32f4_can_sce_irq(&can_port_);
    assert_int_equal(can_port_.stats.bus_errors, 1);
    assert_int_equal(can_.MSR, CAN_MSR_ERRI);  // the write that clears it (write 1)
    can_.ESR = CAN_ESR_EWGF;
    stm32f4_can_sce_irq(&can_port_);
    assert_int_equal(can_port_.stats.bus_errors, 2);
    can_.ESR = 0;  // recovered (a last-error-code change alone is not enabled as a source)
    stm32f4_can_sce_irq(&can_port_);
    assert_int_equal(can_port_.stats.bus_errors, 2);
}

static void send_uses_mailboxes_and_counts(void **state)
{
    (void)state;
    hal_can_frame_t f;
    memset(&f, 0, sizeof f);
    f.id = 0x120;
    f.dlc = 2;
    f.data[0] = 0xAB;
    for (uint32_t m = 0; m < 3u; m++) {
        assert_int_equal(stm32f4_can_send(&can_port_, &f), FW_OK);
        assert_true(can_.tx[m].TIR & CAN_TIR_TXRQ);
        can_.TSR &= ~(CAN_TSR_TME0 << m);  // the hardware: mailbox m now pending
    }
    assert_int_equal(stm32f4_can_send(&can_port_, &f), FW_ERR_FULL);  // a bus without ACK
    assert_int_equal(can_port_.stats.tx_frames, 3);
    assert_int_equal(can_port_.stats.tx_dropped, 1);
    can_.TSR |= CAN_TSR_TME0 << 1;  // mailbox 1 went out
    f.id = 0x121;
    assert_int_equal(stm32f4_can_send(&can_port_, &f), FW_OK);
    assert_int_equal(can_.tx[1].TIR, (0x121u << CAN_IR_STID_SHIFT) | CAN_TIR_TXRQ);
    f.id = 0x800;  // not an 11-bit id: refused, neither sent nor dropped
    assert_int_equal(stm32f4_can_send(&can_port_, &f), FW_ERR_INVAL);
    assert_int_equal(can_port_.stats.tx_frames, 4);
    assert_int_equal(can_port_.stats.tx_dropped, 1);
}

// ---- USART receive ---------------------------------------------------------------------------

static stm32f4_usart_t usart_;
static uint8_t rx_ring_[STM32F4_CFG_UART_RX_BYTES];
static uint8_t tx_ring_[STM32F4_CFG_UART_TX_BYTES];
static stm32f4_usart_port_t uart_;

static void uart_setup_(void)
{
    memset(&usart_, 0, sizeof usart_);
    memset(&uart_, 0, sizeof uart_);
    uart_.regs = &usart_;
    stm32f4_ring_init(&uart_.rx, rx_ring_, sizeof rx_ring_);
    stm32f4_ring_init(&uart_.tx, tx_ring_, sizeof tx_ring_);
    uart_.on_rx = on_uart_isr_;
    assert_int_equal(stm32f4_usart_setup(&uart_, 42000000u, 115200u), FW_OK);
}

// The USART receiving a byte: DR holds it, SR shows RXNE and any error; then the interrupt.
static void line_in_(uint8_t byte, uint32_t flags)
{
    usart_.DR = byte;
    usart_.SR = USART_SR_RXNE | flags;
    (void)stm32f4_usart_irq(&uart_);
}

static void cricket_line_through_ring_and_events(void **state)
{
    (void)state;
    uart_setup_();
    const char *line = "VR=2.0,ID=01:02:03:04:05:06:07:08,SP=B1,DB=142,DR=4170,TM=1,TS=99\r\n";
    const size_t n = strlen(line);
    for (size_t i = 0; i < n; i++) {
        line_in_((uint8_t)line[i], 0);
    }
    assert_int_equal(uart_.stats.rx_bytes, n);
    // One event per byte stored (at least one per byte readable, the hal_uart.h contract); the
    // queue refuses the rest and counts them. The reader drains everything on the first event.
    assert_int_equal(sched_pending_events(&sched_), FW_CFG_SCHED_EVENT_CAPACITY);
    assert_int_equal(events_dropped_(), n - FW_CFG_SCHED_EVENT_CAPACITY);
    uint8_t buf[128];
    assert_int_equal(stm32f4_usart_read(&uart_, buf, sizeof buf), n);
    assert_memory_equal(buf, line, n);
    assert_int_equal(stm32f4_usart_read(&uart_, buf, sizeof buf), 0);
    sched_step(&sched_);
    assert_int_equal(uart_events_, FW_CFG_SCHED_EVENT_CAPACITY);
}

// The main loop does not drain for longer than the ring lasts (44 ms at 115200 baud): every byte
// is either stored, or counted as an overrun or an error. Nothing vanishes.
static void every_byte_is_stored_or_counted(void **state)
{
    (void)state;
    uart_setup_();
    uint32_t fed = 0;
    for (uint32_t i = 0; i < STM32F4_CFG_UART_RX_BYTES + 100u; i++) {
        uint32_t flags = 0;
        if (i % 50u == 7u) {
            flags = USART_SR_FE;  // a corrupted byte
        } else if (i % 70u == 3u) {
            flags = USART_SR_ORE;  // the hardware lost the byte before this one
            fed++;
        }
        line_in_((uint8_t)i, flags);
        fed++;
    }
    const hal_uart_stats_t *st = &uart_.stats;
    assert_int_equal(st->rx_bytes, STM32F4_CFG_UART_RX_BYTES);
    assert_true(st->rx_errors > 0u);
    assert_true(st->rx_overruns > 50u);
    assert_int_equal(st->rx_bytes + st->rx_overruns + st->rx_errors, fed);
    // The ring kept the oldest bytes, in order, minus the corrupted ones.
    uint8_t b = 0;
    uint32_t expect = 0;
    for (uint32_t k = 0; k < STM32F4_CFG_UART_RX_BYTES; k++) {
        while (expect % 50u == 7u) {
            expect++;
        }
        assert_int_equal(stm32f4_usart_read(&uart_, &b, 1), 1);
        assert_int_equal(b, (uint8_t)expect);
        expect++;
    }
    assert_int_equal(stm32f4_usart_read(&uart_, &b, 1), 0);
    // Drained: bytes are stored again.
    line_in_('x', 0);
    assert_int_equal(stm32f4_usart_read(&uart_, &b, 1), 1);
    assert_int_equal(b, 'x');
}

static void overrun_flag_alone_is_cleared_and_counted(void **state)
{
    (void)state;
    uart_setup_();
    usart_.SR = USART_SR_ORE;  // RXNE already gone: DR must still be read to clear ORE
    usart_.DR = 0x55;
    assert_false(stm32f4_usart_irq(&uart_));
    assert_int_equal(uart_.stats.rx_overruns, 1);
    assert_int_equal(uart_.stats.rx_bytes, 0);
    assert_int_equal(sched_pending_events(&sched_), 0);  // nothing readable: no event
}

static void write_before_setup_queues_nothing(void **state)
{
    (void)state;
    stm32f4_usart_port_t idle;
    memset(&idle, 0, sizeof idle);
    const uint8_t cmd[3] = {'P', '\r', '\n'};
    assert_int_equal(stm32f4_usart_queue(&idle, cmd, sizeof cmd), 0);
    uint8_t b;
    assert_int_equal(stm32f4_usart_read(&idle, &b, 1), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(frames_read_out_released_and_posted_in_order, setup_,
                                        stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(slow_release_never_delivers_a_frame_twice, setup_,
                                        stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(nothing_read_while_release_in_progress, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(overrun_counted_and_cleared, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(full_event_queue_drops_are_counted, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(no_handler_still_drains_and_counts, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(error_interrupt_counts_and_clears, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(send_uses_mailboxes_and_counts, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(cricket_line_through_ring_and_events, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(every_byte_is_stored_or_counted, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(overrun_flag_alone_is_cleared_and_counted, setup_,
                                        stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(write_before_setup_queues_nothing, setup_, stm32f4_fake_teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
