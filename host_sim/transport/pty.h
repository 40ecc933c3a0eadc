// SPDX-License-Identifier: MIT
// dynaqpc host_sim transport: a pseudo-terminal standing in for a serial line.
//
// The simulator exposes the Cricket listener's serial output on a pty; `dynaqpc-cricket` (or
// anything using pyserial, minicom, screen) opens the slave path as if it were /dev/ttyUSB0.
// The line is raw (no echo, no line editing, no CR/LF translation): bytes pass unchanged.
//
// Bytes written while nobody has the slave open are kept by the kernel (20 KB measured on
// Linux; then pty_write() returns 0) and handed to whoever opens the slave next, all at once. A
// real serial line keeps nothing for a receiver that is off, so readers drop that backlog:
// pyserial flushes its input when it opens the port, and the host port's UART discards and counts
// it (hal_host_uart_open_path()). The Cricket listener just keeps streaming, as the real one does.
// Closing the master hangs up the slave: a reader sees end of stream.
#ifndef PTY_H
#define PTY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "fw/fw_base.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pty {
    int master_fd; ///< -1 when closed
} pty_t;

/// Opens a pty master in raw, non-blocking mode and writes the slave's path ("/dev/pts/N") into
/// `slave_path` (capacity `cap`, NUL-terminated). Returns FW_OK, FW_ERR_INVAL (NULL argument or
/// `cap` too small for the path) or FW_ERR_IO (no pty available; errno tells why). On failure
/// nothing stays open. Context: thread.
int pty_open(pty_t *pty, char *slave_path, size_t cap);

/// Writes up to `len` bytes without blocking. Returns the number written (0 when the pty's
/// buffer is full: the reader is not keeping up) or FW_ERR_IO.
int pty_write(pty_t *pty, const void *buf, size_t len);

/// Reads up to `cap` bytes the slave side wrote, without blocking. Returns the number read,
/// 0 when nothing is waiting, or FW_ERR_IO (also: nobody has the slave open).
int pty_read(pty_t *pty, void *buf, size_t cap);

/// True once the last process holding the slave open has closed it (the reader went away; the
/// next open of the slave clears it). False before anybody opened the slave: Linux reports no
/// hang-up then. Never blocks.
bool pty_peer_hung_up(const pty_t *pty);

/// Closes the master: readers of the slave see end of stream. Safe to call twice.
void pty_close(pty_t *pty);

#ifdef __cplusplus
}
#endif

#endif // PTY_H
