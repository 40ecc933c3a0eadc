// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 port: the registers it uses, from the STM32F405/407 reference manual (RM0090).
//
// Each peripheral is a struct of volatile 32-bit registers laid out at its offsets; its base
// address is defined once below (STM32F4_*_BASE). The drivers take a pointer to the struct, so the
// host unit tests hand them a plain RAM struct (a fake register block) instead of the hardware.
#ifndef STM32F4_REGS_H
#define STM32F4_REGS_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define STM32F4_REG volatile uint32_t

// ---- Base addresses (RM0090 section 2.3, memory map) -------------------------------------------
#define STM32F4_IWDG_BASE 0x40003000u
#define STM32F4_USART2_BASE 0x40004400u
#define STM32F4_CAN1_BASE 0x40006400u
#define STM32F4_PWR_BASE 0x40007000u
#define STM32F4_USART1_BASE 0x40011000u
#define STM32F4_GPIOA_BASE 0x40020000u
#define STM32F4_GPIOB_BASE 0x40020400u
#define STM32F4_RCC_BASE 0x40023800u
#define STM32F4_FLASH_IF_BASE 0x40023C00u
#define STM32F4_SYSTICK_BASE 0xE000E010u
#define STM32F4_NVIC_ISER_BASE 0xE000E100u
#define STM32F4_NVIC_IPR_BASE 0xE000E400u
#define STM32F4_SCB_ICSR 0xE000ED04u
#define STM32F4_SCB_CPACR 0xE000ED88u
#define STM32F4_FLASH_MEM_BASE 0x08000000u  // main flash memory, sector 0
#define STM32F4_FLASH_SIZE_REG 0x1FFF7A22u  // F_SIZE (RM0090 39.2): 16 bits, flash size in KB

// ---- RCC (RM0090 7.3) ---------------------------------------------------------------------------
typedef struct stm32f4_rcc {
    STM32F4_REG CR;         // 0x00
    STM32F4_REG PLLCFGR;    // 0x04
    STM32F4_REG CFGR;       // 0x08
    STM32F4_REG CIR;        // 0x0C
    STM32F4_REG AHB1RSTR;   // 0x10
    STM32F4_REG AHB2RSTR;   // 0x14
    STM32F4_REG AHB3RSTR;   // 0x18
    STM32F4_REG reserved0;  // 0x1C
    STM32F4_REG APB1RSTR;   // 0x20
    STM32F4_REG APB2RSTR;   // 0x24
    STM32F4_REG reserved1[2];
    STM32F4_REG AHB1ENR;    // 0x30
    STM32F4_REG AHB2ENR;    // 0x34
    STM32F4_REG AHB3ENR;    // 0x38
    STM32F4_REG reserved2;
    STM32F4_REG APB1ENR;    // 0x40
    STM32F4_REG APB2ENR;    // 0x44
    STM32F4_REG reserved3[2];
    STM32F4_REG AHB1LPENR;  // 0x50
    STM32F4_REG AHB2LPENR;  // 0x54
    STM32F4_REG AHB3LPENR;  // 0x58
    STM32F4_REG reserved4;
    STM32F4_REG APB1LPENR;  // 0x60
    STM32F4_REG APB2LPENR;  // 0x64
    STM32F4_REG reserved5[2];
    STM32F4_REG BDCR;       // 0x70
    STM32F4_REG CSR;        // 0x74
} stm32f4_rcc_t;

#define RCC_CR_HSEON (1u << 16)
#define RCC_CR_HSERDY (1u << 17)
#define RCC_CR_PLLON (1u << 24)
#define RCC_CR_PLLRDY (1u << 25)
#define RCC_PLLCFGR_PLLSRC_HSE (1u << 22)
#define RCC_CFGR_SW_PLL 0x2u
#define RCC_CFGR_SWS_MASK (0x3u << 2)
#define RCC_CFGR_SWS_PLL (0x2u << 2)
#define RCC_CFGR_PPRE1_DIV4 (0x5u << 10)
#define RCC_CFGR_PPRE2_DIV2 (0x4u << 13)
#define RCC_AHB1ENR_GPIOAEN (1u << 0)
#define RCC_AHB1ENR_GPIOBEN (1u << 1)
#define RCC_APB1ENR_USART2EN (1u << 17)
#define RCC_APB1ENR_CAN1EN (1u << 25)
#define RCC_APB1ENR_PWREN (1u << 28)
#define RCC_CSR_LSION (1u << 0)
#define RCC_CSR_RMVF (1u << 24)
#define RCC_CSR_BORRSTF (1u << 25)
#define RCC_CSR_PINRSTF (1u << 26)
#define RCC_CSR_PORRSTF (1u << 27)
#define RCC_CSR_SFTRSTF (1u << 28)
#define RCC_CSR_IWDGRSTF (1u << 29)
#define RCC_CSR_WWDGRSTF (1u << 30)
#define RCC_CSR_LPWRRSTF (1u << 31)

