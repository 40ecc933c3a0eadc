// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 port: the hal_* contract on the real peripherals, and their interrupt handlers.
//
// The register-level work is in the drivers (stm32f4_*.c, tested on the host with fake
// registers); this file passes them the real addresses, owns the static state (rings, counters,
// handlers) and the Cortex-M specifics (PRIMASK, WFI, NVIC, SysTick).
#include <string.h>

#include "hal/hal_can.h"
#include "hal/hal_cpu.h"
#include "hal/hal_flash.h"
#include "hal/hal_time.h"
#include "hal/hal_uart.h"
#include "stm32f4/stm32f4_board.h"
#include "stm32f4/stm32f4_drivers.h"

#define RCC ((stm32f4_rcc_t *)STM32F4_RCC_BASE)
#define FLASH_IF ((stm32f4_flash_if_t *)STM32F4_FLASH_IF_BASE)
#define PWR_CR ((volatile uint32_t *)STM32F4_PWR_BASE)
#define GPIOA ((stm32f4_gpio_t *)STM32F4_GPIOA_BASE)
#define GPIOB ((stm32f4_gpio_t *)STM32F4_GPIOB_BASE)
#define CAN1 ((stm32f4_can_t *)STM32F4_CAN1_BASE)
#define USART2 ((stm32f4_usart_t *)STM32F4_USART2_BASE)
#define IWDG ((stm32f4_iwdg_t *)STM32F4_IWDG_BASE)
#define SYSTICK ((stm32f4_systick_t *)STM32F4_SYSTICK_BASE)
#define SCB_ICSR (*(volatile uint32_t *)STM32F4_SCB_ICSR)
#define SCB_SHPR3 (*(volatile uint32_t *)0xE000ED20u)
#define NVIC_ISER ((volatile uint32_t *)STM32F4_NVIC_ISER_BASE)
#define NVIC_IPR ((volatile uint8_t *)STM32F4_NVIC_IPR_BASE)

void SysTick_Handler(void);
void CAN1_RX0_IRQHandler(void);
void CAN1_SCE_IRQHandler(void);
void USART2_IRQHandler(void);

static hal_reset_cause_t reset_cause_ = HAL_RESET_OTHER;

static void nvic_enable_(uint32_t irq, uint32_t prio)
{
    NVIC_IPR[irq] = (uint8_t)(prio << 4);  // 4 priority bits, in the high nibble
    NVIC_ISER[irq / 32u] = 1u << (irq % 32u);
}

static void gpio_af_(stm32f4_gpio_t *g, uint32_t pin, uint32_t af, bool pull_up)
{
    g->MODER = (g->MODER & ~(3u << (2u * pin))) | (2u << (2u * pin));
    g->OSPEEDR |= 2u << (2u * pin);  // fast: 500 kbit/s edges
    g->PUPDR = (g->PUPDR & ~(3u << (2u * pin))) | ((pull_up ? 1u : 0u) << (2u * pin));
    volatile uint32_t *afr = &g->AFR[pin / 8u];
    *afr = (*afr & ~(0xFu << (4u * (pin % 8u)))) | (af << (4u * (pin % 8u)));
}

int stm32f4_board_init(void)
{
    const uint32_t csr = RCC->CSR;
    reset_cause_ = stm32f4_reset_cause_from_csr(csr);
    RCC->CSR = csr | RCC_CSR_RMVF;  // clear the flags so the next reset reports its own cause
    const int rc = stm32f4_clock_init(RCC, FLASH_IF, PWR_CR);
    RCC->AHB1ENR |= RCC_AHB1ENR_GPIOAEN | RCC_AHB1ENR_GPIOBEN;
    (void)RCC->AHB1ENR;  // a read back lets the enable take effect before the first access
    gpio_af_(GPIOB, 8u, 9u, true);   // CAN1_RX
    gpio_af_(GPIOB, 9u, 9u, false);  // CAN1_TX
    gpio_af_(GPIOA, 2u, 7u, false);  // USART2_TX
    gpio_af_(GPIOA, 3u, 7u, true);   // USART2_RX
    return rc;
}

// ---- Time -------------------------------------------------------------------------------------
static volatile uint64_t ms_;

