// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 port: the USART of the Cricket listener, interrupt driven (RM0090 chapter 30).
//
// Receive: each RXNE interrupt stores one byte in a ring the thread side drains. A byte that
// arrives with a framing or noise error is dropped and counted; a full ring or the hardware's
// overrun flag (a byte lost before the interrupt ran) counts an overrun. Reading SR then DR
// clears all of these flags (RM0090 30.6.1), so a garbage line never leaves the port stuck.
#include "stm32f4/stm32f4_drivers.h"

void stm32f4_ring_init(stm32f4_ring_t *r, uint8_t *buf, uint32_t size)
{
    r->buf = buf;
    r->size = size;
    r->head = 0u;
    r->tail = 0u;
}

uint32_t stm32f4_ring_count(const stm32f4_ring_t *r)
{
    return r->head - r->tail;  // free-running indices: wrap-around subtracts correctly
}

bool stm32f4_ring_put(stm32f4_ring_t *r, uint8_t byte)
{
    const uint32_t head = r->head;
    if (head - r->tail >= r->size) {
        return false;
    }
    r->buf[head & (r->size - 1u)] = byte;
    r->head = head + 1u;  // publish after the byte is stored
    return true;
}

bool stm32f4_ring_get(stm32f4_ring_t *r, uint8_t *byte)
{
    const uint32_t tail = r->tail;
    if (r->head == tail) {
        return false;
    }
    *byte = r->buf[tail & (r->size - 1u)];
    r->tail = tail + 1u;
    return true;
}

int stm32f4_usart_brr(uint32_t pclk_hz, uint32_t baud, uint32_t *brr)
{
    if (baud == 0u || pclk_hz / 16u < baud) {
        return FW_ERR_INVAL;
    }
    // With 16x oversampling BRR is USARTDIV in 12.4 fixed point, i.e. pclk / baud.
    const uint32_t div = (uint32_t)(((uint64_t)pclk_hz + baud / 2u) / baud);
    if (div > 0xFFFFu) {
        return FW_ERR_INVAL;
    }
    const uint64_t actual = pclk_hz / div;
    const uint64_t diff = actual > baud ? actual - baud : baud - actual;
    if (diff * 50u > baud) {  // more than 2 %
        return FW_ERR_INVAL;
    }
    *brr = div;
    return FW_OK;
}

int stm32f4_usart_setup(stm32f4_usart_port_t *p, uint32_t pclk_hz, uint32_t baud)
{
    uint32_t brr = 0;
    if (stm32f4_usart_brr(pclk_hz, baud, &brr) != FW_OK) {
        return FW_ERR_INVAL;
    }
    stm32f4_usart_t *u = p->regs;
    u->CR1 = 0u;  // M 0 (8 bits), no parity, 16x oversampling
    u->CR2 = 0u;  // 1 stop bit
    u->CR3 = 0u;  // no flow control (the listener's Xon/Xoff is left to the firmware)
    u->BRR = brr;
    p->rx.head = p->rx.tail = 0u;
    p->tx.head = p->tx.tail = 0u;
    p->stats.rx_bytes = p->stats.rx_overruns = p->stats.rx_errors = 0u;
    u->CR1 = USART_CR1_UE | USART_CR1_RE | USART_CR1_TE | USART_CR1_RXNEIE;
    return FW_OK;
}

bool stm32f4_usart_irq(stm32f4_usart_port_t *p)
{
    stm32f4_usart_t *u = p->regs;
    bool stored = false;
    bool received = false;  // a byte arrived, stored or not
    const uint32_t sr = u->SR;
    if (sr & (USART_SR_RXNE | USART_SR_ORE | USART_SR_FE | USART_SR_NF | USART_SR_PE)) {
        const uint8_t byte = (uint8_t)u->DR;  // SR then DR: clears RXNE and the error flags
        if (sr & USART_SR_ORE) {
            p->stats.rx_overruns++;  // the byte before this one was lost in the hardware
        }
        if (sr & (USART_SR_FE | USART_SR_NF | USART_SR_PE)) {
            p->stats.rx_errors++;
        } else if (sr & USART_SR_RXNE) {
            received = true;
            if (stm32f4_ring_put(&p->rx, byte)) {
                p->stats.rx_bytes++;
                stored = true;
            } else {
                p->stats.rx_overruns++;  // the thread has not drained the ring: counted, dropped
            }
        }
    }
    if ((u->CR1 & USART_CR1_TXEIE) && (sr & USART_SR_TXE)) {
        uint8_t out = 0;
        if (stm32f4_ring_get(&p->tx, &out)) {
            u->DR = out;
        } else {
            u->CR1 &= ~USART_CR1_TXEIE;
        }
    }
    // Also when the byte found the ring full: the firmware's last notification may have been
    // lost (its event queue was full), and a full ring stores no byte to notify it again.
    if (received && p->on_rx != NULL && stm32f4_ring_count(&p->rx) > 0u) {
        p->on_rx(p->ctx);
    }
    return stored;
}

size_t stm32f4_usart_read(stm32f4_usart_port_t *p, uint8_t *buf, size_t cap)
{
    size_t n = 0;
    while (n < cap && stm32f4_ring_get(&p->rx, &buf[n])) {
        n++;
    }
    return n;
}

size_t stm32f4_usart_queue(stm32f4_usart_port_t *p, const uint8_t *data, size_t len)
{
    if (p->regs == NULL || p->tx.buf == NULL) {
        return 0u;  // not set up: nothing would ever send the bytes
    }
    size_t n = 0;
    while (n < len && stm32f4_ring_put(&p->tx, data[n])) {
        n++;
    }
    if (n > 0u) {
        p->regs->CR1 |= USART_CR1_TXEIE;  // the interrupt sends them; caller masks IRQs around
    }
    return n;
}

size_t stm32f4_usart_put_polled(stm32f4_usart_t *u, const uint8_t *data, size_t len, uint32_t polls)
{
    size_t n = 0;
    for (; n < len; n++) {
        uint32_t waited = 0;
        while ((u->SR & USART_SR_TXE) == 0u) {
            if (++waited >= polls) {
                return n;
            }
        }
        u->DR = data[n];
    }
    return n;
}
