# SPDX-License-Identifier: MIT
# cmake -DQEMU=<qemu-system-arm> -DTIMEOUT=<timeout> -DNM=<nm> -DPLUGIN=<libinsn_count.so>
#       -DELF=<dynaqpc-qemu-agent-*.elf> -DPROFILE=<name> -P bench_insn.cmake
# Runs the emulator image with the instruction-counting plugin and prints
#   instructions_per_update=<n> profile=<name> ...
# = instructions executed inside agent_plan() calls (with the markers' own few) / planning updates.
include(${CMAKE_CURRENT_LIST_DIR}/match_or_fail.cmake)
execute_process(COMMAND ${NM} ${ELF} OUTPUT_VARIABLE syms RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${NM} ${ELF} failed")
endif()
set(args "")
foreach(mark begin end report)
    match_or_fail("${syms}" "([0-9a-fA-F]+) T bench_mark_${mark}\n" "no symbol bench_mark_${mark} in ${ELF}" address)
    string(APPEND args ",${mark}=0x${address}")
endforeach()
execute_process(
    COMMAND ${TIMEOUT} 600 ${QEMU} -M mps2-an386 -display none -chardev stdio,id=sh0
        -semihosting-config enable=on,target=native,chardev=sh0
        -plugin ${PLUGIN}${args},top=1000 -kernel ${ELF}
    OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
message("${out}")
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "the emulator image exited with ${rc}")
endif()
match_or_fail("${err}" "insn_count=([0-9]+) windows=([0-9]+) max_window=([0-9]+)" "the plugin printed no count"
              insns windows max_window)
match_or_fail("${out}" "planning_updates=([0-9]+)" "the image printed no planning_updates" updates)
if(updates EQUAL 0)
    message(FATAL_ERROR "no planning updates")
endif()
math(EXPR per_update "(${insns} + ${updates} / 2) / ${updates}")
math(EXPR per_call "(${insns} + ${windows} / 2) / ${windows}")
message("instructions_per_update=${per_update} profile=${PROFILE} cpu=cortex-m4 "
        "instructions_per_plan_call=${per_call} worst_plan_call=${max_window} (QEMU TCG plugin: ${insns} instructions in "
        "${windows} agent_plan calls, which made ${updates} planning updates; calls that found "
        "nothing to plan on are counted too, as in tests/bench)")

# Hot spots: the counted instructions by function (the plugin's 1000 hottest blocks, mapped
# through the symbol table).
execute_process(COMMAND ${NM} -n ${ELF} OUTPUT_VARIABLE sorted)
string(REGEX MATCHALL "[0-9a-f]+ [Tt] [A-Za-z0-9_.]+" fsyms "${sorted}")
string(REGEX MATCHALL "hot pc=0x[0-9a-f]+ insns=[0-9]+" hot "${err}")
set(functions "")
foreach(h ${hot})
    string(REGEX MATCH "pc=0x([0-9a-f]+) insns=([0-9]+)" _ "${h}")
    math(EXPR pc "0x${CMAKE_MATCH_1}")
    set(n ${CMAKE_MATCH_2})
    set(owner "?")
    foreach(sym ${fsyms})
        string(REGEX MATCH "([0-9a-f]+) [Tt] (.+)" _ "${sym}")
        math(EXPR a "0x${CMAKE_MATCH_1}")
        if(a GREATER pc)
            break()
        endif()
        set(owner ${CMAKE_MATCH_2})
    endforeach()
    if(NOT DEFINED total_${owner})
        set(total_${owner} 0)
        list(APPEND functions ${owner})
    endif()
    math(EXPR total_${owner} "${total_${owner}} + ${n}")
endforeach()
set(rows "")
foreach(f ${functions})
    math(EXPR share "100 * ${total_${f}} / ${insns}")
    math(EXPR per "(${total_${f}} + ${updates} / 2) / ${updates}")
    string(LENGTH "${total_${f}}" len)
    math(EXPR pad "12 - ${len}")
    string(REPEAT "0" ${pad} zeros)
    list(APPEND rows "${zeros}${total_${f}} ${f} ${share}% ${per}/update")
endforeach()
list(SORT rows COMPARE NATURAL ORDER DESCENDING)
message("hot spots (${PROFILE}; by function, top 12: instructions, share, per update):")
list(SUBLIST rows 0 12 rows)
foreach(r ${rows})
    string(REGEX REPLACE "^0*([0-9]+) " "  \\1 " r "${r}")
    message("${r}")
endforeach()
