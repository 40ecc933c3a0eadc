// SPDX-License-Identifier: MIT
// dynaqpc host port: the UART. A receive ring the "interrupt" fills (hal_host_uart_feed(), from
// the simulator in lock-step or from the reader thread of a tty), and a transmit buffer the
// simulator drains, or a write() to the tty.
//
// The reader thread polls with a short timeout instead of blocking in read(), so that closing
// never waits on a line that stays silent; a pty whose other side went away reads EIO, which
// ends the reader rather than spinning on it.
//
// A real UART hears only the bytes that arrive after it is enabled. A tty, though, keeps what the
// other side wrote before anybody opened it (a pty buffers several KB): handed to the ring at
// once, that backlog overran it at every start of a program that opened its Cricket line after
// the listener began to stream. So opening a path discards the backlog, and bytes fed before
// hal_uart_init() are not stored either; both are counted apart (hal_host_uart_discarded()),
// because they are not overruns: the receiver was off, not too slow.
//
// A stall of the whole firmware (a debugger halt, a flash erase with the CPU fetching from the
// bank being erased, interrupts masked too long; on the host SIGSTOP, or the machine not
// scheduling the process) stops the receive interrupt too. An STM32F4 USART has no FIFO and the
// port uses no flow control (CR3 = 0; a Cricket listener has none): the first byte that arrives
// stays in DR, every later one finds RXNE still set, sets ORE and is lost (RM0090 30.6.1). When
// the CPU runs again the line carries fresh bytes at once. A pty instead keeps every byte its
// writer sent during the stall (several KB) and would hand that burst to the ring in one go: the
// 256-byte ring overran, and the firmware spent the next tenths of a second parsing Cricket lines
// up to a second old, then lost the fresh ones behind them (69.7 % of the bytes received over
// three 1 s stalls; docs/realtime.md "Stalls"). Neither pacing the reader at the line's rate nor
// leaving the burst in the kernel (reading only what the ring takes, i.e. RTS/CTS flow control)
// is what the hardware does with a stall's backlog: both deliver the stale bytes late instead of
// losing them. (Bytes the reader finds on time are paced at the line's rate, pace_line(): a
// burst the writer sent at once would arrive over a wire at 115200 baud, not in a microsecond.)
//
// So the reader measures its own absence. It polls every READER_POLL_MS; if more than
// STALL_GAP_MS passed since it last looked at the line, the process was not running, and what the
// tty holds now arrived while the receiver could not be serviced: the first byte is kept (DR),
// the rest are overruns, as on the MCU, and also counted in hal_host_uart_stall_lost(). The host
// cannot keep the real deadline (one byte time, 87 us at 115200 baud), so a reader late by less
// than STALL_GAP_MS is treated as on time: the pty stands in for the line's timing there. A
// reader that runs but feeds a ring the firmware does not drain still overruns the ring
// (hal_host_uart_feed()), as a too-slow consumer on the MCU does.
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "fw/fw_base.h"
#include "hal/hal_cpu.h"
#include "hal/hal_uart.h"
#include "hal_host/hal_host.h"
#include "host_internal.h"

#define DEFAULT_BAUD 115200u
#define READER_POLL_MS 20
#define STALL_GAP_MS 50 // > READER_POLL_MS plus the host's usual wake-up latency, < a 0.1 s stall

static pthread_mutex_t lock_ = PTHREAD_MUTEX_INITIALIZER;
static bool ready_;
static uint32_t baud_ = DEFAULT_BAUD;
static hal_uart_rx_fn on_rx_;
static void *rx_ctx_;
// A FIFO of bytes, for the bytes received and for the bytes sent while no tty is attached (a test
// takes them, hal_host_uart_take_tx). Its user holds lock_.
typedef struct {
    uint8_t *buf;
    uint32_t capacity;
    uint32_t head; // the oldest byte
    uint32_t count;
} byte_ring_t;
static uint8_t rx_buf_[FW_CFG_HOST_UART_RX_CAPACITY];
static uint8_t tx_buf_[FW_CFG_HOST_UART_TX_CAPACITY];
static byte_ring_t rx_ = {rx_buf_, FW_CFG_HOST_UART_RX_CAPACITY, 0, 0};
static byte_ring_t tx_ = {tx_buf_, FW_CFG_HOST_UART_TX_CAPACITY, 0, 0};
static hal_uart_stats_t stats_;
static uint32_t discarded_;
static uint32_t stall_lost_;
static uint32_t stalls_;

// Device-path mode.
static int fd_ = -1;
static pthread_t reader_;
static bool reader_running_;
static bool stop_;
static bool alive_;
static bool held_;    // hal_host_uart_hold_reader()
static bool holding_; // the reader saw held_ and stays off the line

