// SPDX-License-Identifier: MIT
// dynaqpc: contract tests of the host HAL port: NOR flash (with power cuts and a backing file),
// CAN delivery and transmission, the UART ring (and a real pty), clock, irq nesting, watchdog.
#define _XOPEN_SOURCE 600 // posix_openpt, grantpt, unlockpt, ptsname
#include "test_common.h"

#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include "fw/fw_base.h"
#include "hal/hal_can.h"
#include "hal/hal_cpu.h"
#include "hal/hal_flash.h"
#include "hal/hal_time.h"
#include "hal/hal_uart.h"
#include "hal_host/hal_host.h"

static int setup(void **state)
{
    (void)state;
    hal_host_reset();
    assert_int_equal(hal_time_init(), FW_OK);
    return 0;
}

// The pty tests run their thread, and so the port's reader thread that hal_host_uart_open_path()
// starts (it inherits the policy), at a real-time priority where this process may (root). The
// reader stands in for the receive interrupt, and the port takes a reader away from the line for
// more than 50 ms for a stalled firmware (host_uart.c: SIGSTOP, or a machine that does not
// schedule it), losing all but one byte of what the line held. At the normal policy a loaded
// machine kept it off the CPU that long: a line written while "running" arrived as one byte
// (test_uart_pty 0x1 != 0x30, test_uart_pty_backlog_discarded_at_open 0x31 != 0x130; 5 runs in
// 180 next to five busy loops), and the burst test's drainer, held off for the 22 ms the line
// takes to fill the ring, overran it. Those tests assert what a reader serviced on time does;
// the stall path has its own, test_uart_pty_stall_loses_backlog (hal_host_uart_hold_reader()).
// Elsewhere they run at the normal policy, and a heavily loaded machine can still fail them.
static int pty_setup(void **state)
{
    const struct sched_param rt = {.sched_priority = 1};
    (void)pthread_setschedparam(pthread_self(), SCHED_FIFO, &rt); // refused without CAP_SYS_NICE
    return setup(state);
}

static int pty_teardown(void **state)
{
    (void)state;
    hal_host_uart_close_path(); // the reader ends before this thread leaves the priority
    const struct sched_param normal = {.sched_priority = 0};
    (void)pthread_setschedparam(pthread_self(), SCHED_OTHER, &normal);
    return 0;
}

// ---- Flash --------------------------------------------------------------------------------------

#define SECTOR 1024u

static int flash_setup(void **state)
{
    (void)setup(state);
    assert_int_equal(hal_host_flash_configure(SECTOR, 4u, 4u), FW_OK);
    return 0;
}

static void assert_bytes(uint32_t offset, size_t len, uint8_t value)
{
    uint8_t buf[SECTOR];
    assert_true(len <= sizeof buf);
    assert_int_equal(hal_flash_read(offset, buf, len), FW_OK);
    for (size_t i = 0; i < len; i++) {
        if (buf[i] != value) {
            fail_msg("byte %u is 0x%02x, expected 0x%02x", (unsigned)(offset + i), buf[i], value);
        }
    }
}

static void test_flash_geometry_and_configure(void **state)
{
    (void)state;
    hal_flash_geometry_t g;
    assert_int_equal(hal_flash_get_geometry(&g), FW_OK);
    assert_int_equal(g.sector_size, SECTOR);
    assert_int_equal(g.sector_count, 4);
    assert_int_equal(g.write_align, 4);
    assert_bytes(0, SECTOR, 0xFF);
    assert_int_equal(hal_host_flash_configure(SECTOR, 1u, 4u), FW_ERR_INVAL);
    assert_int_equal(hal_host_flash_configure(0u, 2u, 4u), FW_ERR_INVAL);
    assert_int_equal(hal_host_flash_configure(SECTOR, 2u, 3u), FW_ERR_INVAL);
    assert_int_equal(hal_host_flash_configure(6u, 2u, 4u), FW_ERR_INVAL);
    assert_int_equal(hal_host_flash_configure(FW_CFG_HOST_FLASH_CAPACITY, 2u, 4u), FW_ERR_INVAL);
    assert_int_equal(hal_host_flash_configure(0x80000000u, 4u, 4u), FW_ERR_INVAL);
    assert_int_equal(hal_host_flash_configure(FW_CFG_HOST_FLASH_CAPACITY / 2u, 2u, 4u), FW_OK);
    assert_int_equal(hal_flash_get_geometry(&g), FW_OK);
    assert_int_equal(g.sector_size, FW_CFG_HOST_FLASH_CAPACITY / 2u);
}

static void test_flash_nor_semantics(void **state)
{
    (void)state;
    const uint8_t a[8] = {0x00, 0x0F, 0xF0, 0xAA, 0x55, 0xFF, 0x12, 0x34};
    assert_int_equal(hal_flash_write(16, a, sizeof a), FW_OK);
    uint8_t r[8];
    assert_int_equal(hal_flash_read(16, r, sizeof r), FW_OK);
    assert_memory_equal(r, a, sizeof a);
    // Clearing more bits of a programmed word is what NOR can do: allowed.
    const uint8_t b[4] = {0x00, 0x0E, 0x80, 0x00};
    assert_int_equal(hal_flash_write(16, b, sizeof b), FW_OK);
    assert_int_equal(hal_flash_read(16, r, 4), FW_OK);
    assert_memory_equal(r, b, 4);
    // A 0 -> 1 cannot be programmed: verify fails, the bits that could clear did.
    const uint8_t c[4] = {0xFF, 0x50, 0xFF, 0x00};
    assert_int_equal(hal_flash_write(20, c, sizeof c), FW_ERR_IO);
    assert_int_equal(hal_flash_read(20, r, 4), FW_OK);
    const uint8_t anded[4] = {0x55 & 0xFF, 0xFF & 0x50, 0x12 & 0xFF, 0x34 & 0x00};
    assert_memory_equal(r, anded, 4);
    // Erase restores 0xFF in that sector only.
    assert_int_equal(hal_flash_write(SECTOR, a, 4), FW_OK);
    assert_int_equal(hal_flash_erase(0), FW_OK);
    assert_bytes(0, SECTOR, 0xFF);
    assert_int_equal(hal_flash_read(SECTOR, r, 4), FW_OK);
    assert_memory_equal(r, a, 4);
    assert_int_equal(hal_host_flash_erase_count(), 1);
    assert_int_equal(hal_host_flash_programmed_bytes(), 8u + 4u + 4u + 4u);
}

