// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 family: the hal_* contract on the robot boards' peripherals (the UART's is
// hal_stm32f4_uart.c, every board's), and their interrupt handlers.
//
// The register-level work is in the drivers (stm32f4_*.c, tested on the host with fake
// registers); this file passes them the real addresses, owns the static state (rings, counters,
// handlers) and the Cortex-M specifics (PRIMASK, WFI, NVIC, SysTick).
#include <string.h>

#include "fw/fw_assert.h"
#include "hal/hal_can.h"
#include "hal/hal_cpu.h"
#include "hal/hal_flash.h"
#include "hal/hal_time.h"
#include "stm32f4/stm32f4_board.h"
#include "stm32f4/stm32f4_cpu.h"
#include "stm32f4/stm32f4_drivers.h"

#define RCC ((stm32f4_rcc_t *)STM32F4_RCC_BASE)
#define FLASH_IF ((stm32f4_flash_if_t *)STM32F4_FLASH_IF_BASE)
#define PWR_CR ((volatile uint32_t *)STM32F4_PWR_BASE)
#define GPIOA ((stm32f4_gpio_t *)STM32F4_GPIOA_BASE)
#define GPIOB ((stm32f4_gpio_t *)STM32F4_GPIOB_BASE)
#define CAN1 ((stm32f4_can_t *)STM32F4_CAN1_BASE)
#define IWDG ((stm32f4_iwdg_t *)STM32F4_IWDG_BASE)
#define SYSTICK ((stm32f4_systick_t *)STM32F4_SYSTICK_BASE)
#define SCB_ICSR (*(volatile uint32_t *)STM32F4_SCB_ICSR)
#define SCB_SHPR3 (*(volatile uint32_t *)0xE000ED20u)

void SysTick_Handler(void);
void CAN1_RX0_IRQHandler(void);
void CAN1_SCE_IRQHandler(void);

static hal_reset_cause_t reset_cause_ = HAL_RESET_OTHER;

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
    const uint32_t s = stm32f4_irq_save();
    uint64_t ms = ms_;
    uint32_t val = SYSTICK->VAL;
    if (SCB_ICSR & SCB_ICSR_PENDSTSET) {
        // The counter wrapped and its interrupt is still pending (masked here): count that
        // millisecond, and re-read the value so that it is certainly after the wrap.
        ms += 1u;
        val = SYSTICK->VAL;
    }
    stm32f4_irq_restore(s);
    return stm32f4_time_us(ms, SYSTICK->LOAD, val, STM32F4_SYSCLK_HZ / 1000000u);
}

// ---- CPU: masking, the idle wait and cost accounting are the family's (hal_stm32f4_cpu.c) ---------
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
// The interrupt handlers' work is in stm32f4_bxcan.c (host-tested with a fake FIFO).
static stm32f4_can_port_t can_ = {CAN1, NULL, NULL, {0}};

int hal_can_init(uint32_t bitrate, const uint32_t *accept_ids, uint32_t n_ids, hal_can_rx_fn on_rx,
                 void *ctx)
{
    RCC->APB1ENR |= RCC_APB1ENR_CAN1EN;
    (void)RCC->APB1ENR;
    can_.on_rx = on_rx;
    can_.ctx = ctx;
    memset(&can_.stats, 0, sizeof can_.stats);
    const int rc = stm32f4_can_setup(CAN1, STM32F4_APB1_HZ, bitrate, accept_ids, n_ids);
    if (rc == FW_OK) {
        stm32f4_nvic_enable(STM32F4_IRQ_CAN1_RX0, STM32F4_CFG_IRQ_PRIO_CAN);
        stm32f4_nvic_enable(STM32F4_IRQ_CAN1_SCE, STM32F4_CFG_IRQ_PRIO_CAN);
    }
    return rc;
}

int hal_can_send(const hal_can_frame_t *frame)
{
    FW_ASSERT(frame != NULL);
    const uint32_t s = stm32f4_irq_save();  // thread and interrupt senders share the mailboxes
    const int rc = stm32f4_can_send(&can_, frame);
    stm32f4_irq_restore(s);
    return rc;
}

void hal_can_get_stats(hal_can_stats_t *out)
{
    FW_ASSERT(out != NULL);
    stm32f4_irq_copy(out, &can_.stats, sizeof *out);
}

void CAN1_RX0_IRQHandler(void)
{
    stm32f4_can_rx_irq(&can_);
}

void CAN1_SCE_IRQHandler(void)
{
    stm32f4_can_sce_irq(&can_);
}

// ---- Flash -------------------------------------------------------------------------------------------
// The region is the board's linker script's (boards/robot: sectors 10-11; boards/robot-f42x:
// bank-2 sectors 20-23), given as the values of these symbols. It is checked once against the
// sector map and the part's F_SIZE: on a part without those sectors there is no region
// (hal_flash_get_geometry says FW_ERR_NOSYS) rather than a bus fault.
extern const uint8_t _dynaqpc_store_start[];
extern const uint8_t _dynaqpc_store_first_sector[];
extern const uint8_t _dynaqpc_store_sectors[];
extern const uint8_t _dynaqpc_store_sector_bytes[];
#define LD_VALUE(sym) ((uint32_t)(uintptr_t)(sym))
#define F_SIZE_KB (*(const volatile uint16_t *)STM32F4_FLASH_SIZE_REG)

static void flash_wait_kick_(void)
{
    hal_cpu_watchdog_kick();
}

static const stm32f4_flash_dev_t *flash_dev_(void)
{
    static stm32f4_flash_dev_t dev;
    static bool checked;
    if (!checked) {
        const uint32_t addr = LD_VALUE(_dynaqpc_store_start);
        const uint32_t first = LD_VALUE(_dynaqpc_store_first_sector);
        const uint32_t count = LD_VALUE(_dynaqpc_store_sectors);
        const uint32_t size = LD_VALUE(_dynaqpc_store_sector_bytes);
        dev.regs = FLASH_IF;
        dev.mem = (volatile uint8_t *)(uintptr_t)addr;
        dev.first_sector = first;
        dev.sector_size = size;
        dev.sector_count =
            stm32f4_flash_region_check(addr, first, count, size, F_SIZE_KB) == FW_OK ? count : 0u;
        dev.on_wait = flash_wait_kick_;
        checked = true;
    }
    return &dev;
}

int hal_flash_get_geometry(hal_flash_geometry_t *out)
{
    FW_ASSERT(out != NULL);
    return stm32f4_flash_geometry(flash_dev_(), out);
}

int hal_flash_read(uint32_t offset, void *buf, size_t len)
{
    FW_ASSERT(buf != NULL || len == 0u);
    return stm32f4_flash_read(flash_dev_(), offset, buf, len);
}

const void *hal_flash_map(uint32_t offset, size_t len)
{
    return stm32f4_flash_map(flash_dev_(), offset, len);
}

int hal_flash_erase(uint32_t sector)
{
    return stm32f4_flash_erase(flash_dev_(), sector);
}

int hal_flash_write(uint32_t offset, const void *data, size_t len)
{
    FW_ASSERT(data != NULL || len == 0u);
    return stm32f4_flash_program(flash_dev_(), offset, data, len);
}