static speed_t termios_speed(uint32_t baud)
{
    switch (baud) {
    case 9600u: return B9600;
    case 19200u: return B19200;
    case 38400u: return B38400;
    case 57600u: return B57600;
    case 115200u: return B115200;
    case 230400u: return B230400;
    default: return B0;
    }
}

static int configure_tty(int fd, uint32_t baud)
{
    speed_t sp = termios_speed(baud);
    if (sp == B0) {
        return FW_ERR_INVAL;
    }
    struct termios tio;
    if (tcgetattr(fd, &tio) != 0) {
        return FW_ERR_IO;
    }
    // Raw 8N1: no line editing, no echo, no translation, no software flow control.
    tio.c_iflag &= ~(tcflag_t)(IGNBRK | BRKINT | PARMRK | ISTRIP | INLCR | IGNCR | ICRNL | IXON);
    tio.c_oflag &= ~(tcflag_t)OPOST;
    tio.c_lflag &= ~(tcflag_t)(ECHO | ECHONL | ICANON | ISIG | IEXTEN);
    tio.c_cflag &= ~(tcflag_t)(CSIZE | PARENB | CSTOPB);
    tio.c_cflag |= (tcflag_t)(CS8 | CREAD | CLOCAL);
    tio.c_cc[VMIN] = 0;
    tio.c_cc[VTIME] = 0;
    if (cfsetispeed(&tio, sp) != 0 || cfsetospeed(&tio, sp) != 0 ||
        tcsetattr(fd, TCSANOW, &tio) != 0) {
        return FW_ERR_IO;
    }
    return FW_OK;
}

int hal_uart_init(uint32_t baud, hal_uart_rx_fn on_rx, void *ctx)
{
    if (baud < 300u || baud > 4000000u) {
        return FW_ERR_INVAL;
    }
    pthread_mutex_lock(&lock_);
    int rc = FW_OK;
    if (fd_ >= 0) {
        rc = configure_tty(fd_, baud);
    }
    if (rc == FW_OK) {
        baud_ = baud;
        on_rx_ = on_rx;
        rx_ctx_ = ctx;
        ready_ = true;
    }
    pthread_mutex_unlock(&lock_);
    return rc;
}

// Stores what fits of data[0..len) after the bytes already in r; returns how many it stored.
static size_t ring_put_(byte_ring_t *r, const uint8_t *data, size_t len)
{
    size_t n = 0;
    while (n < len && r->count < r->capacity) {
        r->buf[(r->head + r->count) % r->capacity] = data[n++];
        r->count++;
    }
    return n;
}

// Moves up to cap of the oldest bytes of r to buf, under lock_; returns how many (0 with no buf).
static size_t ring_take_(byte_ring_t *r, uint8_t *buf, size_t cap)
{
    if (buf == NULL) {
        return 0;
    }
    pthread_mutex_lock(&lock_);
    size_t n = 0;
    while (n < cap && r->count > 0u) {
        buf[n++] = r->buf[r->head];
        r->head = (r->head + 1u) % r->capacity;
        r->count--;
    }
    pthread_mutex_unlock(&lock_);
    return n;
}

size_t hal_host_uart_feed(const uint8_t *data, size_t len)
{
    if (data == NULL || len == 0u) {
        return 0;
    }
    pthread_mutex_lock(&lock_);
    const size_t stored = ready_ ? ring_put_(&rx_, data, len) : 0u;
    stats_.rx_bytes += (uint32_t)stored;
    if (ready_) {
        stats_.rx_overruns += (uint32_t)(len - stored);
    } else {
        discarded_ += (uint32_t)len;
    }
    hal_uart_rx_fn fn = on_rx_;
    void *ctx = rx_ctx_;
    // Also when nothing fitted: the firmware's last notification may have been lost (its event
    // queue was full), and a full ring stores no byte to notify it again (hal_uart_rx_fn).
    const bool unread = ready_ && rx_.count != 0u;
    pthread_mutex_unlock(&lock_);

    if (unread) {
        if (fn != NULL) {
            hal_irq_state_t irq = hal_irq_save();
            fn(ctx);
            hal_irq_restore(irq);
        }
        hal_host_cpu_wake();
    }
    return stored;
}

void hal_host_uart_inject_error(void)
{
    pthread_mutex_lock(&lock_);
    stats_.rx_errors++;
    pthread_mutex_unlock(&lock_);
}

size_t hal_uart_read(uint8_t *buf, size_t cap)
{
    return ring_take_(&rx_, buf, cap);
}