#define PWR_CR_VOS (1u << 14)

// ---- Embedded flash interface (RM0090 3.9) -------------------------------------------------------
typedef struct stm32f4_flash_if {
    STM32F4_REG ACR;      // 0x00
    STM32F4_REG KEYR;     // 0x04
    STM32F4_REG OPTKEYR;  // 0x08
    STM32F4_REG SR;       // 0x0C
    STM32F4_REG CR;       // 0x10
    STM32F4_REG OPTCR;    // 0x14
} stm32f4_flash_if_t;

#define FLASH_ACR_LATENCY_MASK 0xFu
#define FLASH_ACR_PRFTEN (1u << 8)
#define FLASH_ACR_ICEN (1u << 9)
#define FLASH_ACR_DCEN (1u << 10)
#define FLASH_ACR_ICRST (1u << 11)
#define FLASH_ACR_DCRST (1u << 12)
#define FLASH_KEY1 0x45670123u
#define FLASH_KEY2 0xCDEF89ABu
#define FLASH_SR_EOP (1u << 0)
#define FLASH_SR_OPERR (1u << 1)
#define FLASH_SR_WRPERR (1u << 4)
#define FLASH_SR_PGAERR (1u << 5)
#define FLASH_SR_PGPERR (1u << 6)
#define FLASH_SR_PGSERR (1u << 7)
#define FLASH_SR_ERRORS                                                                            \
    (FLASH_SR_OPERR | FLASH_SR_WRPERR | FLASH_SR_PGAERR | FLASH_SR_PGPERR | FLASH_SR_PGSERR)
#define FLASH_SR_BSY (1u << 16)
#define FLASH_CR_PG (1u << 0)
#define FLASH_CR_SER (1u << 1)
#define FLASH_CR_SNB_SHIFT 3u
// SNB is 5 bits on the F42x/43x (bank 2's sectors 12-23 are coded 16-27), 4 bits on the
// F405/407 (bit 7 reserved, kept 0: their sectors 0-11 never set it).
#define FLASH_CR_SNB_MASK (0x1Fu << 3)
#define FLASH_CR_PSIZE_MASK (0x3u << 8)
#define FLASH_CR_PSIZE_X32 (0x2u << 8)  // 32-bit parallelism: supply 2.7-3.6 V
#define FLASH_CR_STRT (1u << 16)
#define FLASH_CR_LOCK (1u << 31)

// ---- bxCAN (RM0090 32.9) ---------------------------------------------------------------------------
typedef struct stm32f4_can_tx_mailbox {
    STM32F4_REG TIR;
    STM32F4_REG TDTR;
    STM32F4_REG TDLR;
    STM32F4_REG TDHR;
} stm32f4_can_tx_mailbox_t;

typedef struct stm32f4_can_rx_fifo {
    STM32F4_REG RIR;
    STM32F4_REG RDTR;
    STM32F4_REG RDLR;
    STM32F4_REG RDHR;
} stm32f4_can_rx_fifo_t;

typedef struct stm32f4_can_filter {
    STM32F4_REG FR1;
    STM32F4_REG FR2;
} stm32f4_can_filter_t;

#define STM32F4_CAN_FILTER_BANKS 28u

typedef struct stm32f4_can {
    STM32F4_REG MCR;  // 0x000
    STM32F4_REG MSR;  // 0x004
    STM32F4_REG TSR;  // 0x008
    STM32F4_REG RF0R; // 0x00C
    STM32F4_REG RF1R; // 0x010
    STM32F4_REG IER;  // 0x014
    STM32F4_REG ESR;  // 0x018
    STM32F4_REG BTR;  // 0x01C
    STM32F4_REG reserved0[88];
    stm32f4_can_tx_mailbox_t tx[3];  // 0x180
    stm32f4_can_rx_fifo_t rx[2];     // 0x1B0
    STM32F4_REG reserved1[12];
    STM32F4_REG FMR;   // 0x200
    STM32F4_REG FM1R;  // 0x204
    STM32F4_REG reserved2;
    STM32F4_REG FS1R;  // 0x20C
    STM32F4_REG reserved3;
    STM32F4_REG FFA1R; // 0x214
    STM32F4_REG reserved4;
    STM32F4_REG FA1R;  // 0x21C
    STM32F4_REG reserved5[8];
    stm32f4_can_filter_t filter[STM32F4_CAN_FILTER_BANKS];  // 0x240
} stm32f4_can_t;

