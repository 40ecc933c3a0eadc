// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 family: the hal_uart contract on USART2 (the Cricket listener), for every board.
//
// Received bytes come by interrupt through the driver's ring (stm32f4_usart.c, host-tested with a
// fake USART). Transmission goes through a ring too, fed by the TXE interrupt; a board whose
// USART never raises TXE's interrupt (QEMU's, boards/netduinoplus2) sets
// STM32F4_CFG_UART_TX_POLLED: its bytes are then written to DR directly, with interrupts masked,
// each after a bounded wait for TXE.
#include <stddef.h>

#include "fw/fw_assert.h"
#include "hal/hal_cpu.h"
#include "hal/hal_uart.h"
#include "stm32f4/stm32f4_cpu.h"
#include "stm32f4/stm32f4_drivers.h"

#define RCC ((stm32f4_rcc_t *)STM32F4_RCC_BASE)
#define USART2 ((stm32f4_usart_t *)STM32F4_USART2_BASE)

void USART2_IRQHandler(void);

static uint8_t uart_rx_buf_[STM32F4_CFG_UART_RX_BYTES];
#if !STM32F4_CFG_UART_TX_POLLED
static uint8_t uart_tx_buf_[STM32F4_CFG_UART_TX_BYTES];
#endif
static stm32f4_usart_port_t uart_;

int hal_uart_init(uint32_t baud, hal_uart_rx_fn on_rx, void *ctx)
{
    RCC->APB1ENR |= RCC_APB1ENR_USART2EN;
    (void)RCC->APB1ENR;
    uart_.regs = USART2;
    stm32f4_ring_init(&uart_.rx, uart_rx_buf_, sizeof uart_rx_buf_);
#if STM32F4_CFG_UART_TX_POLLED
    stm32f4_ring_init(&uart_.tx, NULL, 0u);
#else
    stm32f4_ring_init(&uart_.tx, uart_tx_buf_, sizeof uart_tx_buf_);
#endif
    uart_.on_rx = on_rx;
    uart_.ctx = ctx;
    const int rc = stm32f4_usart_setup(&uart_, STM32F4_APB1_HZ, baud);
    if (rc == FW_OK) {
        stm32f4_nvic_enable(STM32F4_IRQ_USART2, STM32F4_CFG_IRQ_PRIO_UART);
    }
    return rc;
}

void USART2_IRQHandler(void)
{
    (void)stm32f4_usart_irq(&uart_);
}

size_t hal_uart_read(uint8_t *buf, size_t cap)
{
    FW_ASSERT(buf != NULL || cap == 0u);
    return stm32f4_usart_read(&uart_, buf, cap);
}

size_t hal_uart_write(const uint8_t *data, size_t len)
{
    FW_ASSERT(data != NULL || len == 0u);
#if STM32F4_CFG_UART_TX_POLLED
    if (uart_.regs == NULL) {
        return 0u;
    }
    const uint32_t s = stm32f4_irq_save();
    const size_t n = stm32f4_usart_put_polled(USART2, data, len, STM32F4_CFG_UART_TX_POLLS);
#else
    const uint32_t s = stm32f4_irq_save();  // CR1 is also changed by the interrupt
    const size_t n = stm32f4_usart_queue(&uart_, data, len);
#endif
    stm32f4_irq_restore(s);
    return n;
}

void hal_uart_get_stats(hal_uart_stats_t *out)
{
    FW_ASSERT(out != NULL);
    stm32f4_irq_copy(out, &uart_.stats, sizeof *out);
}
