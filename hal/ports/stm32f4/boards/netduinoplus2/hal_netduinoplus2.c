// SPDX-License-Identifier: MIT
// dynaqpc netduinoplus2 board: the hal_* contract on what QEMU's netduinoplus2 models (board.h).
//
// Interrupts and the USARTs are the STM32F4 family's drivers on the same registers
// (stm32f4_usart.c), and the Cricket listener's hal_uart is the family's (hal_stm32f4_uart.c);
// time is TIM2's counter (below: why not SysTick's interrupts, as on the robot). CAN is SLCAN
// over USART1. Two facts of QEMU 7.2's stm32f2xx-usart shape the serial code: its interrupt is
// raised for RXNE only (TXE never interrupts), and a write to DR is sent at once (TXE always
// reads 1). So received bytes come by interrupt, one per interrupt, through the driver's ring;
// transmitted bytes are written to DR directly, with interrupts masked, each after a bounded wait
// for TXE (STM32F4_CFG_UART_TX_POLLED, set by board.cmake).
#include <string.h>

#include "fw/fw_assert.h"
#include "hal/hal_can.h"
#include "hal/hal_cpu.h"
#include "hal/hal_flash.h"
#include "hal/hal_time.h"
#include "netduinoplus2/board.h"
#include "netduinoplus2/slcan.h"
#include "stm32f4/semihost.h"
#include "stm32f4/stm32f4_cpu.h"
#include "stm32f4/stm32f4_drivers.h"

#define USART1 ((stm32f4_usart_t *)STM32F4_USART1_BASE)
#define SYSTICK ((stm32f4_systick_t *)STM32F4_SYSTICK_BASE)
#define SCB_ICSR (*(volatile uint32_t *)STM32F4_SCB_ICSR)
#define SCB_SHPR3 (*(volatile uint32_t *)0xE000ED20u)

void HardFault_Handler(void);
void SysTick_Handler(void);
void USART1_IRQHandler(void);

// Writes bytes to a USART's DR; returns how many went out. Caller masks interrupts.
static size_t usart_put_(stm32f4_usart_t *u, const uint8_t *data, size_t len)
{
    return stm32f4_usart_put_polled(u, data, len, STM32F4_CFG_UART_TX_POLLS);
}

// ---- Board ------------------------------------------------------------------------------------
// The hal_flash region: SRAM the linker script reserves (netduinoplus2.ld).
extern uint8_t _dynaqpc_store_start[];
extern const uint8_t _dynaqpc_store_sectors[];
extern const uint8_t _dynaqpc_store_sector_bytes[];
#define LD_VALUE(sym) ((uint32_t)(uintptr_t)(sym))

int nd2_board_init(void)
{
    // Power-on: the region is erased (QEMU's RAM starts zeroed, flash starts erased).
    memset(_dynaqpc_store_start, 0xFF, (size_t)LD_VALUE(_dynaqpc_store_sectors) * LD_VALUE(_dynaqpc_store_sector_bytes));
    return 0;
}

// ---- Faults and the stack (the family's reset handler calls in: startup_hooks.h) -----------------
extern uint32_t _sstack, _estack;

uint32_t nd2_stack_unused_bytes(void)
{
    const volatile uint32_t *w = &_sstack;
    while (w < &_estack && *w == ND2_STACK_PAINT) {
        w++;
    }
    return (uint32_t)((uintptr_t)w - (uintptr_t)&_sstack);
}

void nd2_fault(const char *what)
{
    uint32_t ipsr;
    __asm__ volatile("mrs %0, ipsr" : "=r"(ipsr));
    semihost_puts("\nnetduinoplus2: ");
    semihost_puts(what);
    semihost_puts(" ");
    semihost_kv("exception", ipsr & 0x1FFu);
    semihost_kv("cfsr", *(volatile uint32_t *)0xE000ED28u);
    semihost_kv("hfsr", *(volatile uint32_t *)0xE000ED2Cu);
    semihost_puts("\n");
    semihost_exit(ND2_EXIT_HARD_FAULT);
}