static void test_flash_alignment_and_range(void **state)
{
    (void)state;
    const uint8_t d[8] = {0};
    uint8_t r[8];
    assert_int_equal(hal_flash_write(2, d, 4), FW_ERR_INVAL);
    assert_int_equal(hal_flash_write(4, d, 3), FW_ERR_INVAL);
    assert_int_equal(hal_flash_write(4 * SECTOR - 4, d, 8), FW_ERR_INVAL);
    assert_int_equal(hal_flash_write(4 * SECTOR, d, 4), FW_ERR_INVAL);
    assert_int_equal(hal_flash_write(UINT32_MAX - 3u, d, 4), FW_ERR_INVAL);
    assert_int_equal(hal_flash_write(0, NULL, 4), FW_ERR_INVAL);
    assert_int_equal(hal_flash_write(4 * SECTOR - 4, d, 4), FW_OK);
    assert_int_equal(hal_flash_read(4 * SECTOR - 4, r, 5), FW_ERR_INVAL);
    assert_int_equal(hal_flash_read(UINT32_MAX, r, 1), FW_ERR_INVAL);
    assert_int_equal(hal_flash_read(4 * SECTOR, r, 0), FW_OK);
    assert_int_equal(hal_flash_erase(4), FW_ERR_INVAL);
    // Nothing else changed.
    assert_bytes(0, SECTOR, 0xFF);
    assert_int_equal(hal_host_flash_programmed_bytes(), 4u);
}

static void test_flash_power_cut(void **state)
{
    (void)state;
    uint8_t d[32];
    for (uint32_t i = 0; i < sizeof d; i++) {
        d[i] = (uint8_t)i;
    }
    // 4 bytes go through in a first write, then 10 more: the second write of 16 bytes at 104
    // programs 104..113 and leaves 114..119 erased.
    hal_host_flash_cut_power_after(14);
    assert_int_equal(hal_flash_write(96, d, 4), FW_OK);
    assert_int_equal(hal_flash_write(104, d, 16), FW_ERR_IO);
    uint8_t r[24];
    assert_int_equal(hal_flash_read(96, r, sizeof r), FW_OK);
    assert_memory_equal(r, d, 4);
    assert_bytes(100, 4, 0xFF);
    assert_memory_equal(&r[8], d, 10);
    assert_bytes(114, 6, 0xFF);
    // Power stays off: writes and erases do nothing.
    assert_int_equal(hal_flash_write(200, d, 4), FW_ERR_IO);
    assert_int_equal(hal_flash_erase(0), FW_ERR_IO);
    assert_bytes(200, 4, 0xFF);
    assert_int_equal(hal_flash_read(96, r, 4), FW_OK);
    assert_memory_equal(r, d, 4);
    hal_host_flash_restore_power();
    assert_int_equal(hal_flash_write(200, d, 4), FW_OK);
    assert_int_equal(hal_flash_erase(0), FW_OK);
    assert_bytes(0, SECTOR, 0xFF);

    // A cut exactly at the end of a write: it succeeds, the next does nothing.
    hal_host_flash_cut_power_after(8);
    assert_int_equal(hal_flash_write(0, d, 8), FW_OK);
    assert_int_equal(hal_flash_write(8, d, 4), FW_ERR_IO);
    assert_bytes(8, 4, 0xFF);
    // A cut at 0: nothing at all.
    hal_host_flash_restore_power();
    hal_host_flash_cut_power_after(0);
    assert_int_equal(hal_flash_write(16, d, 4), FW_ERR_IO);
    assert_bytes(16, 4, 0xFF);
    hal_host_flash_restore_power();
}

static void temp_path(char *buf, size_t cap)
{
    const char *dir = getenv("TMPDIR");
    snprintf(buf, cap, "%s/dynaqpc_flash_XXXXXX", dir != NULL ? dir : "/tmp");
    int fd = mkstemp(buf);
    assert_true(fd >= 0);
    close(fd);
    assert_int_equal(unlink(buf), 0); // attach creates it
}

static long file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long)st.st_size : -1L;
}

