# SPDX-License-Identifier: MIT
# How the netduinoplus2 port links an image (the same function and signature as the STM32F4
# port's, hal/ports/stm32f4/image.cmake): <name>.elf with this port's startup and
# ld/netduinoplus2.ld, its size printed against the budgets, and the test cortex-m4.size.<name>.
function(dynaqpc_image name)
    cmake_parse_arguments(ARG "" "SCRIPT;RAM;FLASH;STACK" "SOURCES;LIBS;DEFINES" ${ARGN})
    add_executable(${name}.elf ${ARG_SOURCES} $<TARGET_OBJECTS:dynaqpc_netduinoplus2_startup>)
    target_link_libraries(${name}.elf PRIVATE ${ARG_LIBS} dynaqpc_c_flags)
    target_compile_definitions(${name}.elf PRIVATE ${ARG_DEFINES})
    set(ld_dir ${DYNAQPC_NETDUINOPLUS2_DIR}/ld)
    if(IS_ABSOLUTE "${ARG_SCRIPT}")
        set(script ${ARG_SCRIPT})
    else()
        set(script ${ld_dir}/${ARG_SCRIPT})
    endif()
    target_link_options(${name}.elf PRIVATE
        -nostartfiles --specs=nano.specs
        -L${ld_dir} -T${script}
        -Wl,--defsym=DYNAQPC_STACK_BYTES=${ARG_STACK}
        -Wl,--defsym=DYNAQPC_RAM_BUDGET=${ARG_RAM}
        -Wl,--defsym=DYNAQPC_FLASH_BUDGET=${ARG_FLASH}
        -Wl,-Map=${CMAKE_CURRENT_BINARY_DIR}/${name}.map)
    set_target_properties(${name}.elf PROPERTIES LINK_DEPENDS "${script}")
    set(size_report ${PROJECT_SOURCE_DIR}/cmake/size_report.cmake)
    add_custom_command(TARGET ${name}.elf POST_BUILD
        COMMAND ${CMAKE_COMMAND} -DSIZE=${CMAKE_SIZE} -DELF=$<TARGET_FILE:${name}.elf>
            -DRAM_BUDGET=${ARG_RAM} -DFLASH_BUDGET=${ARG_FLASH} -P ${size_report}
        VERBATIM)
    add_test(NAME cortex-m4.size.${name}
        COMMAND ${CMAKE_COMMAND} -DSIZE=${CMAKE_SIZE} -DELF=$<TARGET_FILE:${name}.elf>
            -DRAM_BUDGET=${ARG_RAM} -DFLASH_BUDGET=${ARG_FLASH} -P ${size_report})
    set_tests_properties(cortex-m4.size.${name} PROPERTIES PASS_REGULAR_EXPRESSION "within budget")
endfunction()