void HardFault_Handler(void)
{
    nd2_fault("HARD FAULT");
}

// ---- Time: TIM2's counter, read; SysTick's 1 kHz interrupt only wakes the idle loop ---------------
// QEMU delivers SysTick's interrupt when the vCPU thread runs. On a loaded host that thread can
// be off the CPU for more than a millisecond; periods that expire meanwhile raise one pending
// interrupt, not several, so a clock that counts SysTick interrupts (as the STM32F4 port's does,
// where no interrupt is ever that late) loses milliseconds. Measured on the shared 2-core host at
// load ~8: the firmware's clock ran at 0.89 of the wall and of the simulated devices' time, so
// each action's two 192 ms periods lasted 12 % longer in the world (turns and steps overshot) and
// the gyro's integration, timed by the same clock, saw 11 % less rotation than there was: the
// heading drifted and the robot learned three times more slowly than the lock-step build
// (docs/results/emulated-board.md). QEMU's stm32f2xx-timer computes CNT from its virtual clock at
// each read (1 GHz input by default: with PSC = 999 it counts microseconds), so nothing is lost
// however late the vCPU runs; the 32-bit count (71 minutes) is extended to 64 bits here, read
// at least every millisecond by the SysTick handler. With -icount the virtual clock counts
// instructions, as SysTick does.
#define TIM2_BASE 0x40000000u
#define TIM2_CR1 (*(volatile uint32_t *)(TIM2_BASE + 0x00u))
#define TIM2_EGR (*(volatile uint32_t *)(TIM2_BASE + 0x14u))
#define TIM2_CNT (*(volatile uint32_t *)(TIM2_BASE + 0x24u))
#define TIM2_PSC (*(volatile uint32_t *)(TIM2_BASE + 0x28u))
#define TIM2_INPUT_HZ 1000000000u  // QEMU 7.2 stm32f2xx-timer "clock-frequency" default
#define TIM_CR1_CEN 1u
#define TIM_EGR_UG 1u

static uint32_t speed_ = 1u;         // firmware time runs this many times faster than QEMU's clock
static uint32_t tim_last_;           // the last count read
static uint64_t tim_high_;           // counts before it, in multiples of 2^32
static uint32_t ticks_per_us_ = STM32F4_SYSCLK_HZ / 1000000u;  // SysTick cycles per firmware us

int nd2_set_time_speed(uint32_t speed)
{
    if (speed == 0u || (STM32F4_SYSCLK_HZ / 1000000u) % speed != 0u) {
        return -1;
    }
    speed_ = speed;
    ticks_per_us_ = STM32F4_SYSCLK_HZ / 1000000u / speed;
    return 0;
}

int hal_time_init(void)
{
    TIM2_CR1 = 0u;
    TIM2_PSC = TIM2_INPUT_HZ / 1000000u - 1u;  // 1 MHz: QEMU microseconds
    TIM2_CNT = 0u;
    TIM2_EGR = TIM_EGR_UG;
    TIM2_CR1 = TIM_CR1_CEN;
    tim_last_ = 0u;
    tim_high_ = 0u;
    SYSTICK->CTRL = 0u;
    SYSTICK->LOAD = ticks_per_us_ * 1000u - 1u;
    SYSTICK->VAL = 0u;
    SCB_SHPR3 = (SCB_SHPR3 & 0x00FFFFFFu) | ((uint32_t)STM32F4_CFG_IRQ_PRIO_SYSTICK << 28);
    SYSTICK->CTRL = SYSTICK_CTRL_CLKSOURCE | SYSTICK_CTRL_TICKINT | SYSTICK_CTRL_ENABLE;
    return (SYSTICK->CTRL & SYSTICK_CTRL_ENABLE) ? FW_OK : FW_ERR_IO;
}