static void test_flash_file_round_trip(void **state)
{
    (void)state;
    char path[256];
    temp_path(path, sizeof path);
    const uint8_t d[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    assert_int_equal(hal_host_flash_attach_file(path), FW_OK);
    assert_int_equal(file_size(path), 4 * SECTOR);
    assert_int_equal(hal_flash_write(SECTOR + 8, d, 8), FW_OK);
    // A power cut while attached: the file holds exactly what was programmed.
    hal_host_flash_cut_power_after(4);
    assert_int_equal(hal_flash_write(2 * SECTOR, d, 8), FW_ERR_IO);
    hal_host_flash_restore_power();
    hal_host_flash_detach_file();

    // A reboot with fresh RAM: configure erases the image, the file brings it back.
    assert_int_equal(hal_host_flash_configure(SECTOR, 4u, 4u), FW_OK);
    assert_bytes(SECTOR + 8, 8, 0xFF);
    assert_int_equal(hal_host_flash_attach_file(path), FW_OK);
    uint8_t r[8];
    assert_int_equal(hal_flash_read(SECTOR + 8, r, 8), FW_OK);
    assert_memory_equal(r, d, 8);
    assert_int_equal(hal_flash_read(2 * SECTOR, r, 8), FW_OK);
    assert_memory_equal(r, d, 4);
    assert_bytes(2 * SECTOR + 4, 4, 0xFF);
    // Erase goes through too.
    assert_int_equal(hal_flash_erase(1), FW_OK);
    hal_host_flash_detach_file();
    assert_int_equal(hal_host_flash_configure(SECTOR, 4u, 4u), FW_OK);
    assert_int_equal(hal_host_flash_attach_file(path), FW_OK);
    assert_bytes(SECTOR, SECTOR, 0xFF);
    assert_int_equal(hal_flash_read(2 * SECTOR, r, 4), FW_OK);
    assert_memory_equal(r, d, 4);
    hal_host_flash_detach_file();

    // A file of the wrong size is refused and left alone; the image is untouched.
    assert_int_equal(hal_host_flash_configure(SECTOR, 2u, 4u), FW_OK);
    assert_int_equal(hal_flash_write(0, d, 8), FW_OK);
    assert_int_equal(hal_host_flash_attach_file(path), FW_ERR_CORRUPT);
    assert_int_equal(file_size(path), 4 * SECTOR);
    assert_int_equal(hal_flash_read(0, r, 8), FW_OK);
    assert_memory_equal(r, d, 8);
    assert_int_equal(hal_host_flash_attach_file("/nonexistent-dir/flash.bin"), FW_ERR_IO);
    assert_int_equal(hal_host_flash_attach_file(NULL), FW_ERR_INVAL);
    assert_int_equal(unlink(path), 0);
}

// Loading a file boots from it without backing it: what the firmware writes stays in RAM.
static void test_flash_load_file_leaves_the_file(void **state)
{
    (void)state;
    char path[256];
    temp_path(path, sizeof path);
    const uint8_t d[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    const uint8_t e[8] = {9, 9, 9, 9, 9, 9, 9, 9};
    assert_int_equal(hal_host_flash_load_file(path), FW_ERR_IO);  // it must exist
    assert_int_equal(hal_host_flash_attach_file(path), FW_OK);
    assert_int_equal(hal_flash_write(SECTOR, d, 8), FW_OK);
    hal_host_flash_detach_file();

    assert_int_equal(hal_host_flash_configure(SECTOR, 4u, 4u), FW_OK);
    assert_int_equal(hal_host_flash_load_file(path), FW_OK);
    uint8_t r[8];
    assert_int_equal(hal_flash_read(SECTOR, r, 8), FW_OK);
    assert_memory_equal(r, d, 8);
    assert_int_equal(hal_flash_erase(1), FW_OK);
    assert_int_equal(hal_flash_write(SECTOR, e, 8), FW_OK);
    assert_int_equal(hal_flash_read(SECTOR, r, 8), FW_OK);
    assert_memory_equal(r, e, 8);
    // The file still holds what it held.
    assert_int_equal(hal_host_flash_configure(SECTOR, 4u, 4u), FW_OK);
    assert_int_equal(hal_host_flash_load_file(path), FW_OK);
    assert_int_equal(hal_flash_read(SECTOR, r, 8), FW_OK);
    assert_memory_equal(r, d, 8);
    // A file of another size is refused and the image is untouched.
    assert_int_equal(hal_host_flash_configure(SECTOR, 2u, 4u), FW_OK);
    assert_int_equal(hal_flash_write(0, e, 8), FW_OK);
    assert_int_equal(hal_host_flash_load_file(path), FW_ERR_CORRUPT);
    assert_int_equal(hal_flash_read(0, r, 8), FW_OK);
    assert_memory_equal(r, e, 8);
    assert_int_equal(hal_host_flash_load_file(NULL), FW_ERR_INVAL);
    assert_int_equal(unlink(path), 0);
}

// ---- CAN ----------------------------------------------------------------------------------------

#define RX_LOG 16
static hal_can_frame_t rx_log_[RX_LOG];
static uint32_t rx_n_;
static uint32_t rx_depth_ok_;

static void can_rx(const hal_can_frame_t *frame, void *ctx)
{
    assert_ptr_equal(ctx, &rx_n_);
    if (rx_n_ < RX_LOG) {
        rx_log_[rx_n_] = *frame;
    }
    rx_n_++;
    // Handlers run as interrupts: the irq lock is held, and nesting it works.
    hal_irq_state_t st = hal_irq_save();
    if (st >= 1u) {
        rx_depth_ok_++;
    }
    hal_irq_restore(st);
}

static hal_can_frame_t frame(uint32_t id, uint8_t dlc, uint8_t flags)
{
    hal_can_frame_t f;
    memset(&f, 0xEE, sizeof f); // padding bytes beyond dlc must not reach the handler
    f.id = id;
    f.dlc = dlc;
    f.flags = flags;
    for (uint8_t i = 0; i < dlc && i < 8u; i++) {
        f.data[i] = (uint8_t)(id + i);
    }
    return f;
}

static void test_can_init_and_filters(void **state)
{
    (void)state;
    rx_n_ = 0;
    rx_depth_ok_ = 0;
    hal_can_frame_t f = frame(0x100, 2, 0);
    assert_int_equal(hal_host_can_deliver(&f), FW_ERR_IO); // before init
    assert_int_equal(hal_can_send(&f), FW_ERR_IO);
    const uint32_t ids[] = {0x100, 0x2A0};
    assert_int_equal(hal_can_init(500000u, ids, 2, NULL, NULL), FW_ERR_INVAL);
    assert_int_equal(hal_can_init(5000000u, ids, 2, can_rx, &rx_n_), FW_ERR_INVAL);
    const uint32_t bad_ids[] = {0x800};
    assert_int_equal(hal_can_init(500000u, bad_ids, 1, can_rx, &rx_n_), FW_ERR_INVAL);
    assert_int_equal(hal_can_init(500000u, ids, FW_CFG_HOST_CAN_MAX_FILTER_IDS + 1u, can_rx,
                                  &rx_n_),
                     FW_ERR_INVAL);
    assert_int_equal(hal_can_init(500000u, ids, 2, can_rx, &rx_n_), FW_OK);
    assert_int_equal(hal_host_can_bitrate(), 500000u);

    assert_int_equal(hal_host_can_deliver(&f), FW_OK);
    hal_can_frame_t other = frame(0x101, 8, 0);
    assert_int_equal(hal_host_can_deliver(&other), FW_ERR_NOENT);
    hal_can_frame_t ext = frame(0x100, 1, HAL_CAN_FLAG_EXTENDED);
    assert_int_equal(hal_host_can_deliver(&ext), FW_ERR_NOENT);
    hal_can_frame_t rtr = frame(0x2A0, 4, HAL_CAN_FLAG_REMOTE);
    assert_int_equal(hal_host_can_deliver(&rtr), FW_OK);
    assert_int_equal(rx_n_, 2);
    assert_int_equal(rx_log_[0].id, 0x100);
    assert_int_equal(rx_log_[0].dlc, 2);
    assert_int_equal(rx_log_[0].data[0], 0x00);
    assert_int_equal(rx_log_[0].data[1], 0x01);
    for (int i = 2; i < 8; i++) {
        assert_int_equal(rx_log_[0].data[i], 0); // zeroed beyond dlc
    }
    for (int i = 0; i < 8; i++) {
        assert_int_equal(rx_log_[1].data[i], 0); // a remote frame carries no data
    }
    assert_int_equal(rx_depth_ok_, 2);

    // Bad frames are refused and counted as bus errors; nothing reaches the handler.
    hal_can_frame_t bad[4] = {frame(0x100, 9, 0), frame(0x800, 1, 0),
                              frame(0x20000000u, 1, HAL_CAN_FLAG_EXTENDED), frame(0x100, 1, 0x80)};
    for (int i = 0; i < 4; i++) {
        assert_int_equal(hal_host_can_deliver(&bad[i]), FW_ERR_INVAL);
        assert_int_equal(hal_can_send(&bad[i]), FW_ERR_INVAL);
    }
    assert_int_equal(hal_host_can_deliver(NULL), FW_ERR_INVAL);
    hal_can_stats_t st;
    hal_can_get_stats(&st);
    assert_int_equal(st.rx_frames, 2);
    assert_int_equal(st.bus_errors, 4);
    assert_int_equal(st.tx_frames, 0);
    assert_int_equal(rx_n_, 2);

    // An empty list accepts everything, extended ids included.
    assert_int_equal(hal_can_init(250000u, NULL, 0, can_rx, &rx_n_), FW_OK);
    hal_can_frame_t e2 = frame(0x1ABCDEF0u, 8, HAL_CAN_FLAG_EXTENDED);
    assert_int_equal(hal_host_can_deliver(&e2), FW_OK);
    assert_int_equal(hal_host_can_deliver(&other), FW_OK);
    assert_int_equal(rx_n_, 4);
    assert_int_equal(rx_log_[2].id, 0x1ABCDEF0u);
    hal_host_can_count_rx_overrun(3);
    hal_can_get_stats(&st);
    assert_int_equal(st.rx_overruns, 3);
}

// A stall's backlog meets bxCAN's unlocked three-mailbox FIFO: of ten accepted frames the first
// two and the last reach the handler, in that order, and the seven overwritten ones are counted
// as overruns and stall losses; filtered frames take no mailbox and invalid ones are bus errors.
// Fails if the backlog is handed over whole (ten frames, no overrun).
static void test_can_stall_keeps_what_the_fifo_holds(void **state)
{
    (void)state;
    rx_n_ = 0;
    const uint32_t ids[] = {0x100};
    assert_int_equal(hal_can_init(500000u, ids, 1, can_rx, &rx_n_), FW_OK);
    hal_can_frame_t f = frame(0x100, 1, 0);
    hal_can_frame_t other = frame(0x200, 1, 0);
    hal_can_frame_t bad = frame(0x100, 9, 0);
    hal_host_can_stall_begin();
    for (uint8_t i = 0; i < 10u; i++) {
        f.data[0] = i;
        assert_int_equal(hal_host_can_deliver_stalled(&f), FW_OK);
        assert_int_equal(hal_host_can_deliver_stalled(&other), FW_ERR_NOENT);
    }
    assert_int_equal(hal_host_can_deliver_stalled(&bad), FW_ERR_INVAL);
    assert_int_equal(rx_n_, 2);  // the newest waits in the last mailbox until the stall ends
    hal_host_can_stall_end();
    assert_int_equal(rx_n_, 3);
    assert_int_equal(rx_log_[0].data[0], 0);
    assert_int_equal(rx_log_[1].data[0], 1);
    assert_int_equal(rx_log_[2].data[0], 9);
    hal_can_stats_t st;
    hal_can_get_stats(&st);
    assert_int_equal(st.rx_frames, 3);
    assert_int_equal(st.rx_overruns, 7);
    assert_int_equal(st.bus_errors, 1);
    assert_int_equal(hal_host_can_stall_lost(), 7);

    // A stall with fewer frames than mailboxes loses nothing; outside one, frames go straight in.
    hal_host_can_stall_begin();
    assert_int_equal(hal_host_can_deliver_stalled(&f), FW_OK);
    hal_host_can_stall_end();
    assert_int_equal(hal_host_can_deliver_stalled(&f), FW_OK);
    assert_int_equal(rx_n_, 5);
    assert_int_equal(hal_host_can_stall_lost(), 7);
}

static void test_can_send_and_take(void **state)
{
    (void)state;
    assert_int_equal(hal_can_init(500000u, NULL, 0, can_rx, &rx_n_), FW_OK);
    hal_can_frame_t out;
    assert_false(hal_host_can_take_tx(&out));
    for (uint32_t i = 0; i < FW_CFG_HOST_CAN_TX_CAPACITY; i++) {
        hal_can_frame_t f = frame(i & 0x7FFu, (uint8_t)(i % 9u), 0);
        assert_int_equal(hal_can_send(&f), FW_OK);
    }
    hal_can_frame_t more = frame(0x7FF, 1, 0);
    assert_int_equal(hal_can_send(&more), FW_ERR_FULL);
    for (uint32_t i = 0; i < FW_CFG_HOST_CAN_TX_CAPACITY; i++) {
        assert_true(hal_host_can_take_tx(&out));
        assert_int_equal(out.id, i & 0x7FFu);
        assert_int_equal(out.dlc, i % 9u);
    }
    assert_false(hal_host_can_take_tx(&out));
    // Room again after draining, and the order wraps correctly.
    assert_int_equal(hal_can_send(&more), FW_OK);
    assert_true(hal_host_can_take_tx(&out));
    assert_int_equal(out.id, 0x7FF);
    hal_can_stats_t st;
    hal_can_get_stats(&st);
    assert_int_equal(st.tx_frames, FW_CFG_HOST_CAN_TX_CAPACITY + 1u);
    assert_int_equal(st.tx_dropped, 1);
}

// A transport that keeps what it is given and refuses when told to: the routing under test is
// the port's, the transport is the caller's plug.
static uint32_t tr_sent_;
static int tr_result_;
static uint32_t tr_last_id_;

static int tr_send(const hal_can_frame_t *f, void *ctx)
{
    assert_ptr_equal(ctx, &tr_sent_);
    if (tr_result_ == FW_OK) {
        tr_sent_++;
        tr_last_id_ = f->id;
    }
    return tr_result_;
}

static void test_can_transport(void **state)
{
    (void)state;
    static const hal_host_can_transport_t tr = {tr_send, &tr_sent_};
    tr_sent_ = 0;
    tr_result_ = FW_OK;
    assert_int_equal(hal_can_init(500000u, NULL, 0, can_rx, &rx_n_), FW_OK);
    hal_host_can_set_transport(&tr);
    hal_can_frame_t f = frame(0x321, 3, 0);
    assert_int_equal(hal_can_send(&f), FW_OK);
    assert_int_equal(tr_sent_, 1);
    assert_int_equal(tr_last_id_, 0x321);
    hal_can_frame_t out;
    assert_false(hal_host_can_take_tx(&out)); // not in the lock-step queue
    tr_result_ = FW_ERR_FULL;
    assert_int_equal(hal_can_send(&f), FW_ERR_FULL);
    tr_result_ = -42;
    assert_int_equal(hal_can_send(&f), FW_ERR_IO);
    hal_can_stats_t st;
    hal_can_get_stats(&st);
    assert_int_equal(st.tx_frames, 1);
    assert_int_equal(st.tx_dropped, 2);
    hal_host_can_set_transport(NULL);
    assert_int_equal(hal_can_send(&f), FW_OK);
    assert_true(hal_host_can_take_tx(&out));
}

// ---- UART ---------------------------------------------------------------------------------------

static uint32_t notified_;

static void uart_rx(void *ctx)
{
    (void)ctx;
    notified_++;
}

static void test_uart_ring_and_overruns(void **state)
{
    (void)state;
    notified_ = 0;
    uint8_t buf[FW_CFG_HOST_UART_RX_CAPACITY + 64];
    for (size_t i = 0; i < sizeof buf; i++) {
        buf[i] = (uint8_t)(i * 7u);
    }
    // Before init the receiver is off: nothing stored, counted as discarded (not an overrun).
    assert_int_equal(hal_host_uart_feed(buf, 10), 0);
    assert_int_equal(hal_host_uart_discarded(), 10);
    assert_int_equal(hal_uart_init(100u, uart_rx, NULL), FW_ERR_INVAL);
    assert_int_equal(hal_uart_init(115200u, uart_rx, NULL), FW_OK);
    assert_int_equal(hal_host_uart_feed(buf, 100), 100);
    assert_int_equal(notified_, 1);
    // 100 + 220 > capacity: 156 stored, 64 lost.
    assert_int_equal(hal_host_uart_feed(&buf[100], 220), FW_CFG_HOST_UART_RX_CAPACITY - 100u);
    assert_int_equal(notified_, 2);
    // Full: nothing stored, but the firmware hears again (its last wake-up may have been lost
    // to a full event queue, and a full ring stores no byte that would notify it).
    assert_int_equal(hal_host_uart_feed(buf, 5), 0);
    assert_int_equal(notified_, 3);
    hal_host_uart_inject_error();
    hal_uart_stats_t st;
    hal_uart_get_stats(&st);
    assert_int_equal(st.rx_bytes, FW_CFG_HOST_UART_RX_CAPACITY);
    assert_int_equal(st.rx_overruns, (220u - (FW_CFG_HOST_UART_RX_CAPACITY - 100u)) + 5u);
    assert_int_equal(hal_host_uart_discarded(), 10); // overruns once on are not discards
    assert_int_equal(st.rx_errors, 1);
    // Oldest first, across the wrap.
    uint8_t r[FW_CFG_HOST_UART_RX_CAPACITY];
    assert_int_equal(hal_uart_read(r, 50), 50);
    assert_memory_equal(r, buf, 50);
    assert_int_equal(hal_host_uart_feed(buf, 30), 30);
    assert_int_equal(hal_uart_read(r, sizeof r), FW_CFG_HOST_UART_RX_CAPACITY - 50u + 30u);
    assert_memory_equal(r, &buf[50], FW_CFG_HOST_UART_RX_CAPACITY - 50u);
    assert_memory_equal(&r[FW_CFG_HOST_UART_RX_CAPACITY - 50u], buf, 30);
    assert_int_equal(hal_uart_read(r, sizeof r), 0);
    // Empty ring, receiver on, an error byte only: nothing to read, no notify.
    const uint32_t before = notified_;
    hal_host_uart_inject_error();
    assert_int_equal(notified_, before);
}

static void test_uart_write_and_take(void **state)
{
    (void)state;
    uint8_t buf[FW_CFG_HOST_UART_TX_CAPACITY + 10];
    memset(buf, 'x', sizeof buf);
    assert_int_equal(hal_uart_write(buf, 4), 0); // before init
    assert_int_equal(hal_uart_init(115200u, NULL, NULL), FW_OK);
    assert_int_equal(hal_uart_write((const uint8_t *)"CFG\r\n", 5), 5);
    assert_int_equal(hal_uart_write(buf, sizeof buf), FW_CFG_HOST_UART_TX_CAPACITY - 5u);
    uint8_t out[8];
    assert_int_equal(hal_host_uart_take_tx(out, 5), 5);
    assert_memory_equal(out, "CFG\r\n", 5);
    uint8_t rest[FW_CFG_HOST_UART_TX_CAPACITY];
    assert_int_equal(hal_host_uart_take_tx(rest, sizeof rest), FW_CFG_HOST_UART_TX_CAPACITY - 5u);
    assert_int_equal(hal_host_uart_take_tx(rest, sizeof rest), 0);
}

// Waits (bounded) until `n` bytes were read from the port.
static size_t read_n(uint8_t *buf, size_t n)
{
    size_t got = 0;
    for (int tries = 0; tries < 400 && got < n; tries++) {
        got += hal_uart_read(&buf[got], n - got);
        if (got < n) {
            (void)poll(NULL, 0, 5);
        }
    }
    return got;
}

static void test_uart_pty(void **state)
{
    (void)state;
    assert_int_equal(hal_host_uart_open_path("/nonexistent/tty"), FW_ERR_IO);
    assert_int_equal(hal_host_uart_open_path("/dev/null"), FW_ERR_IO); // not a tty
    assert_int_equal(hal_host_uart_open_path(NULL), FW_ERR_INVAL);

    int master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0) {
        skip(); // no pty support in this sandbox
    }
    assert_int_equal(grantpt(master), 0);
    assert_int_equal(unlockpt(master), 0);
    char slave[128];
    snprintf(slave, sizeof slave, "%s", ptsname(master));

    notified_ = 0;
    assert_int_equal(hal_uart_init(115200u, uart_rx, NULL), FW_OK);
    assert_int_equal(hal_host_uart_open_path(slave), FW_OK);
    assert_true(hal_host_uart_path_alive());
    const char line[] = "VR=2.0,ID=01:02:03:04:05:06:07:08,DB=14,DR=423\r\n";
    assert_int_equal(write(master, line, sizeof line - 1), (ssize_t)(sizeof line - 1));
    uint8_t r[64];
    assert_int_equal(read_n(r, sizeof line - 1), sizeof line - 1);
    assert_memory_equal(r, line, sizeof line - 1); // raw: \r\n untranslated
    assert_true(notified_ >= 1u);

    assert_int_equal(hal_uart_write((const uint8_t *)"PING\n", 5), 5);
    char back[8] = {0};
    size_t got = 0;
    for (int tries = 0; tries < 400 && got < 5; tries++) {
        struct pollfd p = {.fd = master, .events = POLLIN, .revents = 0};
        if (poll(&p, 1, 5) > 0) {
            ssize_t n = read(master, &back[got], 5 - got);
            got += n > 0 ? (size_t)n : 0u;
        }
    }
    assert_memory_equal(back, "PING\n", 5);

    // The other side goes away: the reader ends, nothing hangs.
    close(master);
    for (int tries = 0; tries < 400 && hal_host_uart_path_alive(); tries++) {
        (void)poll(NULL, 0, 5);
    }
    assert_false(hal_host_uart_path_alive());
    hal_host_uart_close_path();
}

// A pty master in raw mode (as pty_open() makes it: no echo, no line editing, bytes pass
// unchanged), its slave's path into `slave`; -1 where this sandbox has no ptys.
static int open_raw_pty(char *slave, size_t cap)
{
    const int master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0) {
        return -1;
    }
    assert_int_equal(grantpt(master), 0);
    assert_int_equal(unlockpt(master), 0);
    struct termios t;
    assert_int_equal(tcgetattr(master, &t), 0);
    t.c_iflag &= ~(tcflag_t)(IGNBRK | BRKINT | PARMRK | ISTRIP | INLCR | IGNCR | ICRNL | IXON);
    t.c_oflag &= ~(tcflag_t)OPOST;
    t.c_lflag &= ~(tcflag_t)(ECHO | ECHONL | ICANON | ISIG | IEXTEN);
    assert_int_equal(tcsetattr(master, TCSANOW, &t), 0);
    snprintf(slave, cap, "%s", ptsname(master));
    return master;
}

