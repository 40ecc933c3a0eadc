// SPDX-License-Identifier: MIT
// dynaqpc host_sim transport: a pseudo-terminal standing in for a serial line.
//
// Raw mode is set on the master: master and slave share one termios, so the slave is raw for
// whoever opens it (pyserial sets its own mode again anyway).
#define _GNU_SOURCE 1 // ptsname_r (glibc, musl); the thread-safe ptsname

#include "pty.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

#include "fw/fw_base.h"

int pty_open(pty_t *pty, char *slave_path, size_t cap)
{
    struct termios t;
    if (pty == NULL || slave_path == NULL || cap == 0u) {
        return FW_ERR_INVAL;
    }
    pty->master_fd = posix_openpt(O_RDWR | O_NOCTTY);
    if (pty->master_fd < 0) {
        return FW_ERR_IO;
    }
    int rc = FW_ERR_IO;
    if (grantpt(pty->master_fd) != 0 || unlockpt(pty->master_fd) != 0) {
        goto fail;
    }
    if (ptsname_r(pty->master_fd, slave_path, cap) != 0) {
        rc = errno == ERANGE ? FW_ERR_INVAL : FW_ERR_IO;
        goto fail;
    }
    if (tcgetattr(pty->master_fd, &t) != 0) {
        goto fail;
    }
    cfmakeraw(&t);
    (void)cfsetispeed(&t, B115200);
    (void)cfsetospeed(&t, B115200);
    int flags = fcntl(pty->master_fd, F_GETFL);
    if (tcsetattr(pty->master_fd, TCSANOW, &t) != 0 || flags < 0 ||
        fcntl(pty->master_fd, F_SETFL, flags | O_NONBLOCK) != 0) {
        goto fail;
    }
    return FW_OK;
fail:
    {
        int saved = errno;
        pty_close(pty);
        slave_path[0] = '\0';
        errno = saved;
    }
    return rc;
}

// pty_write()'s and pty_read()'s answer from the call's (after EINTR's retries): the bytes moved;
// 0 when the non-blocking master had no room or nothing to read (EAGAIN); FW_ERR_IO otherwise.
static int transfer_result_(ssize_t n)
{
    if (n < 0) {
        return (errno == EAGAIN || errno == EWOULDBLOCK) ? 0 : FW_ERR_IO;
    }
    return (int)n;
}

int pty_write(pty_t *pty, const void *buf, size_t len)
{
    ssize_t n;
    do {
        n = write(pty->master_fd, buf, len);
    } while (n < 0 && errno == EINTR);
    return transfer_result_(n);
}

int pty_read(pty_t *pty, void *buf, size_t cap)
{
    ssize_t n;
    do {
        n = read(pty->master_fd, buf, cap);
    } while (n < 0 && errno == EINTR);
    return transfer_result_(n);
}

bool pty_peer_hung_up(const pty_t *pty)
{
    struct pollfd p = {pty->master_fd, POLLOUT, 0};
    if (pty->master_fd < 0 || poll(&p, 1, 0) < 0) {
        return false;
    }
    return (p.revents & POLLHUP) != 0;
}

void pty_close(pty_t *pty)
{
    if (pty != NULL && pty->master_fd >= 0) {
        close(pty->master_fd);
        pty->master_fd = -1;
    }
}
