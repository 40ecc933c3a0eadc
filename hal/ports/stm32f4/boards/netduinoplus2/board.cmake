# SPDX-License-Identifier: MIT
# The emulated robot board: QEMU's `-M netduinoplus2`, an STM32F405 with SysTick, NVIC, USARTs and
# TIM2-5 modelled; no RCC, bxCAN, flash interface, IWDG or CCM (include/netduinoplus2/board.h says
# what stands in for them). Built alone (-DDYNAQPC_BOARD=netduinoplus2); the cortex-m4 preset
# builds it so in <build>/netduinoplus2 (targets/CMakeLists.txt), for its closed-loop tests.
#
# From the family: the drivers (the USART with its ring), hal_uart and PRIMASK/WFI, the startup (with this board's hooks,
# startup_hooks.h), the output sections and region checks (ld/), semihosting, dynaqpc_image().
# Its own: the hal_* contract on what QEMU models (hal_netduinoplus2.c), the SLCAN codec that
# stands in for bxCAN, the memory map (netduinoplus2.ld).

# SLCAN framing: pure code, also compiled into the host tests (tests/unit/slcan).
add_library(dynaqpc_slcan STATIC ${DYNAQPC_BOARD_DIR}/slcan.c)
target_include_directories(dynaqpc_slcan PUBLIC ${DYNAQPC_BOARD_DIR}/include)
target_link_libraries(dynaqpc_slcan PUBLIC dynaqpc_hal PRIVATE dynaqpc_c_flags)

# The board's frames reach it through a Python bridge on a host it shares: their receive times
# jitter by tens of ms, so the gyro integrates over its samples' own period (drivers_config.h).
target_compile_definitions(dynaqpc_c_flags INTERFACE FW_CFG_GYRO_PERIOD_US=16000u)

# QEMU's USART never raises TXE's interrupt: the family's hal_uart writes DR directly.
target_compile_definitions(dynaqpc_stm32f4_hal_common PRIVATE STM32F4_CFG_UART_TX_POLLED=1)

add_library(dynaqpc_hal_netduinoplus2 STATIC ${DYNAQPC_BOARD_DIR}/hal_netduinoplus2.c)
target_include_directories(dynaqpc_hal_netduinoplus2 PUBLIC ${DYNAQPC_BOARD_DIR}/include)
target_link_libraries(dynaqpc_hal_netduinoplus2
    PUBLIC dynaqpc_hal dynaqpc_slcan dynaqpc_stm32f4_drivers dynaqpc_stm32f4_hal_common
        dynaqpc_stm32f4_semihost
    PRIVATE dynaqpc_c_flags)

set(DYNAQPC_NETDUINOPLUS2_LD ${DYNAQPC_BOARD_DIR}/netduinoplus2.ld CACHE INTERNAL "the emulated board's memory map")
set(board_startup_hooks ${DYNAQPC_BOARD_DIR}/startup_hooks.h)
set(board_startup_include ${DYNAQPC_BOARD_DIR}/include)
list(APPEND board_targets netduinoplus2-robot)