// The port at 115200 baud on the slave of a new raw pty, whose master it returns (-1: no ptys).
static int open_port_on_raw_pty(void)
{
    char slave[128];
    const int master = open_raw_pty(slave, sizeof slave);
    if (master >= 0) {
        assert_int_equal(hal_uart_init(115200u, uart_rx, NULL), FW_OK);
        assert_int_equal(hal_host_uart_open_path(slave), FW_OK);
    }
    return master;
}

// A listener that streams before the firmware opens its line: the tty's backlog (more than the
// ring holds) is discarded at the open, counted apart, and is no overrun; what comes after is
// received whole.
static void test_uart_pty_backlog_discarded_at_open(void **state)
{
    (void)state;
    char slave[128];
    const int master = open_raw_pty(slave, sizeof slave);
    if (master < 0) {
        skip(); // no pty support in this sandbox
    }

    static uint8_t backlog[4u * FW_CFG_HOST_UART_RX_CAPACITY];
    memset(backlog, 'b', sizeof backlog);
    assert_int_equal(write(master, backlog, sizeof backlog), (ssize_t)sizeof backlog);

    assert_int_equal(hal_uart_init(115200u, uart_rx, NULL), FW_OK);
    assert_int_equal(hal_host_uart_open_path(slave), FW_OK);
    assert_int_equal(hal_host_uart_discarded(), sizeof backlog);
    const char line[] = "VR=2.0,ID=01:02:03:04:05:06:07:08,DB=14,DR=423\r\n";
    assert_int_equal(write(master, line, sizeof line - 1), (ssize_t)(sizeof line - 1));
    uint8_t r[64];
    assert_int_equal(read_n(r, sizeof line - 1), sizeof line - 1);
    assert_memory_equal(r, line, sizeof line - 1);
    hal_uart_stats_t st;
    hal_uart_get_stats(&st);
    assert_int_equal(st.rx_bytes, sizeof line - 1);
    assert_int_equal(st.rx_overruns, 0);

    // Once open, a burst larger than the ring that nobody reads is a real overrun, and counted.
    static uint8_t burst[2u * FW_CFG_HOST_UART_RX_CAPACITY];
    memset(burst, 'x', sizeof burst);
    assert_int_equal(write(master, burst, sizeof burst), (ssize_t)sizeof burst);
    for (int tries = 0; tries < 400; tries++) {
        hal_uart_get_stats(&st);
        if (st.rx_bytes + st.rx_overruns >= sizeof line - 1 + sizeof burst) {
            break;
        }
        (void)poll(NULL, 0, 5);
    }
    assert_int_equal(st.rx_bytes, sizeof line - 1 + FW_CFG_HOST_UART_RX_CAPACITY);
    assert_int_equal(st.rx_overruns, sizeof burst - FW_CFG_HOST_UART_RX_CAPACITY);
    assert_int_equal(hal_host_uart_discarded(), sizeof backlog);
    hal_host_uart_close_path();
    close(master);
}

