// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 port: register-level drivers, each working on a register block it is given.
//
// The port's hal_* functions (hal_stm32f4.c) pass the real peripheral addresses; the host unit
// tests (tests/unit/stm32f4_*) pass fake register blocks in RAM. Nothing here touches a fixed
// address, an interrupt or a CPU instruction, so this code builds for the host as it is.
//
// Every wait on a hardware flag is bounded: stm32f4_wait_bits() polls a register at most
// `max_polls` times and the callers return FW_ERR_TIMEOUT (or FW_ERR_IO) when the flag never
// comes. No function here blocks forever.
#ifndef STM32F4_DRIVERS_H
#define STM32F4_DRIVERS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "hal/hal_can.h"
#include "hal/hal_cpu.h"
#include "hal/hal_flash.h"
#include "hal/hal_uart.h"
#include "stm32f4/stm32f4_config.h"
#include "stm32f4/stm32f4_regs.h"

#ifdef __cplusplus
extern "C" {
#endif

// ---- Bounded waiting --------------------------------------------------------------------------

/// Called once per poll by stm32f4_wait_bits() when not NULL. NULL on the MCU; a host test sets it
/// to make its fake register block respond over time (a flag that comes after a few polls).
extern void (*stm32f4_poll_hook)(void);

/// Polls until (*reg & mask) == want, at most max_polls times. Returns FW_OK or FW_ERR_TIMEOUT.
int stm32f4_wait_bits(const volatile uint32_t *reg, uint32_t mask, uint32_t want,
                      uint32_t max_polls);

// ---- Clocks and reset cause (stm32f4_rcc.c) ----------------------------------------------------

/// HSE 8 MHz -> PLL (M 8, N 336, P 2, Q 7) -> SYSCLK 168 MHz, AHB 168, APB1 42, APB2 84 MHz, with
/// 5 flash wait states, prefetch and caches on (RM0090 table 10: 2.7-3.6 V). Returns FW_OK or
/// FW_ERR_TIMEOUT (HSE or PLL not ready, or the switch not taken: the CPU stays on HSI 16 MHz).
int stm32f4_clock_init(stm32f4_rcc_t *rcc, stm32f4_flash_if_t *flash, volatile uint32_t *pwr_cr);

/// The reset cause encoded in RCC_CSR's flags (a watchdog wins over the pin flag it also sets).
hal_reset_cause_t stm32f4_reset_cause_from_csr(uint32_t csr);

// ---- Independent watchdog (stm32f4_iwdg.c) --------------------------------------------------------

/// Prescaler code (0: /4 ... 6: /256) and reload value (1..4095) for a timeout at the nominal
/// LSI frequency. Returns FW_OK or FW_ERR_INVAL (0 ms, or longer than 32.768 s).
int stm32f4_iwdg_divider(uint32_t timeout_ms, uint32_t *pr, uint32_t *rlr);

/// Unlocks PR/RLR, writes them, waits for the update flags, starts the watchdog.
/// Returns FW_OK, FW_ERR_INVAL or FW_ERR_TIMEOUT.
int stm32f4_iwdg_start(stm32f4_iwdg_t *iwdg, uint32_t timeout_ms);

/// Reloads the counter.
void stm32f4_iwdg_kick(stm32f4_iwdg_t *iwdg);

// ---- SysTick time (stm32f4_time.c) ----------------------------------------------------------------

/// Microseconds since boot from the millisecond count, the SysTick reload value and current
/// value (counting down from load to 0 each millisecond), at `ticks_per_us` core clocks per µs.
uint64_t stm32f4_time_us(uint64_t ms, uint32_t load, uint32_t val, uint32_t ticks_per_us);

// ---- bxCAN (stm32f4_bxcan.c) -------------------------------------------------------------------------

/// A bit timing: prescaler, time segments 1 and 2 and the resync jump width, in time quanta.
typedef struct stm32f4_can_timing {
    uint32_t brp;  ///< 1..1024
    uint32_t bs1;  ///< 1..16
    uint32_t bs2;  ///< 1..8
    uint32_t sjw;  ///< 1..4
} stm32f4_can_timing_t;

/// The timing for `bitrate` from the APB1 clock: 8..25 quanta per bit, the sample point nearest
/// 87.5 % (CiA 301), exact bit rate only. Returns FW_OK or FW_ERR_INVAL (no exact divider).
int stm32f4_can_timing(uint32_t pclk_hz, uint32_t bitrate, stm32f4_can_timing_t *out);

/// The BTR register value of a timing.
uint32_t stm32f4_can_btr(const stm32f4_can_timing_t *t);

/// Standard ids that fit CAN1's filter banks in 16-bit identifier-list mode (4 ids a bank).
#define STM32F4_CAN_MAX_IDS (4u * STM32F4_CFG_CAN1_FILTER_BANKS)

/// Resets the controller into initialisation mode, sets the bit timing, the filters (the ids
/// listed, or accept-all for an empty list, all into FIFO 0), automatic bus-off recovery,
/// transmit order by request, the interrupts (FIFO 0 message pending and overrun, error
/// warning/passive/bus-off), and leaves initialisation mode. Returns FW_OK, FW_ERR_INVAL, or
/// FW_ERR_IO (the controller did not enter or leave initialisation mode).
int stm32f4_can_setup(stm32f4_can_t *can, uint32_t pclk_hz, uint32_t bitrate,
                      const uint32_t *accept_ids, uint32_t n_ids);

/// Writes the frame into a free TX mailbox and requests transmission. Returns the mailbox
/// number (0..2), FW_ERR_INVAL (bad id, dlc or flags), or FW_ERR_FULL (all three busy).
int stm32f4_can_write(stm32f4_can_t *can, const hal_can_frame_t *frame);

/// Takes the oldest frame of FIFO 0 and releases its slot. Returns true if there was one; false
/// when the FIFO is empty or the previous release is still in progress (RFOM0 still set: the
/// output mailbox would show the frame already taken). Sets *overrun when the FIFO overflowed
/// since the last call, and clears the flag.
bool stm32f4_can_read(stm32f4_can_t *can, hal_can_frame_t *frame, bool *overrun);

/// A CAN controller with the receive handler and the counters of hal_can.h.
typedef struct stm32f4_can_port {
    stm32f4_can_t *regs;
    hal_can_rx_fn on_rx;  ///< called per frame in interrupt context; may be NULL
    void *ctx;
    hal_can_stats_t stats;
} stm32f4_can_port_t;

/// The FIFO 0 interrupt's work (message pending, FIFO overrun): reads out every frame waiting
/// (at most 3), hands each to on_rx and releases its slot, counts frames and overruns. Stops
/// early if a release does not complete within STM32F4_CFG_CAN_RELEASE_POLLS polls (the
/// interrupt stays pending while FMP0 is not 0, so the rest comes on the next entry).
void stm32f4_can_rx_irq(stm32f4_can_port_t *p);

/// The status-change/error interrupt's work: counts a bus error when the error warning, error
/// passive or bus-off flag is set, and clears MSR.ERRI.
void stm32f4_can_sce_irq(stm32f4_can_port_t *p);

/// hal_can_send's work: stm32f4_can_write, counting tx_frames or tx_dropped (FW_ERR_FULL).
/// Returns FW_OK, FW_ERR_INVAL or FW_ERR_FULL. The caller masks interrupts (thread and
/// interrupt senders share the mailboxes and the counters).
int stm32f4_can_send(stm32f4_can_port_t *p, const hal_can_frame_t *frame);

// ---- USART (stm32f4_usart.c) ----------------------------------------------------------------------

/// A single-producer single-consumer byte ring (one side in an interrupt, one in thread code).
typedef struct stm32f4_ring {
    volatile uint8_t *buf;  ///< volatile: the byte is stored before the index that publishes it
    uint32_t size;  ///< a power of two
    volatile uint32_t head;  ///< written by the producer only
    volatile uint32_t tail;  ///< written by the consumer only
} stm32f4_ring_t;

void stm32f4_ring_init(stm32f4_ring_t *r, uint8_t *buf, uint32_t size);
bool stm32f4_ring_put(stm32f4_ring_t *r, uint8_t byte);
bool stm32f4_ring_get(stm32f4_ring_t *r, uint8_t *byte);
uint32_t stm32f4_ring_count(const stm32f4_ring_t *r);

/// BRR for `baud` at `pclk_hz` with 16x oversampling, rounded to nearest. Returns FW_OK or
/// FW_ERR_INVAL when the achieved rate is more than 2 % off (or out of the register's range).
int stm32f4_usart_brr(uint32_t pclk_hz, uint32_t baud, uint32_t *brr);

/// A USART with its receive and transmit rings, counters and receive notification.
typedef struct stm32f4_usart_port {
    stm32f4_usart_t *regs;
    stm32f4_ring_t rx;
    stm32f4_ring_t tx;
    hal_uart_stats_t stats;
    hal_uart_rx_fn on_rx;  ///< called (interrupt context) after each byte received while the
                           ///< ring holds unread bytes (hal_uart_rx_fn); may be NULL
    void *ctx;
} stm32f4_usart_port_t;

/// 8N1 at `baud`, receiver and its interrupt on, transmitter on. Returns FW_OK or FW_ERR_INVAL.
int stm32f4_usart_setup(stm32f4_usart_port_t *p, uint32_t pclk_hz, uint32_t baud);

/// The interrupt handler's work: takes a received byte into the rx ring (counting overruns and
/// framing/noise errors; an errored byte is dropped, a byte that finds the ring full is counted
/// as an overrun) and calls on_rx after each received byte while the ring is not empty (a full
/// ring too: see hal_uart_rx_fn); feeds the transmitter from the tx ring and
/// turns the TXE interrupt off when it is empty. Returns true when a byte was stored.
bool stm32f4_usart_irq(stm32f4_usart_port_t *p);

/// Copies up to `cap` received bytes out of the rx ring, oldest first. Returns how many.
/// Thread context (the one consumer); no masking needed.
size_t stm32f4_usart_read(stm32f4_usart_port_t *p, uint8_t *buf, size_t cap);

/// Queues bytes for transmission and enables the TXE interrupt. Returns how many were queued
/// (0 before stm32f4_usart_setup). The caller masks interrupts (CR1 is shared with the handler).
size_t stm32f4_usart_queue(stm32f4_usart_port_t *p, const uint8_t *data, size_t len);

/// Writes bytes straight to DR, each after at most `polls` reads of SR for TXE, without the
/// interrupt or the tx ring (a USART whose TXE never interrupts: QEMU's, boards/netduinoplus2).
/// Returns how many went out: fewer when TXE stayed clear. The caller masks interrupts.
size_t stm32f4_usart_put_polled(stm32f4_usart_t *u, const uint8_t *data, size_t len, uint32_t polls);

// ---- Internal flash (stm32f4_flash.c) ----------------------------------------------------------------

/// Sectors of the largest STM32F4 map (RM0090 3.3, table 6: 2 MB in two banks). Sectors 0-11 are
/// bank 1, the whole 1 MB of an F405/407 (table 5); sectors 12-23 are bank 2 of a 2 MB
/// F42x/43x. Each bank: 4 x 16 KB, 1 x 64 KB, 7 x 128 KB.
#define STM32F4_FLASH_SECTORS_MAX 24u

/// Start address and size of RM0090 sector `sector`. Returns FW_OK or FW_ERR_INVAL (>= 24).
int stm32f4_flash_sector(uint32_t sector, uint32_t *addr, uint32_t *size);

/// The FLASH_CR.SNB code of a sector: 0-11 as they are, bank 2's 12-23 as 16-27.
uint32_t stm32f4_flash_snb(uint32_t sector);

/// The flash region: the flash interface's registers, the region's memory (sector `first_sector`
/// at `mem`), its sectors, and what to call while waiting for a long erase (the watchdog kick).
/// A region of 0 sectors is "no region": geometry says FW_ERR_NOSYS, the rest FW_ERR_INVAL.
typedef struct stm32f4_flash_dev {
    stm32f4_flash_if_t *regs;
    volatile uint8_t *mem;
    uint32_t first_sector;   ///< RM0090 sector number of the region's first sector
    uint32_t sector_count;
    uint32_t sector_size;
    void (*on_wait)(void);   ///< called every STM32F4_FLASH_WAIT_SLICE polls, may be NULL
} stm32f4_flash_dev_t;

#define STM32F4_FLASH_WAIT_SLICE 4096u

/// Checks a region against the sector map and the part: `count` (>= 2) sectors from
/// `first_sector`, each `sector_size` bytes, the first at `addr`, all inside the part's
/// `flash_kb` (the F_SIZE register). Returns FW_OK, or FW_ERR_NOSYS (the part has no such
/// region: e.g. an image for a 2 MB F427 on a 1 MB part, or for a 1 MB F405 on a 512 KB F407xE).
int stm32f4_flash_region_check(uint32_t addr, uint32_t first_sector, uint32_t count,
                               uint32_t sector_size, uint32_t flash_kb);

/// hal_flash_get_geometry of the region (write_align 4). FW_OK or FW_ERR_NOSYS (no region).
int stm32f4_flash_geometry(const stm32f4_flash_dev_t *d, hal_flash_geometry_t *out);

/// Copies `len` bytes at `offset` of the region. FW_OK or FW_ERR_INVAL (out of the region).
int stm32f4_flash_read(const stm32f4_flash_dev_t *d, uint32_t offset, void *buf, size_t len);

/// hal_flash_map of the region: its memory at `offset`, or NULL (out of range, no region).
const void *stm32f4_flash_map(const stm32f4_flash_dev_t *d, uint32_t offset, size_t len);

/// Erases one sector of the region (0-based). Returns FW_OK, FW_ERR_INVAL, FW_ERR_TIMEOUT or
/// FW_ERR_IO (an error flag, or the sector did not read back 0xFF).
int stm32f4_flash_erase(const stm32f4_flash_dev_t *d, uint32_t sector);

/// Programs 32-bit words (offset and len multiples of 4) and verifies them. Returns FW_OK,
/// FW_ERR_INVAL, FW_ERR_TIMEOUT or FW_ERR_IO.
int stm32f4_flash_program(const stm32f4_flash_dev_t *d, uint32_t offset, const void *data,
                          size_t len);

#ifdef __cplusplus
}
#endif

#endif // STM32F4_DRIVERS_H
