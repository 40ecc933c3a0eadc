# SPDX-License-Identifier: MIT
# cmake -DSOURCE=<repo> -DPORT=<port> [-DBOARD=<board>] -DTOOLCHAIN=<file> -DWORK=<dir> -P port_alone.cmake
# Configures and builds the firmware with DYNAQPC_PORT=<port> (and DYNAQPC_BOARD=<board>, one
# board of the port's family) alone, in a build folder of its own: a port or a board must need no
# other port's or board's pieces (linker scripts, startup, libraries). Prints
# "<port>[/<board>] builds alone" on success.
foreach(v SOURCE PORT TOOLCHAIN WORK)
    if(NOT DEFINED ${v})
        message(FATAL_ERROR "port_alone.cmake: -D${v}= missing")
    endif()
endforeach()
set(what ${PORT})
set(board_arg "")
if(BOARD)
    set(what ${PORT}/${BOARD})
    set(board_arg -DDYNAQPC_BOARD=${BOARD})
endif()
file(REMOVE_RECURSE "${WORK}")
execute_process(
    COMMAND ${CMAKE_COMMAND} -S "${SOURCE}" -B "${WORK}" -G Ninja
        -DCMAKE_TOOLCHAIN_FILE=${TOOLCHAIN} -DCMAKE_BUILD_TYPE=MinSizeRel -DDYNAQPC_PORT=${PORT}
        ${board_arg} -DDYNAQPC_EMU_BOARD=OFF
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "DYNAQPC_PORT=${what}: configure failed (${rc})\n${out}\n${err}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build "${WORK}" -j 2
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "DYNAQPC_PORT=${what}: build failed (${rc})\n${out}\n${err}")
endif()
message("${what} builds alone")