// A writer's burst (simulated devices catching up on a loaded host write a dozen Cricket lines
// at once) reaches the ring at the line's rate, as on a wire, not in one go: a firmware that
// drains every millisecond loses nothing of four rings' worth written at once. Fails if the
// reader hands the tty's contents over as fast as it reads them (the ring fills within
// microseconds and about three quarters of the burst are overruns).
static void test_uart_pty_burst_arrives_at_line_rate(void **state)
{
    (void)state;
    const int master = open_port_on_raw_pty();
    if (master < 0) {
        skip(); // no pty support in this sandbox
    }

    static uint8_t burst[4u * FW_CFG_HOST_UART_RX_CAPACITY];
    for (size_t i = 0; i < sizeof burst; i++) {
        burst[i] = (uint8_t)(i * 7u + 1u);
    }
    assert_int_equal(write(master, burst, sizeof burst), (ssize_t)sizeof burst);
    static uint8_t got[sizeof burst];
    size_t n = 0;
    hal_uart_stats_t st;
    for (int tries = 0; tries < 2000 && n < sizeof burst; tries++) {
        n += hal_uart_read(&got[n], sizeof burst - n);
        hal_uart_get_stats(&st);
        if (st.rx_overruns != 0u) {
            break;
        }
        (void)poll(NULL, 0, 1);
    }
    hal_uart_get_stats(&st);
    assert_int_equal(st.rx_overruns, 0);
    assert_int_equal(n, sizeof burst);
    assert_memory_equal(got, burst, sizeof burst);
    hal_host_uart_close_path();
    close(master);
}

