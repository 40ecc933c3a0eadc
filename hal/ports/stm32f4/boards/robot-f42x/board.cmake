# SPDX-License-Identifier: MIT
# The reference robot board with an STM32F427/429/437/439, 2 MB (the "I" parts; RM0090): the same
# peripherals at the same addresses as the F405 (the family's src/hal_stm32f4.c), two flash banks,
# and 256 KB of RAM: 192 KB of contiguous SRAM1/2/3 for .data and .bss (room for the paper-sim
# agent, one 158 KB object) and 64 KB of CCM for the stack (stm32f427.ld).
# Images: the paper-sim robot (targets/stm32f4-robot), its RAM checked against this board's own
# budget by the size report (cortex-m4.size.dynaqpc-fw-paper-sim) and the link: 192 KB, the
# default; and the paper-sim-large robot in the whole 256 KB (cortex-m4.size.dynaqpc-fw-paper-
# sim-large), whose tables beyond the SRAM are in CCM (the reset handler zeroes only .bss: they
# are cleared by their owners, robot/src/profiles/profile_paper_sim_large.c).
set(DYNAQPC_ROBOT_F42X_RAM_BUDGET 196608 CACHE STRING
    "RAM budget of the robot-f42x board's images (bytes; the board has 262144: SRAM + CCM)")
if(DYNAQPC_ROBOT_F42X_RAM_BUDGET GREATER 262144)
    message(FATAL_ERROR "DYNAQPC_ROBOT_F42X_RAM_BUDGET=${DYNAQPC_ROBOT_F42X_RAM_BUDGET}: the board has 262144 bytes of RAM")
endif()
list(APPEND board_robot_images "paper-sim|${DYNAQPC_BOARD_DIR}/stm32f427.ld|DYNAQPC_ROBOT_F42X_RAM_BUDGET")
# The 256 KB image: the paper-sim-large profile (16,384 Q rows with 16-bit keys, for floors of up
# to 16 x 16 m), SRAM for .data, .bss and the stack and CCM for its .ccm tables
# (stm32f427-large.ld); its size report checks the board's whole RAM.
set(DYNAQPC_ROBOT_F42X_LARGE_RAM_BUDGET 262144 CACHE STRING
    "RAM budget of the robot-f42x board's paper-sim-large image (bytes: SRAM + CCM)")
list(APPEND board_robot_images "paper-sim-large|${DYNAQPC_BOARD_DIR}/stm32f427-large.ld|DYNAQPC_ROBOT_F42X_LARGE_RAM_BUDGET")
list(APPEND board_targets stm32f4-robot)