#define CAN_MCR_INRQ (1u << 0)
#define CAN_MCR_SLEEP (1u << 1)
#define CAN_MCR_TXFP (1u << 2)
#define CAN_MCR_ABOM (1u << 6)
#define CAN_MCR_RESET (1u << 15)
#define CAN_MSR_INAK (1u << 0)
#define CAN_MSR_SLAK (1u << 1)
#define CAN_MSR_ERRI (1u << 2)
#define CAN_TSR_TME0 (1u << 26)
#define CAN_RF0R_FMP0_MASK 0x3u
#define CAN_RF0R_FULL0 (1u << 3)
#define CAN_RF0R_FOVR0 (1u << 4)
#define CAN_RF0R_RFOM0 (1u << 5)
#define CAN_IER_FMPIE0 (1u << 1)
#define CAN_IER_FOVIE0 (1u << 3)
#define CAN_IER_EWGIE (1u << 8)
#define CAN_IER_EPVIE (1u << 9)
#define CAN_IER_BOFIE (1u << 10)
#define CAN_IER_ERRIE (1u << 15)
#define CAN_ESR_EWGF (1u << 0)
#define CAN_ESR_EPVF (1u << 1)
#define CAN_ESR_BOFF (1u << 2)
#define CAN_TIR_TXRQ (1u << 0)
#define CAN_IR_RTR (1u << 1)  // TIR and RIR
#define CAN_IR_IDE (1u << 2)  // TIR and RIR
#define CAN_IR_STID_SHIFT 21u
#define CAN_IR_EXID_SHIFT 3u
#define CAN_DTR_DLC_MASK 0xFu
#define CAN_FMR_FINIT (1u << 0)

// ---- USART (RM0090 30.6) ----------------------------------------------------------------------------
typedef struct stm32f4_usart {
    STM32F4_REG SR;   // 0x00
    STM32F4_REG DR;   // 0x04
    STM32F4_REG BRR;  // 0x08
    STM32F4_REG CR1;  // 0x0C
    STM32F4_REG CR2;  // 0x10
    STM32F4_REG CR3;  // 0x14
    STM32F4_REG GTPR; // 0x18
} stm32f4_usart_t;

#define USART_SR_PE (1u << 0)
#define USART_SR_FE (1u << 1)
#define USART_SR_NF (1u << 2)
#define USART_SR_ORE (1u << 3)
#define USART_SR_RXNE (1u << 5)
#define USART_SR_TXE (1u << 7)
#define USART_CR1_RE (1u << 2)
#define USART_CR1_TE (1u << 3)
#define USART_CR1_RXNEIE (1u << 5)
#define USART_CR1_TXEIE (1u << 7)
#define USART_CR1_UE (1u << 13)

// ---- GPIO (RM0090 8.4) -------------------------------------------------------------------------------
typedef struct stm32f4_gpio {
    STM32F4_REG MODER;   // 0x00
    STM32F4_REG OTYPER;  // 0x04
    STM32F4_REG OSPEEDR; // 0x08
    STM32F4_REG PUPDR;   // 0x0C
    STM32F4_REG IDR;     // 0x10
    STM32F4_REG ODR;     // 0x14
    STM32F4_REG BSRR;    // 0x18
    STM32F4_REG LCKR;    // 0x1C
    STM32F4_REG AFR[2];  // 0x20, 0x24
} stm32f4_gpio_t;

// ---- Independent watchdog (RM0090 19.4) -------------------------------------------------------------
typedef struct stm32f4_iwdg {
    STM32F4_REG KR;   // 0x00
    STM32F4_REG PR;   // 0x04
    STM32F4_REG RLR;  // 0x08
    STM32F4_REG SR;   // 0x0C
} stm32f4_iwdg_t;

#define IWDG_KEY_RELOAD 0xAAAAu
#define IWDG_KEY_ACCESS 0x5555u
#define IWDG_KEY_START 0xCCCCu
#define IWDG_SR_PVU (1u << 0)
#define IWDG_SR_RVU (1u << 1)
#define IWDG_LSI_HZ 32000u  // nominal; RM0090 gives 17-47 kHz over temperature and parts

// ---- SysTick (ARMv7-M architecture manual B3.3) ------------------------------------------------------
typedef struct stm32f4_systick {
    STM32F4_REG CTRL;
    STM32F4_REG LOAD;
    STM32F4_REG VAL;
    STM32F4_REG CALIB;
} stm32f4_systick_t;

#define SYSTICK_CTRL_ENABLE (1u << 0)
#define SYSTICK_CTRL_TICKINT (1u << 1)
#define SYSTICK_CTRL_CLKSOURCE (1u << 2)
#define SCB_ICSR_PENDSTSET (1u << 26)

// ---- Interrupt numbers (RM0090 table 61) --------------------------------------------------------------
#define STM32F4_IRQ_CAN1_TX 19u
#define STM32F4_IRQ_CAN1_RX0 20u
#define STM32F4_IRQ_CAN1_RX1 21u
#define STM32F4_IRQ_CAN1_SCE 22u
#define STM32F4_IRQ_USART1 37u
#define STM32F4_IRQ_USART2 38u
#define STM32F4_IRQ_COUNT 82u

#ifdef __cplusplus
}
#endif

#endif // STM32F4_REGS_H