// A stall of the whole firmware (the reader held as SIGSTOP holds it): what the tty gathered
// meanwhile is what an STM32F4 USART loses to overrun, all but the first byte (DR); counted in
// rx_overruns and hal_host_uart_stall_lost(), nothing of it reaches the ring beyond that byte,
// and the line resumes with the bytes written after the stall, whole. Fails if the backlog is
// handed to the ring (256 stale bytes received, the rest overruns, stall_lost 0).
static void test_uart_pty_stall_loses_backlog(void **state)
{
    (void)state;
    const int master = open_port_on_raw_pty();
    if (master < 0) {
        skip(); // no pty support in this sandbox
    }

    hal_host_uart_hold_reader(true);
    static uint8_t during[8u * FW_CFG_HOST_UART_RX_CAPACITY];
    for (size_t i = 0; i < sizeof during; i++) {
        during[i] = (uint8_t)('a' + i % 26u);
    }
    assert_int_equal(write(master, during, sizeof during), (ssize_t)sizeof during);
    (void)poll(NULL, 0, 120); // longer than the 50 ms the reader may be late by
    hal_host_uart_hold_reader(false);
    hal_uart_stats_t st;
    for (int tries = 0; tries < 400; tries++) {
        hal_uart_get_stats(&st);
        if (st.rx_bytes + st.rx_overruns >= sizeof during) {
            break;
        }
        (void)poll(NULL, 0, 5);
    }
    assert_int_equal(st.rx_bytes, 1);
    assert_int_equal(st.rx_overruns, sizeof during - 1u);
    assert_int_equal(hal_host_uart_stall_lost(), sizeof during - 1u);
    assert_int_equal(hal_host_uart_stalls(), 1);
    uint8_t r[64];
    assert_int_equal(hal_uart_read(r, sizeof r), 1);
    assert_int_equal(r[0], 'a'); // the first byte of the stall stays in DR

    // Running again: a line written now arrives whole, and no byte more is lost.
    const char line[] = "VR=2.0,ID=01:02:03:04:05:06:07:08,DB=14,DR=423\r\n";
    assert_int_equal(write(master, line, sizeof line - 1), (ssize_t)(sizeof line - 1));
    assert_int_equal(read_n(r, sizeof line - 1), sizeof line - 1);
    assert_memory_equal(r, line, sizeof line - 1);
    hal_uart_get_stats(&st);
    assert_int_equal(st.rx_overruns, sizeof during - 1u);
    hal_host_uart_close_path();
    close(master);
}