void SysTick_Handler(void)
{
    (void)hal_time_us();  // keeps the 64-bit extension of TIM2's count current
}

uint64_t hal_time_us(void)
{
    const uint32_t s = stm32f4_irq_save();
    const uint32_t cnt = TIM2_CNT;
    if (cnt < tim_last_) {
        tim_high_ += 1u;  // the 32-bit count wrapped since the last read (< 71 minutes ago)
    }
    tim_last_ = cnt;
    const uint64_t us = ((tim_high_ << 32) | cnt) * speed_;
    stm32f4_irq_restore(s);
    return us;
}

// ---- CPU: masking, the idle wait and cost accounting are the family's (hal_stm32f4_cpu.c) ---------
int hal_cpu_watchdog_start(uint32_t timeout_ms)
{
    (void)timeout_ms;
    return FW_ERR_NOSYS;  // QEMU models no IWDG
}

void hal_cpu_watchdog_kick(void)
{
}

hal_reset_cause_t hal_cpu_reset_cause(void)
{
    return HAL_RESET_POWER_ON;  // QEMU models no RCC_CSR: every start is a power-on
}

// ---- CAN: SLCAN lines on USART1 -----------------------------------------------------------------------
static uint8_t can_rx_buf_[256];
static stm32f4_usart_port_t can_uart_;
static slcan_parser_t slcan_;
static hal_can_rx_fn can_on_rx_;
static void *can_ctx_;
static hal_can_stats_t can_stats_;
static uint32_t slcan_errors_;
static uint32_t accept_[32];
static uint32_t n_accept_;

static bool accepted_(const hal_can_frame_t *f)
{
    if (n_accept_ == 0u) {
        return true;
    }
    if (f->flags & HAL_CAN_FLAG_EXTENDED) {
        return false;  // the list is of standard ids (as the bxCAN filters are set up)
    }
    for (uint32_t i = 0; i < n_accept_; i++) {
        if (accept_[i] == f->id) {
            return true;
        }
    }
    return false;
}

// USART1's receive notification, in its interrupt: the bytes become frames (the "controller"'s
// work), each accepted frame goes to the handler, a command is answered.
static void can_uart_rx_(void *ctx)
{
    (void)ctx;
    uint8_t b;
    while (stm32f4_ring_get(&can_uart_.rx, &b)) {
        hal_can_frame_t f;
        const slcan_result_t r = slcan_feed(&slcan_, b, &f);
        if (r == SLCAN_FRAME) {
            if (accepted_(&f) && can_on_rx_ != NULL) {
                can_stats_.rx_frames++;
                can_on_rx_(&f, can_ctx_);
            }
        } else if (r == SLCAN_COMMAND || r == SLCAN_ERROR) {
            const uint8_t answer = r == SLCAN_COMMAND ? (uint8_t)SLCAN_OK : (uint8_t)SLCAN_ERR;
            slcan_errors_ += r == SLCAN_ERROR ? 1u : 0u;
            (void)usart_put_(USART1, &answer, 1u);
        }
    }
}

int hal_can_init(uint32_t bitrate, const uint32_t *accept_ids, uint32_t n_ids, hal_can_rx_fn on_rx,
                 void *ctx)
{
    if (bitrate == 0u || n_ids > sizeof accept_ / sizeof accept_[0] || (n_ids > 0u && accept_ids == NULL)) {
        return FW_ERR_INVAL;
    }
    for (uint32_t i = 0; i < n_ids; i++) {
        accept_[i] = accept_ids[i];
    }
    n_accept_ = n_ids;
    can_on_rx_ = on_rx;
    can_ctx_ = ctx;
    memset(&can_stats_, 0, sizeof can_stats_);
    slcan_parser_init(&slcan_);
    can_uart_.regs = USART1;
    stm32f4_ring_init(&can_uart_.rx, can_rx_buf_, sizeof can_rx_buf_);
    stm32f4_ring_init(&can_uart_.tx, NULL, 0u);  // transmit goes straight to DR
    can_uart_.on_rx = can_uart_rx_;
    can_uart_.ctx = NULL;
    const int rc = stm32f4_usart_setup(&can_uart_, STM32F4_APB2_HZ, 115200u);
    if (rc == FW_OK) {
        stm32f4_nvic_enable(STM32F4_IRQ_USART1, STM32F4_CFG_IRQ_PRIO_CAN);
    }
    return rc;
}