int hal_time_init(void)
{
    ms_ = 0u;
    SYSTICK->CTRL = 0u;
    SYSTICK->LOAD = STM32F4_SYSCLK_HZ / 1000u - 1u;
    SYSTICK->VAL = 0u;
    SCB_SHPR3 = (SCB_SHPR3 & 0x00FFFFFFu) | ((uint32_t)STM32F4_CFG_IRQ_PRIO_SYSTICK << 28);
    SYSTICK->CTRL = SYSTICK_CTRL_CLKSOURCE | SYSTICK_CTRL_TICKINT | SYSTICK_CTRL_ENABLE;
    return (SYSTICK->CTRL & SYSTICK_CTRL_ENABLE) ? FW_OK : FW_ERR_IO;
}

void SysTick_Handler(void)
{
    ms_ = ms_ + 1u;
}

uint64_t hal_time_us(void)
{
    const hal_irq_state_t s = hal_irq_save();
    uint64_t ms = ms_;
    uint32_t val = SYSTICK->VAL;
    if (SCB_ICSR & SCB_ICSR_PENDSTSET) {
        // The counter wrapped and its interrupt is still pending (masked here): count that
        // millisecond, and re-read the value so that it is certainly after the wrap.
        ms += 1u;
        val = SYSTICK->VAL;
    }
    hal_irq_restore(s);
    return stm32f4_time_us(ms, SYSTICK->LOAD, val, STM32F4_SYSCLK_HZ / 1000000u);
}

// ---- CPU ------------------------------------------------------------------------------------------
hal_irq_state_t hal_irq_save(void)
{
    uint32_t primask;
    __asm__ volatile("mrs %0, primask\n\tcpsid i" : "=r"(primask)::"memory");
    return primask;
}

void hal_irq_restore(hal_irq_state_t state)
{
    __asm__ volatile("msr primask, %0" ::"r"(state) : "memory");
}

void hal_cpu_wait_until(uint64_t deadline_us)
{
    // SysTick wakes the core every millisecond, so one WFI never oversleeps by more than 1 ms;
    // the contract allows the early return.
    if (hal_time_us() < deadline_us) {
        __asm__ volatile("dsb\n\twfi" ::: "memory");
    }
}

static bool watchdog_running_;

int hal_cpu_watchdog_start(uint32_t timeout_ms)
{
    const int rc = stm32f4_iwdg_start(IWDG, timeout_ms);
    watchdog_running_ = rc == FW_OK;
    return rc;
}

void hal_cpu_watchdog_kick(void)
{
    if (watchdog_running_) {
        stm32f4_iwdg_kick(IWDG);
    }
}

hal_reset_cause_t hal_cpu_reset_cause(void)
{
    return reset_cause_;
}

// ---- CAN --------------------------------------------------------------------------------------------
static hal_can_rx_fn can_rx_;
static void *can_ctx_;
static hal_can_stats_t can_stats_;

int hal_can_init(uint32_t bitrate, const uint32_t *accept_ids, uint32_t n_ids, hal_can_rx_fn on_rx,
                 void *ctx)
{
    RCC->APB1ENR |= RCC_APB1ENR_CAN1EN;
    (void)RCC->APB1ENR;
    can_rx_ = on_rx;
    can_ctx_ = ctx;
    memset(&can_stats_, 0, sizeof can_stats_);
    const int rc = stm32f4_can_setup(CAN1, STM32F4_APB1_HZ, bitrate, accept_ids, n_ids);
    if (rc == FW_OK) {
        nvic_enable_(STM32F4_IRQ_CAN1_RX0, STM32F4_CFG_IRQ_PRIO_CAN);
        nvic_enable_(STM32F4_IRQ_CAN1_SCE, STM32F4_CFG_IRQ_PRIO_CAN);
    }
    return rc;
}

int hal_can_send(const hal_can_frame_t *frame)
{
    const hal_irq_state_t s = hal_irq_save();  // thread and interrupt senders share the mailboxes
    const int rc = stm32f4_can_write(CAN1, frame);
    if (rc >= 0) {
        can_stats_.tx_frames++;
    } else if (rc == FW_ERR_FULL) {
        can_stats_.tx_dropped++;
    }
    hal_irq_restore(s);
    return rc >= 0 ? FW_OK : rc;
}

void hal_can_get_stats(hal_can_stats_t *out)
{
    const hal_irq_state_t s = hal_irq_save();
    *out = can_stats_;
    hal_irq_restore(s);
}

void CAN1_RX0_IRQHandler(void)
{
    hal_can_frame_t frame;
    bool overrun = false;
    for (uint32_t i = 0; i < 3u; i++) {  // the FIFO holds at most 3 frames
        const bool got = stm32f4_can_read(CAN1, &frame, &overrun);
        if (overrun) {
            can_stats_.rx_overruns++;
        }
        if (!got) {
            break;
        }
        can_stats_.rx_frames++;
        if (can_rx_ != NULL) {
            can_rx_(&frame, can_ctx_);
        }
    }
}