size_t hal_uart_write(const uint8_t *data, size_t len)
{
    if (data == NULL || len == 0u) {
        return 0;
    }
    pthread_mutex_lock(&lock_);
    size_t n = 0;
    if (!ready_) {
        // nothing queued before init
    } else if (fd_ >= 0) {
        ssize_t w = write(fd_, data, len);
        n = w > 0 ? (size_t)w : 0u; // EAGAIN: the line is busy, the caller retries
    } else {
        n = ring_put_(&tx_, data, len);
    }
    pthread_mutex_unlock(&lock_);
    return n;
}

void hal_uart_get_stats(hal_uart_stats_t *out)
{
    pthread_mutex_lock(&lock_);
    *out = stats_;
    pthread_mutex_unlock(&lock_);
}

size_t hal_host_uart_take_tx(uint8_t *buf, size_t cap)
{
    return ring_take_(&tx_, buf, cap);
}

static int64_t now_us(void)
{
    struct timespec ts;
    (void)clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

static int64_t now_ms(void)
{
    return now_us() / 1000;
}

// What the tty holds after the reader was away longer than STALL_GAP_MS: the first byte is kept
// (the USART's DR), the rest were lost to overrun while the CPU stood still (the header above).
// Reads until the tty is empty, bounded like discard_backlog(). Returns false on a read error.
#define STALL_MAX_READS 4096
static bool take_stall_backlog(int fd)
{
    uint8_t buf[256];
    uint32_t n = 0;
    uint8_t first = 0;
    bool open = true;
    for (int i = 0; i < STALL_MAX_READS; i++) {
        ssize_t r = read(fd, buf, sizeof buf);
        if (r > 0) {
            if (n == 0u) {
                first = buf[0];
            }
            n += (uint32_t)r;
        } else if (r < 0 && errno == EINTR) {
            continue;
        } else {
            // Empty (a raw tty with VMIN = VTIME = 0 reads 0, or EAGAIN), or an error such as the
            // EIO of a pty whose master closed, which ends the reader.
            open = r == 0 || errno == EAGAIN;
            break;
        }
    }
    if (n == 0u) {
        return open;
    }
    (void)hal_host_uart_feed(&first, 1u);
    pthread_mutex_lock(&lock_);
    if (ready_) {
        stats_.rx_overruns += n - 1u;
        stall_lost_ += n - 1u;
        stalls_++;
    } else {
        discarded_ += n - 1u; // receiver off: not an overrun (feed counted the first byte)
    }
    pthread_mutex_unlock(&lock_);
    return open;
}

// A pty hands over at once what its writer sent in one go; a wire carries it at the baud rate
// (8N1: 10 bits a byte). A writer that fell behind and caught up (the simulated devices on a
// loaded host) wrote a dozen Cricket lines at once, and fed in one go they filled the ring
// within a millisecond, before the firmware could have run: an overrun no MCU would see, since
// there the same bytes take 22 ms per 256. So the reader feeds no faster than the line: after
// handing over `n` bytes it waits until the line would have carried them. A stall's backlog is
// not paced (take_stall_backlog(): those bytes were lost on the MCU).
static void pace_line(size_t n, int64_t *line_free_us)
{
    pthread_mutex_lock(&lock_);
    const uint32_t baud = baud_;
    pthread_mutex_unlock(&lock_);
    const int64_t now = now_us();
    const int64_t from = *line_free_us > now ? *line_free_us : now;
    *line_free_us = from + (int64_t)n * 10 * 1000000 / (int64_t)baud;
    const int64_t wait = *line_free_us - now;
    if (wait > 0) {
        const struct timespec ts = {(time_t)(wait / 1000000), (long)(wait % 1000000) * 1000};
        (void)nanosleep(&ts, NULL);
    }
}

static void *reader_main(void *arg)
{
    (void)arg;
    pthread_mutex_lock(&lock_);
    int fd = fd_;
    pthread_mutex_unlock(&lock_);
    uint8_t buf[64];
    int64_t looked = now_ms(); // the last time the reader serviced the line
    int64_t line_free_us = 0;  // when the line has carried what was fed so far
    for (;;) {
        pthread_mutex_lock(&lock_);
        bool stop = stop_;
        bool held = held_;
        pthread_mutex_unlock(&lock_);
        if (stop) {
            break;
        }
        pthread_mutex_lock(&lock_);
        holding_ = held;
        pthread_mutex_unlock(&lock_);
        if (held) {
            (void)poll(NULL, 0, 2); // as a stopped process: the line is not serviced
            continue;
        }
        struct pollfd pfd = {.fd = fd, .events = POLLIN, .revents = 0};
        int pr = poll(&pfd, 1, READER_POLL_MS);
        if (pr < 0 && errno != EINTR) {
            break;
        }
        const int64_t now = now_ms();
        const bool stalled = now - looked > STALL_GAP_MS;
        looked = now;
        if (pr <= 0) {
            continue;
        }
        if (stalled) {
            if (!take_stall_backlog(fd)) {
                break;
            }
            continue;
        }
        ssize_t n = read(fd, buf, sizeof buf);
        if (n > 0) {
            (void)hal_host_uart_feed(buf, (size_t)n);
            pace_line((size_t)n, &line_free_us);
        } else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
            break; // end of stream (EOF, or EIO from a pty whose master closed)
        }
    }
    host_locked_set_bool(&lock_, &alive_, false);
    return NULL;
}

