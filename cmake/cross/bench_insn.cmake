# SPDX-License-Identifier: MIT
# cmake -DQEMU=<qemu-system-arm> -DTIMEOUT=<timeout> -DNM=<nm> -DPLUGIN=<libinsn_count.so>
#       -DELF=<dynaqpc-qemu-agent-*.elf> -DPROFILE=<name> -P bench_insn.cmake
# Runs the emulator image with the instruction-counting plugin and prints
#   instructions_per_update=<n> profile=<name> ...
# = instructions executed inside agent_plan() calls (with the markers' own few) / planning updates.
execute_process(COMMAND ${NM} ${ELF} OUTPUT_VARIABLE syms RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${NM} ${ELF} failed")
endif()
set(args "")
foreach(mark begin end report)
    if(NOT syms MATCHES "([0-9a-fA-F]+) T bench_mark_${mark}\n")
        message(FATAL_ERROR "no symbol bench_mark_${mark} in ${ELF}")
    endif()
    string(APPEND args ",${mark}=0x${CMAKE_MATCH_1}")
endforeach()
execute_process(
    COMMAND ${TIMEOUT} 600 ${QEMU} -M mps2-an386 -display none -chardev stdio,id=sh0
        -semihosting-config enable=on,target=native,chardev=sh0
        -plugin ${PLUGIN}${args} -kernel ${ELF}
    OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
message("${out}${err}")
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "the emulator image exited with ${rc}")
endif()
if(NOT err MATCHES "insn_count=([0-9]+) windows=([0-9]+)")
    message(FATAL_ERROR "the plugin printed no count")
endif()
set(insns ${CMAKE_MATCH_1})
set(windows ${CMAKE_MATCH_2})
if(NOT out MATCHES "planning_updates=([0-9]+)")
    message(FATAL_ERROR "the image printed no planning_updates")
endif()
set(updates ${CMAKE_MATCH_1})
if(updates EQUAL 0)
    message(FATAL_ERROR "no planning updates")
endif()
math(EXPR per_update "(${insns} + ${updates} / 2) / ${updates}")
math(EXPR per_call "(${insns} + ${windows} / 2) / ${windows}")
message("instructions_per_update=${per_update} profile=${PROFILE} cpu=cortex-m4 "
        "instructions_per_plan_call=${per_call} (QEMU TCG plugin: ${insns} instructions in "
        "${windows} agent_plan calls, which made ${updates} planning updates; calls that found "
        "nothing to plan on are counted too, as in tests/bench)")
