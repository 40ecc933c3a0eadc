// SPDX-License-Identifier: MIT
// dynaqpc HAL: the serial port of the Cricket listener (115200 8N1, ASCII lines).
//
// Bytes arrive by interrupt into a ring buffer the port owns; the firmware drains it from a task.
// On the host the bytes come from the simulator in lock-step, or from a pty between processes.
#ifndef HAL_UART_H
#define HAL_UART_H

#include <stddef.h>
#include <stdint.h>

#include "fw/fw_base.h"  // FW_OK and the FW_ERR_* codes the functions return

#ifdef __cplusplus
extern "C" {
#endif

/// Called by the port on every receive interrupt after which the ring holds unread bytes: when a
/// byte was stored, and also when a byte was lost because the ring was full. So a firmware that
/// could not act on one call (its event queue was full) hears again with the next byte, and a
/// line that keeps sending is never left undrained for good. Context: interrupt. Must not block.
typedef void (*hal_uart_rx_fn)(void *ctx);

typedef struct hal_uart_stats {
    uint32_t rx_bytes;      ///< bytes stored in the ring buffer
    uint32_t rx_overruns;   ///< bytes lost: ring buffer full, or the hardware's overrun flag
    uint32_t rx_errors;     ///< framing and noise errors (the byte is dropped)
} hal_uart_stats_t;

/// Opens the port at `baud`, 8 data bits, no parity, 1 stop bit; `on_rx` may be NULL.
/// Returns FW_OK, FW_ERR_INVAL (baud not reachable within 2 %), or FW_ERR_IO.
/// Context: thread, at boot.
FW_CHECK_RETURN int hal_uart_init(uint32_t baud, hal_uart_rx_fn on_rx, void *ctx);

/// Copies up to `cap` received bytes into `buf`, oldest first. Returns how many (0 if none).
/// Never blocks. Context: thread (one reader).
size_t hal_uart_read(uint8_t *buf, size_t cap);

/// Queues bytes for transmission (the Cricket listener takes configuration commands). Returns
/// how many were queued, which may be fewer than `len` when the TX buffer is full. Never blocks.
/// Context: thread.
size_t hal_uart_write(const uint8_t *data, size_t len);

void hal_uart_get_stats(hal_uart_stats_t *out);

#ifdef __cplusplus
}
#endif

#endif // HAL_UART_H
