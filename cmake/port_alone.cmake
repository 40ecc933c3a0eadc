# SPDX-License-Identifier: MIT
# cmake -DSOURCE=<repo> -DPORT=<port> -DTOOLCHAIN=<file> -DWORK=<dir> -P port_alone.cmake
# Configures and builds the firmware with DYNAQPC_PORT=<port> alone, in a build folder of its own:
# a port must need no other port's pieces (linker scripts, startup, libraries). Prints
# "<port> builds alone" on success.
foreach(v SOURCE PORT TOOLCHAIN WORK)
    if(NOT DEFINED ${v})
        message(FATAL_ERROR "port_alone.cmake: -D${v}= missing")
    endif()
endforeach()
file(REMOVE_RECURSE "${WORK}")
execute_process(
    COMMAND ${CMAKE_COMMAND} -S "${SOURCE}" -B "${WORK}" -G Ninja
        -DCMAKE_TOOLCHAIN_FILE=${TOOLCHAIN} -DCMAKE_BUILD_TYPE=MinSizeRel -DDYNAQPC_PORT=${PORT}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "DYNAQPC_PORT=${PORT}: configure failed (${rc})\n${out}\n${err}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build "${WORK}" -j 2
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "DYNAQPC_PORT=${PORT}: build failed (${rc})\n${out}\n${err}")
endif()
message("${PORT} builds alone")