int hal_can_send(const hal_can_frame_t *frame)
{
    FW_ASSERT(frame != NULL);
    uint8_t line[SLCAN_MAX_LINE];
    const size_t n = slcan_encode(frame, line);
    if (n == 0u) {
        return FW_ERR_INVAL;
    }
    const uint32_t s = stm32f4_irq_save();  // one line at a time on the wire
    const size_t sent = usart_put_(USART1, line, n);
    if (sent == n) {
        can_stats_.tx_frames++;
    } else {
        can_stats_.tx_dropped++;
    }
    stm32f4_irq_restore(s);
    return sent == n ? FW_OK : FW_ERR_FULL;
}

void hal_can_get_stats(hal_can_stats_t *out)
{
    FW_ASSERT(out != NULL);
    const uint32_t s = stm32f4_irq_save();
    *out = can_stats_;
    out->rx_overruns = can_uart_.stats.rx_overruns;
    out->bus_errors = can_uart_.stats.rx_errors;
    stm32f4_irq_restore(s);
}

uint32_t nd2_slcan_errors(void)
{
    return slcan_errors_;
}

void USART1_IRQHandler(void)
{
    (void)stm32f4_usart_irq(&can_uart_);
}

// ---- Flash: the region in SRAM, NOR semantics --------------------------------------------------------
static uint32_t region_bytes_(void)
{
    return LD_VALUE(_dynaqpc_store_sectors) * LD_VALUE(_dynaqpc_store_sector_bytes);
}

int hal_flash_get_geometry(hal_flash_geometry_t *out)
{
    FW_ASSERT(out != NULL);
    out->sector_size = LD_VALUE(_dynaqpc_store_sector_bytes);
    out->sector_count = LD_VALUE(_dynaqpc_store_sectors);
    out->write_align = 4u;
    return FW_OK;
}

static bool in_region_(uint32_t offset, size_t len)
{
    return offset <= region_bytes_() && len <= region_bytes_() - offset;
}

int hal_flash_read(uint32_t offset, void *buf, size_t len)
{
    FW_ASSERT(buf != NULL || len == 0u);
    if (!in_region_(offset, len)) {
        return FW_ERR_INVAL;
    }
    memcpy(buf, &_dynaqpc_store_start[offset], len);
    return FW_OK;
}

const void *hal_flash_map(uint32_t offset, size_t len)
{
    return in_region_(offset, len) ? &_dynaqpc_store_start[offset] : NULL;
}

int hal_flash_erase(uint32_t sector)
{
    if (sector >= LD_VALUE(_dynaqpc_store_sectors)) {
        return FW_ERR_INVAL;
    }
    const uint32_t size = LD_VALUE(_dynaqpc_store_sector_bytes);
    memset(&_dynaqpc_store_start[sector * size], 0xFF, size);
    return FW_OK;
}

int hal_flash_write(uint32_t offset, const void *data, size_t len)
{
    FW_ASSERT(data != NULL || len == 0u);
    if (!in_region_(offset, len) || offset % 4u != 0u || len % 4u != 0u) {
        return FW_ERR_INVAL;
    }
    const uint8_t *src = (const uint8_t *)data;
    uint8_t *dst = &_dynaqpc_store_start[offset];
    for (size_t i = 0; i < len; i++) {
        dst[i] &= src[i];  // programming only clears bits
        if (dst[i] != src[i]) {
            return FW_ERR_IO;  // verify: the bytes were not erased
        }
    }
    return FW_OK;
}
