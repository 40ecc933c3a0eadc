# SPDX-License-Identifier: MIT
# The reference robot board with an STM32F427/429/437/439, 2 MB (the "I" parts; RM0090): the same
# peripherals at the same addresses as the F405 (the family's src/hal_stm32f4.c), two flash banks,
# and 256 KB of RAM: 192 KB of contiguous SRAM1/2/3 for .data and .bss (room for the paper-sim
# agent, one 158 KB object) and 64 KB of CCM for the stack (stm32f427.ld).
# Image: the paper-sim robot (targets/stm32f4-robot), its RAM checked against this board's own
# budget by the size report (cortex-m4.size.dynaqpc-fw-paper-sim) and the link. 192 KB stays the
# default; the board's whole 256 KB is -DDYNAQPC_ROBOT_F42X_RAM_BUDGET=262144, for a profile
# whose tables beyond 192 KB go to CCM (the reset handler zeroes only .bss: such a table must be
# placed and cleared by its owner).
set(DYNAQPC_ROBOT_F42X_RAM_BUDGET 196608 CACHE STRING
    "RAM budget of the robot-f42x board's images (bytes; the board has 262144: SRAM + CCM)")
if(DYNAQPC_ROBOT_F42X_RAM_BUDGET GREATER 262144)
    message(FATAL_ERROR "DYNAQPC_ROBOT_F42X_RAM_BUDGET=${DYNAQPC_ROBOT_F42X_RAM_BUDGET}: the board has 262144 bytes of RAM")
endif()
list(APPEND board_robot_images "paper-sim|${DYNAQPC_BOARD_DIR}/stm32f427.ld|DYNAQPC_ROBOT_F42X_RAM_BUDGET")
list(APPEND board_targets stm32f4-robot)