// ---- Clock, CPU, watchdog -----------------------------------------------------------------------

static void test_lockstep_clock_and_account(void **state)
{
    (void)state;
    assert_int_equal(hal_host_time_mode(), HAL_HOST_CLOCK_LOCKSTEP);
    assert_int_equal(hal_time_us(), 0u);
    assert_int_equal(hal_host_time_set_us(1000u), FW_OK);
    assert_int_equal(hal_host_time_set_us(999u), FW_ERR_INVAL);
    assert_int_equal(hal_host_time_advance_us(24u), FW_OK);
    assert_int_equal(hal_time_us(), 1024u);
    // 168 MHz: 168 cycles per microsecond; fractions add up exactly.
    hal_cpu_account(168u);
    assert_int_equal(hal_time_us(), 1025u);
    for (int i = 0; i < 100; i++) {
        hal_cpu_account(84u);
    }
    assert_int_equal(hal_time_us(), 1075u);
    assert_int_equal(hal_host_cpu_accounted_cycles(), 168u + 8400u);
    assert_int_equal(hal_host_cpu_set_hz(0u), FW_ERR_INVAL);
    assert_int_equal(hal_host_cpu_set_hz(1000000u), FW_OK);
    hal_cpu_account(5u);
    assert_int_equal(hal_time_us(), 1080u);

    // Waits are recorded, not slept; time moving or an interrupt ends them.
    hal_cpu_wait_until(5000u);
    assert_int_equal(hal_host_wait_deadline(), 5000u);
    assert_int_equal(hal_time_us(), 1080u);
    assert_int_equal(hal_host_time_set_us(2000u), FW_OK);
    assert_int_equal(hal_host_wait_deadline(), 2000u);
    hal_cpu_wait_until(5000u);
    hal_host_cpu_wake();
    assert_int_equal(hal_host_wait_deadline(), 2000u);
    hal_cpu_wait_until(100u); // already passed
    assert_int_equal(hal_host_wait_deadline(), 2000u);
    assert_int_equal(hal_time_init(), FW_OK);
    assert_int_equal(hal_time_us(), 0u);
}

