# SPDX-License-Identifier: MIT
# The STM32F4 family's register-level drivers: no fixed address, no CPU instruction, so the host
# tests compile the same files against fake register blocks (tests/support/stm32f4_fake.h).
# Included by the family's CMakeLists.txt and by tests/support/CMakeLists.txt.
set(DYNAQPC_STM32F4_DRIVER_SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/src/stm32f4_wait.c
    ${CMAKE_CURRENT_LIST_DIR}/src/stm32f4_rcc.c
    ${CMAKE_CURRENT_LIST_DIR}/src/stm32f4_iwdg.c
    ${CMAKE_CURRENT_LIST_DIR}/src/stm32f4_time.c
    ${CMAKE_CURRENT_LIST_DIR}/src/stm32f4_bxcan.c
    ${CMAKE_CURRENT_LIST_DIR}/src/stm32f4_usart.c
    ${CMAKE_CURRENT_LIST_DIR}/src/stm32f4_flash.c)
set(DYNAQPC_STM32F4_INCLUDE_DIR ${CMAKE_CURRENT_LIST_DIR}/include)
