// SPDX-License-Identifier: MIT
// dynaqpc host port: what the simulator, the tests and the firmware's standalone host build use
// to drive the HAL on a PC. The firmware itself sees only hal/include/hal/*.h.
//
// Two clock modes:
//  - lock-step (the default): time is virtual and belongs to the simulator. hal_time_us()
//    returns what hal_host_time_set_us()/hal_host_time_advance_us() set, plus the CPU time the
//    firmware declared with hal_cpu_account(). hal_cpu_wait_until() returns at once and records
//    the wake-up it asked for (hal_host_wait_deadline()). CAN frames and UART bytes move through
//    in-process queues the simulator fills and drains. Deterministic: nothing depends on the OS.
//  - real-time: hal_time_us() is CLOCK_MONOTONIC since hal_time_init(), times a speed factor;
//    hal_cpu_wait_until() sleeps on a condition variable until the deadline or until
//    hal_host_cpu_wake(). Receiver threads (the virtual CAN bus, the pty reader) are the
//    "interrupts": they deliver through hal_host_can_deliver()/hal_host_uart_feed().
//
// Interrupt masking: hal_irq_save() locks one process-wide RECURSIVE mutex and hal_irq_restore()
// unlocks it (the returned state is the nesting depth, for checking only). Each save must be
// matched by a restore on the same thread. hal_host_can_deliver() and hal_host_uart_feed() call
// the firmware's rx handler with that mutex held, as an interrupt handler runs while the main
// loop is stopped: so the main loop's critical sections and the "ISRs" exclude each other, and
// an ISR may nest hal_irq_save() (sched_post() does).
//
// Typical lock-step loop of a simulator (one firmware, one thread):
//
//     hal_host_reset();                       // everything volatile back to power-on
//     hal_time_init();  firmware_boot();      // boot registers tasks, hal_can_init(), ...
//     while (running) {
//         sched_step(&s);                     // firmware: events, due tasks, idle work
//         while (hal_host_can_take_tx(&f)) bus_to_devices(&f);
//         n = hal_host_uart_take_tx(buf, sizeof buf);
//         uint64_t wake = hal_host_wait_deadline();   // now, if it did not ask to sleep
//         uint64_t t = min(wake, next_world_event_us);
//         if (t > hal_time_us()) { world_advance_to(t); hal_host_time_set_us(t); }
//         deliver due device frames: hal_host_can_deliver(&f); hal_host_uart_feed(bytes, n);
//     }
#ifndef HAL_HOST_HAL_HOST_H
#define HAL_HOST_HAL_HOST_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "hal/hal_can.h"
#include "hal/hal_cpu.h"
#include "hal_host/hal_host_config.h"