static void *waker(void *arg)
{
    (void)arg;
    (void)poll(NULL, 0, 20);
    hal_host_cpu_wake();
    return NULL;
}

static void test_realtime_clock(void **state)
{
    (void)state;
    hal_host_time_set_mode(HAL_HOST_CLOCK_REALTIME);
    assert_int_equal(hal_host_time_set_us(5u), FW_ERR_INVAL);
    assert_int_equal(hal_host_time_advance_us(5u), FW_ERR_INVAL);
    assert_int_equal(hal_host_time_set_speed(0.0), FW_ERR_INVAL);
    assert_int_equal(hal_host_time_set_speed(1000.0), FW_OK);
    uint64_t t0 = hal_time_us();
    // 2 ms of wall time at 1000x is 2 s of firmware time, asked through the wait.
    hal_cpu_wait_until(t0 + 2000000u);
    uint64_t t1 = hal_time_us();
    assert_true(t1 >= t0 + 2000000u);
    // Accounting does not move a real clock by itself.
    hal_cpu_account(168000000u);
    assert_true(hal_time_us() >= t1);

    // A wake from another thread ends a long wait early; a wake before the wait is not lost.
    assert_int_equal(hal_host_time_set_speed(1.0), FW_OK);
    pthread_t th;
    assert_int_equal(pthread_create(&th, NULL, waker, NULL), 0);
    uint64_t a = hal_time_us();
    hal_cpu_wait_until(a + 60u * 1000000u);
    assert_int_equal(pthread_join(th, NULL), 0);
    uint64_t b = hal_time_us();
    assert_true(b - a < 30u * 1000000u);
    hal_host_cpu_wake();
    hal_cpu_wait_until(b + 60u * 1000000u);
    assert_true(hal_time_us() - b < 30u * 1000000u);
    hal_host_time_set_mode(HAL_HOST_CLOCK_LOCKSTEP);
    assert_int_equal(hal_time_us(), 0u);
}

static void test_irq_nesting(void **state)
{
    (void)state;
    hal_irq_state_t a = hal_irq_save();
    hal_irq_state_t b = hal_irq_save();
    assert_int_equal(a, 0);
    assert_int_equal(b, 1);
    hal_irq_restore(b);
    hal_irq_restore(a);
    assert_int_equal(hal_irq_save(), 0);
    hal_irq_restore(0);
}

static void test_watchdog_and_reset_cause(void **state)
{
    (void)state;
    assert_false(hal_host_watchdog_expired());
    assert_int_equal(hal_cpu_watchdog_start(0u), FW_ERR_INVAL);
    assert_int_equal(hal_cpu_watchdog_start(100u), FW_OK);
    assert_int_equal(hal_host_watchdog_timeout_ms(), 100);
    assert_int_equal(hal_host_time_advance_us(100000u), FW_OK);
    assert_false(hal_host_watchdog_expired());
    hal_cpu_watchdog_kick();
    assert_int_equal(hal_host_time_advance_us(100000u), FW_OK);
    assert_false(hal_host_watchdog_expired());
    assert_int_equal(hal_host_time_advance_us(1u), FW_OK);
    assert_true(hal_host_watchdog_expired());
    hal_cpu_watchdog_kick();
    assert_false(hal_host_watchdog_expired());
    assert_int_equal(hal_host_watchdog_kicks(), 2);

    assert_int_equal(hal_cpu_reset_cause(), HAL_RESET_POWER_ON);
    hal_host_set_reset_cause(HAL_RESET_WATCHDOG);
    assert_int_equal(hal_cpu_reset_cause(), HAL_RESET_WATCHDOG);
    hal_host_reset();
    assert_int_equal(hal_cpu_reset_cause(), HAL_RESET_POWER_ON);
    assert_int_equal(hal_host_watchdog_timeout_ms(), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_flash_geometry_and_configure, flash_setup),
        cmocka_unit_test_setup(test_flash_nor_semantics, flash_setup),
        cmocka_unit_test_setup(test_flash_alignment_and_range, flash_setup),
        cmocka_unit_test_setup(test_flash_power_cut, flash_setup),
        cmocka_unit_test_setup(test_flash_file_round_trip, flash_setup),
        cmocka_unit_test_setup(test_flash_load_file_leaves_the_file, flash_setup),
        cmocka_unit_test_setup(test_can_init_and_filters, setup),
        cmocka_unit_test_setup(test_can_stall_keeps_what_the_fifo_holds, setup),
        cmocka_unit_test_setup(test_can_send_and_take, setup),
        cmocka_unit_test_setup(test_can_transport, setup),
        cmocka_unit_test_setup(test_uart_ring_and_overruns, setup),
        cmocka_unit_test_setup(test_uart_write_and_take, setup),
        cmocka_unit_test_setup_teardown(test_uart_pty, pty_setup, pty_teardown),
        cmocka_unit_test_setup_teardown(test_uart_pty_backlog_discarded_at_open, pty_setup, pty_teardown),
        cmocka_unit_test_setup_teardown(test_uart_pty_burst_arrives_at_line_rate, pty_setup, pty_teardown),
        cmocka_unit_test_setup_teardown(test_uart_pty_stall_loses_backlog, pty_setup, pty_teardown),
        cmocka_unit_test_setup(test_lockstep_clock_and_account, setup),
        cmocka_unit_test_setup(test_realtime_clock, setup),
        cmocka_unit_test_setup(test_irq_nesting, setup),
        cmocka_unit_test_setup(test_watchdog_and_reset_cause, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
