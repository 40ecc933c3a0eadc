# SPDX-License-Identifier: MIT
# The reference robot board with an STM32F405/407 (RM0090): 1 MB flash, 128 KB SRAM + 64 KB CCM
# (192 KB of RAM: the default board). Its peripherals are the family's (src/hal_stm32f4.c: bxCAN
# on PB8/PB9, the Cricket listener on USART2, the flash region, IWDG); its memory map is
# stm32f405.ld. Images: the paper-lab robot (targets/stm32f4-robot), and the agent on QEMU's
# mps2-an386 with this family's startup (targets/qemu-agent: the robot's CPU learns what the host
# learns, and what it costs).
list(APPEND board_robot_images "paper-lab|${DYNAQPC_BOARD_DIR}/stm32f405.ld|DYNAQPC_PAPER_LAB_RAM_BUDGET")
list(APPEND board_targets stm32f4-robot qemu-agent)
