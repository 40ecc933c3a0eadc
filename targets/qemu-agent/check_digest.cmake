# SPDX-License-Identifier: MIT
# cmake "-DQEMU=<command;args>" -DELF=<image.elf> -DHOST=<host program> -P check_digest.cmake
# Runs the emulator image and the host build of the same program; passes (printing "host = MCU")
# when both learned (result=learned) and printed the same digest= of what they learned.
function(run_one what)
    execute_process(COMMAND ${ARGN} OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
    message("--- ${what}\n${out}${err}")
    if(NOT rc EQUAL 0 OR NOT out MATCHES "result=learned")
        message(FATAL_ERROR "${what} did not learn (exit ${rc})")
    endif()
    if(NOT out MATCHES "digest=([0-9]+)")
        message(FATAL_ERROR "${what} printed no digest")
    endif()
    set(digest_${what} ${CMAKE_MATCH_1} PARENT_SCOPE)
endfunction()

run_one(mcu ${QEMU} -kernel ${ELF})
run_one(host ${HOST})
if(NOT digest_mcu STREQUAL digest_host)
    message(FATAL_ERROR "the MCU learned digest=${digest_mcu}, the host digest=${digest_host}")
endif()
message("digest=${digest_mcu}: host = MCU")
