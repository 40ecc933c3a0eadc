# SPDX-License-Identifier: MIT
# How an image links on the STM32F4 family, whichever the board (included by the family's
# CMakeLists.txt; the images themselves are defined under targets/).
#
# dynaqpc_image(<name> SCRIPT <ld> RAM <bytes> FLASH <bytes> STACK <bytes>
#               SOURCES ... LIBS ... [DEFINES ...])
# Links <name>.elf with the family's startup and the linker script SCRIPT: a board's memory map
# (an absolute path: boards/<board>/*.ld, or an emulator's under targets/) that INCLUDEs the
# family's ld/sections.ld (and ld/store.ld when it has a hal_flash region). Prints its size
# against the budgets after each build and registers the test cortex-m4.size.<name>.
# Another port provides a function of the same name and signature in its own folder.
function(dynaqpc_image name)
    cmake_parse_arguments(ARG "" "SCRIPT;RAM;FLASH;STACK" "SOURCES;LIBS;DEFINES" ${ARGN})
    add_executable(${name}.elf ${ARG_SOURCES} $<TARGET_OBJECTS:dynaqpc_stm32f4_startup>)
    target_link_libraries(${name}.elf PRIVATE ${ARG_LIBS} dynaqpc_c_flags)
    target_compile_definitions(${name}.elf PRIVATE ${ARG_DEFINES})
    set(ld_dir ${DYNAQPC_STM32F4_DIR}/ld)
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
    set_target_properties(${name}.elf PROPERTIES
        LINK_DEPENDS "${script};${ld_dir}/sections.ld;${ld_dir}/store.ld")
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

# dynaqpc_image_binaries(<name>): <name>.bin and <name>.hex beside <name>.elf, for flashing.
function(dynaqpc_image_binaries name)
    add_custom_command(TARGET ${name}.elf POST_BUILD
        COMMAND ${CMAKE_OBJCOPY} -O binary $<TARGET_FILE:${name}.elf>
            $<TARGET_FILE_DIR:${name}.elf>/${name}.bin
        COMMAND ${CMAKE_OBJCOPY} -O ihex $<TARGET_FILE:${name}.elf>
            $<TARGET_FILE_DIR:${name}.elf>/${name}.hex
        VERBATIM)
endfunction()
