# SPDX-License-Identifier: MIT
# cmake -DSIZE=<size> -DELF=<elf> -DRAM_BUDGET=<bytes> -DFLASH_BUDGET=<bytes> -P size_report.cmake
# Prints an image's text/data/bss and its RAM and flash against the budgets; fails beyond them.
include(${CMAKE_CURRENT_LIST_DIR}/match_or_fail.cmake)
execute_process(COMMAND ${SIZE} -B ${ELF} OUTPUT_VARIABLE out RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${SIZE} ${ELF} failed")
endif()
match_or_fail("${out}" "\n[ \t]*([0-9]+)[ \t]+([0-9]+)[ \t]+([0-9]+)" "cannot parse: ${out}" text data bss)
math(EXPR ram "${data} + ${bss}")
math(EXPR flash "${text} + ${data}")
get_filename_component(name ${ELF} NAME)
set(line "size ${name}: text=${text} data=${data} bss=${bss} (bss includes the stack) ram=${ram}/${RAM_BUDGET} flash=${flash}/${FLASH_BUDGET}")
if(ram GREATER RAM_BUDGET OR flash GREATER FLASH_BUDGET)
    message(FATAL_ERROR "${line}: OVER BUDGET")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E echo "${line}: within budget")