#ifdef __cplusplus
extern "C" {
#endif

// ---- Whole port ---------------------------------------------------------------------------------

/// Returns every volatile part of the port to its power-on state, as a reboot would: lock-step
/// mode at time 0 with the default CPU clock, CAN and UART uninitialised with empty queues and
/// zero counters, no transport, UART path closed, watchdog stopped, reset cause POWER_ON.
/// Flash contents and geometry are kept (it is non-volatile); the power-cut injector is cleared.
/// Context: the simulator's thread, with no receiver thread running.
void hal_host_reset(void);

// ---- Time ---------------------------------------------------------------------------------------

typedef enum hal_host_clock_mode {
    HAL_HOST_CLOCK_LOCKSTEP = 0, ///< virtual time, owned by the simulator (the default)
    HAL_HOST_CLOCK_REALTIME = 1, ///< CLOCK_MONOTONIC x speed
} hal_host_clock_mode_t;

/// Picks the clock mode and restarts the clock at 0 (as hal_time_init() does in either mode).
void hal_host_time_set_mode(hal_host_clock_mode_t mode);
hal_host_clock_mode_t hal_host_time_mode(void);

/// Lock-step: sets virtual time. Returns FW_OK, or FW_ERR_INVAL if `t_us` is earlier than now
/// (time never goes backwards) or the clock is in real-time mode. Ends a recorded wait.
int hal_host_time_set_us(uint64_t t_us);

/// Lock-step: advances virtual time by `dt_us`. Returns FW_OK or FW_ERR_INVAL (real-time mode).
/// May be called from a task body to model a task that takes time. Ends a recorded wait.
int hal_host_time_advance_us(uint64_t dt_us);

/// Real-time: firmware time runs `speed` times faster than CLOCK_MONOTONIC (1.0 = real time).
/// Changing it keeps hal_time_us() continuous. Returns FW_OK or FW_ERR_INVAL (speed not in
/// (0, 1e6]). Allowed in lock-step mode too (kept for the next real-time start).
int hal_host_time_set_speed(double speed);

// ---- CPU ----------------------------------------------------------------------------------------

/// Lock-step: the wake-up the firmware asked for in its last hal_cpu_wait_until(), or the
/// current time if it has not asked to wait since time last moved or an "interrupt" (a CAN
/// delivery, UART bytes) happened. A result <= hal_time_us() means: run sched_step() again now.
uint64_t hal_host_wait_deadline(void);

/// Whether the last hal_cpu_wait_until() was called with interrupts masked, as the sleep handoff
/// of hal_cpu.h asks (for the scheduler's tests). Context: the thread that waited.
bool hal_host_last_wait_masked(void);

/// Lock-step: the modelled CPU clock hal_cpu_account() divides by (default FW_CFG_HOST_CPU_HZ).
/// Returns FW_OK or FW_ERR_INVAL (0).
int hal_host_cpu_set_hz(uint32_t hz);

/// Total cycles declared with hal_cpu_account() since hal_host_reset().
uint64_t hal_host_cpu_accounted_cycles(void);

/// Real-time: wakes a hal_cpu_wait_until() in progress, or makes the next one return at once.
/// Called by receiver threads after delivering; hal_host_can_deliver()/hal_host_uart_feed()
/// already call it. Context: any thread.
void hal_host_cpu_wake(void);

/// Watchdog: true if it was started and not kicked for longer than its timeout (by the mode's
/// clock). The host does not reset anything; the simulator decides what an expiry means.
bool hal_host_watchdog_expired(void);
/// hal_cpu_watchdog_kick() calls since the watchdog was started; timeout in ms (0: not started).
uint32_t hal_host_watchdog_kicks(void);
uint32_t hal_host_watchdog_timeout_ms(void);

/// What hal_cpu_reset_cause() reports. hal_host_reset() sets POWER_ON: set the cause after it to
/// model, say, a reboot by the watchdog.
void hal_host_set_reset_cause(hal_reset_cause_t cause);

// ---- CAN ----------------------------------------------------------------------------------------

/// Another way to put frames on a bus (the virtual CAN bus over UDP, in real-time mode).
typedef struct hal_host_can_transport {
    /// Sends one valid frame. Returns FW_OK, or FW_ERR_FULL / FW_ERR_IO (counted in tx_dropped).
    /// Called from hal_can_send(): thread or interrupt context; must not block for long.
    int (*send)(const hal_can_frame_t *frame, void *ctx);
    void *ctx;
} hal_host_can_transport_t;

/// Routes hal_can_send() to `transport` (kept by pointer: static storage), or back to the
/// lock-step TX queue with NULL. Frames the transport receives must be handed to
/// hal_host_can_deliver(). Context: thread, before the firmware sends.
void hal_host_can_set_transport(const hal_host_can_transport_t *transport);

/// Lock-step: takes the oldest frame the firmware sent. Returns false if none. Any thread.
bool hal_host_can_take_tx(hal_can_frame_t *out);

/// A frame arrives from the bus: it is validated (id within 11 or 29 bits, dlc <= 8, known
/// flags; else FW_ERR_INVAL and counted in bus_errors), filtered (an extended frame, or a
/// standard id not in the list, when the list is non-empty: FW_ERR_NOENT, not counted, as the
/// hardware filter never shows it), then handed to the rx handler as an interrupt would (with
/// the irq mutex held) and counted in rx_frames; then the CPU is woken. Returns FW_OK, those
/// codes, or FW_ERR_IO before hal_can_init(). Context: any thread (a receiver thread is an ISR).
int hal_host_can_deliver(const hal_can_frame_t *frame);

/// A stall of the whole firmware (its process stopped, or not scheduled: a debugger halt or a
/// flash erase on the MCU) stops the receive interrupt too. bxCAN's receive FIFO 0 has three
/// mailboxes and the STM32F4 port leaves it unlocked (MCR.RFLM = 0): once full, each arriving
/// frame overwrites the newest one there and sets FOVR0 (RM0090, "Receive FIFO"). A socket
/// instead keeps every frame of the stall. A receiver that finds it was away (the firmware's
/// receive thread) hands that backlog over between these calls, each frame to
/// hal_host_can_deliver_stalled(): the first two frames the filters accept are delivered at
/// once, each later one replaces the newest, and hal_host_can_stall_end() delivers that one.
/// Every replaced frame is counted in rx_overruns and in hal_host_can_stall_lost(). Filtered and
/// invalid frames are treated as hal_host_can_deliver() treats them; outside a stall,
/// hal_host_can_deliver_stalled() is hal_host_can_deliver().
void hal_host_can_stall_begin(void);
int hal_host_can_deliver_stalled(const hal_can_frame_t *frame);
void hal_host_can_stall_end(void);
/// Frames lost to stalls since the last reset (also in rx_overruns).
uint32_t hal_host_can_stall_lost(void);

/// A transport that lost received frames (its socket buffer overflowed) reports them here:
/// they are counted in rx_overruns.
void hal_host_can_count_rx_overrun(uint32_t frames);

/// The bitrate hal_can_init() was given (0 before).
uint32_t hal_host_can_bitrate(void);

// ---- UART ---------------------------------------------------------------------------------------

/// Bytes arrive on the line: as many as fit go into the receive ring (rx_bytes), the rest are
/// lost and counted (rx_overruns); then, if the ring holds unread bytes (stored now or before:
/// a full ring too), the rx notify runs as an interrupt (irq mutex held) and the CPU is woken.
/// Returns the number stored. Before hal_uart_init() the receiver is off: nothing is stored,
/// and the bytes are counted in hal_host_uart_discarded(), not as overruns. Context: any thread.
size_t hal_host_uart_feed(const uint8_t *data, size_t len);

/// A framing or noise error on the line: the byte is dropped and counted in rx_errors.
void hal_host_uart_inject_error(void);

/// Lock-step: takes up to `cap` bytes the firmware wrote, oldest first. Returns how many.
size_t hal_host_uart_take_tx(uint8_t *buf, size_t cap);

/// Device-path mode: opens a tty (a pty slave, a USB serial adapter), sets it raw 8N1 at the
/// baud of hal_uart_init() (115200 if called before), non-blocking, and starts a reader thread
/// that feeds received bytes through hal_host_uart_feed(). hal_uart_write() then writes to the
/// device. Returns FW_OK, FW_ERR_IO (cannot open, not a tty, thread not started) or
/// FW_ERR_INVAL (NULL, baud not a standard termios speed). What the tty held from before the
/// open (a pty keeps what its writer sent while nobody listened) is discarded and counted in
/// hal_host_uart_discarded(): a UART hears only what arrives after it is switched on.
/// Context: thread, at boot.
int hal_host_uart_open_path(const char *path);

/// Stops the reader thread and closes the device (no-op if none). Context: thread.
void hal_host_uart_close_path(void);

/// True while a device path is open and its reader has not seen end-of-file or an error (a pty
/// whose other side closed).
bool hal_host_uart_path_alive(void);

/// Bytes the receiver never heard because it was off, not because it was slow: fed before
/// hal_uart_init(), or read and discarded by hal_host_uart_open_path() as the tty's backlog
/// (bytes the kernel still queued beyond its line buffer are flushed uncounted). Not in
/// hal_uart_stats_t's rx_overruns. Reset by hal_host_reset(). Context: any thread.
uint32_t hal_host_uart_discarded(void);

/// Device-path mode: bytes lost while the firmware was stalled (SIGSTOP, not scheduled): when
/// the reader thread finds it was away from the line for more than 50 ms, the tty's backlog is
/// what arrived while no receive interrupt could run. As on an STM32F4 USART (no FIFO, no flow
/// control), the first of those bytes is received and the others are overruns: they are counted
/// in hal_uart_stats_t's rx_overruns and here. rx_overruns minus this is what a running firmware
/// lost to a full ring. Reset by hal_host_reset(). Context: any thread.
uint32_t hal_host_uart_stall_lost(void);

/// How many stalls hal_host_uart_stall_lost() met with bytes waiting. Context: any thread.
uint32_t hal_host_uart_stalls(void);

/// For tests: while held, the reader thread does not service the line, as if the process were
/// stopped (returns once the reader is off the line); released, it finds the stall as after
/// SIGCONT. Context: any thread.
void hal_host_uart_hold_reader(bool hold);

// ---- Flash --------------------------------------------------------------------------------------

/// Sets the geometry and erases the whole region to 0xFF; detaches any file. Requirements:
/// sector_count >= 2, sector_size > 0 and a multiple of write_align, write_align a power of two,
/// sector_size * sector_count <= FW_CFG_HOST_FLASH_CAPACITY. Returns FW_OK or FW_ERR_INVAL.
int hal_host_flash_configure(uint32_t sector_size, uint32_t sector_count, uint32_t write_align);

/// Backs the region with a file: if it exists, its contents are loaded (it must be exactly the
/// region's size, else FW_ERR_CORRUPT and neither the file nor the image changes); if not, it
/// is created from the current image. From then on every erase and write goes through to the
/// file. Returns FW_OK, FW_ERR_CORRUPT, FW_ERR_IO or FW_ERR_INVAL (NULL).
int hal_host_flash_attach_file(const char *path);

/// Loads a file into the region without backing it: erases and writes change the image in RAM
/// only, so the file stays as it was (a replay that keeps learning from a saved image). The file
/// must exist and be exactly the region's size, else FW_ERR_IO / FW_ERR_CORRUPT and the image does
/// not change. Detaches any backing file. Returns FW_OK, FW_ERR_CORRUPT, FW_ERR_IO or FW_ERR_INVAL.
int hal_host_flash_load_file(const char *path);

/// Closes the backing file (its contents stay). No-op if none.
void hal_host_flash_detach_file(void);

/// Power-cut injector: after `bytes` more programmed bytes (hal_flash_write counts each byte of
/// its range, in address order), the power is off. The write that crosses the limit programs
/// exactly the bytes before the cut and returns FW_ERR_IO; from then on every write and erase
/// returns FW_ERR_IO without effect until hal_host_flash_restore_power(). Reads still work.
/// `bytes` = 0 cuts before the next programmed byte. Erases count no bytes.
void hal_host_flash_cut_power_after(uint32_t bytes);
void hal_host_flash_restore_power(void);

/// Power-cut injector inside an erase: the erase after `erases` more complete ones stops once the
/// first `bytes` bytes of its sector are erased (0xFF); the rest keep what they held, as a NOR
/// erase cut short leaves a sector partly erased. It returns FW_ERR_IO and the power is off, as
/// above, until hal_host_flash_restore_power(). `bytes` >= the sector size completes the erase
/// and then cuts. Writes before that erase program as usual.
void hal_host_flash_cut_power_in_erase(uint32_t erases, uint32_t bytes);

/// Bytes programmed and sectors erased since hal_host_reset() (wear and timing statistics).
uint64_t hal_host_flash_programmed_bytes(void);
uint32_t hal_host_flash_erase_count(void);

#ifdef __cplusplus
}
#endif

#endif // HAL_HOST_HAL_HOST_H