void hal_host_uart_hold_reader(bool hold)
{
    host_locked_set_bool(&lock_, &held_, hold);
    // Holding returns once the reader is off the line (it may be inside a poll of up to
    // READER_POLL_MS, and would service what arrives there); bounded, should it have ended.
    for (int i = 0; hold && reader_running_ && i < 1000; i++) {
        pthread_mutex_lock(&lock_);
        const bool off = holding_ || !alive_;
        pthread_mutex_unlock(&lock_);
        if (off) {
            break;
        }
        (void)poll(NULL, 0, 1);
    }
}

uint32_t hal_host_uart_stall_lost(void)
{
    return host_locked_u32(&lock_, &stall_lost_);
}

uint32_t hal_host_uart_stalls(void)
{
    return host_locked_u32(&lock_, &stalls_);
}

uint32_t hal_host_uart_discarded(void)
{
    return host_locked_u32(&lock_, &discarded_);
}

// Reads and counts what the tty holds from before the open, then flushes whatever the kernel
// still had queued behind it (the part beyond the line discipline's buffer). Bounded: a line that
// streams faster than it can be read ends the loop after FLUSH_MAX_READS reads anyway.
#define FLUSH_MAX_READS 4096
static uint32_t discard_backlog(int fd)
{
    uint8_t buf[256];
    uint32_t n = 0;
    for (int i = 0; i < FLUSH_MAX_READS; i++) {
        ssize_t r = read(fd, buf, sizeof buf);
        if (r > 0) {
            n += (uint32_t)r;
        } else if (r < 0 && errno == EINTR) {
            continue;
        } else {
            break; // EAGAIN: nothing more waiting; 0 or an error: the reader will see it too
        }
    }
    (void)tcflush(fd, TCIFLUSH);
    return n;
}

int hal_host_uart_open_path(const char *path)
{
    if (path == NULL) {
        return FW_ERR_INVAL;
    }
    hal_host_uart_close_path();
    int fd = open(path, O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (fd < 0) {
        return FW_ERR_IO;
    }
    if (!isatty(fd)) {
        close(fd);
        return FW_ERR_IO;
    }
    pthread_mutex_lock(&lock_);
    int rc = configure_tty(fd, baud_);
    if (rc == FW_OK) {
        discarded_ += discard_backlog(fd);
        fd_ = fd;
        stop_ = false;
        alive_ = true;
    }
    pthread_mutex_unlock(&lock_);
    if (rc != FW_OK) {
        close(fd);
        return rc;
    }
    if (pthread_create(&reader_, NULL, reader_main, NULL) != 0) {
        pthread_mutex_lock(&lock_);
        fd_ = -1;
        alive_ = false;
        pthread_mutex_unlock(&lock_);
        close(fd);
        return FW_ERR_IO;
    }
    reader_running_ = true;
    return FW_OK;
}

void hal_host_uart_close_path(void)
{
    if (reader_running_) {
        pthread_mutex_lock(&lock_);
        stop_ = true;
        pthread_mutex_unlock(&lock_);
        pthread_join(reader_, NULL);
        reader_running_ = false;
    }
    pthread_mutex_lock(&lock_);
    if (fd_ >= 0) {
        close(fd_);
        fd_ = -1;
    }
    alive_ = false;
    pthread_mutex_unlock(&lock_);
}

bool hal_host_uart_path_alive(void)
{
    return host_locked_bool(&lock_, &alive_);
}

void host_uart_reset(void)
{
    hal_host_uart_close_path();
    pthread_mutex_lock(&lock_);
    ready_ = false;
    baud_ = DEFAULT_BAUD;
    on_rx_ = NULL;
    rx_ctx_ = NULL;
    rx_.head = rx_.count = 0;
    tx_.head = tx_.count = 0;
    memset(&stats_, 0, sizeof stats_);
    discarded_ = 0;
    stall_lost_ = 0;
    stalls_ = 0;
    held_ = false;
    holding_ = false;
    pthread_mutex_unlock(&lock_);
}