void CAN1_SCE_IRQHandler(void)
{
    // Error warning, passive and bus-off transitions (ABOM recovers from bus-off by itself).
    if (CAN1->ESR & (CAN_ESR_EWGF | CAN_ESR_EPVF | CAN_ESR_BOFF)) {
        can_stats_.bus_errors++;
    }
    CAN1->MSR = CAN_MSR_ERRI;  // write 1 to clear
}

// ---- UART ------------------------------------------------------------------------------------------
static uint8_t uart_rx_buf_[STM32F4_CFG_UART_RX_BYTES];
static uint8_t uart_tx_buf_[STM32F4_CFG_UART_TX_BYTES];
static stm32f4_usart_port_t uart_;
static hal_uart_rx_fn uart_rx_;
static void *uart_ctx_;

int hal_uart_init(uint32_t baud, hal_uart_rx_fn on_rx, void *ctx)
{
    RCC->APB1ENR |= RCC_APB1ENR_USART2EN;
    (void)RCC->APB1ENR;
    uart_.regs = USART2;
    stm32f4_ring_init(&uart_.rx, uart_rx_buf_, sizeof uart_rx_buf_);
    stm32f4_ring_init(&uart_.tx, uart_tx_buf_, sizeof uart_tx_buf_);
    uart_rx_ = on_rx;
    uart_ctx_ = ctx;
    const int rc = stm32f4_usart_setup(&uart_, STM32F4_APB1_HZ, baud);
    if (rc == FW_OK) {
        nvic_enable_(STM32F4_IRQ_USART2, STM32F4_CFG_IRQ_PRIO_UART);
    }
    return rc;
}

void USART2_IRQHandler(void)
{
    if (stm32f4_usart_irq(&uart_) && uart_rx_ != NULL) {
        uart_rx_(uart_ctx_);
    }
}

size_t hal_uart_read(uint8_t *buf, size_t cap)
{
    size_t n = 0;
    while (n < cap && stm32f4_ring_get(&uart_.rx, &buf[n])) {
        n++;
    }
    return n;
}

size_t hal_uart_write(const uint8_t *data, size_t len)
{
    const hal_irq_state_t s = hal_irq_save();  // CR1 is also changed by the interrupt
    const size_t n = stm32f4_usart_queue(&uart_, data, len);
    hal_irq_restore(s);
    return n;
}

void hal_uart_get_stats(hal_uart_stats_t *out)
{
    const hal_irq_state_t s = hal_irq_save();
    *out = uart_.stats;
    hal_irq_restore(s);
}

// ---- Flash -------------------------------------------------------------------------------------------
static void flash_wait_kick_(void)
{
    hal_cpu_watchdog_kick();
}

static const stm32f4_flash_dev_t flash_dev_ = {
    FLASH_IF,
    (volatile uint8_t *)STM32F4_HAL_FLASH_BASE,
    STM32F4_HAL_FLASH_FIRST_SECTOR,
    STM32F4_HAL_FLASH_SECTORS,
    STM32F4_HAL_FLASH_SECTOR_SIZE,
    flash_wait_kick_,
};

int hal_flash_get_geometry(hal_flash_geometry_t *out)
{
    out->sector_size = STM32F4_HAL_FLASH_SECTOR_SIZE;
    out->sector_count = STM32F4_HAL_FLASH_SECTORS;
    out->write_align = 4u;
    return FW_OK;
}

int hal_flash_read(uint32_t offset, void *buf, size_t len)
{
    const uint32_t region = STM32F4_HAL_FLASH_SECTORS * STM32F4_HAL_FLASH_SECTOR_SIZE;
    if (offset > region || len > region - offset) {
        return FW_ERR_INVAL;
    }
    memcpy(buf, (const void *)(uintptr_t)(STM32F4_HAL_FLASH_BASE + offset), len);
    return FW_OK;
}

int hal_flash_erase(uint32_t sector)
{
    return stm32f4_flash_erase(&flash_dev_, sector);
}

int hal_flash_write(uint32_t offset, const void *data, size_t len)
{
    return stm32f4_flash_program(&flash_dev_, offset, data, len);
}

// Real time passes by itself on the MCU: the scheduler's cost accounting is for the host's
// lock-step model only.
void hal_cpu_account(uint32_t cycles)
{
    (void)cycles;
}
