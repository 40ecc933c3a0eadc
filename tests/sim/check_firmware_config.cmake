# SPDX-License-Identifier: MIT
# cmake -DSIM=<dynaqpc-sim> -DWORK=<dir> -DCOMMITTED=<robot_scenarios.c> -P check_firmware_config.cmake
# Fails when the committed built-in scenarios differ from what `dynaqpc-sim firmware-config`
# writes from host_sim/scenarios/*.scn (regenerate with --out <COMMITTED>).
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${SIM} firmware-config --out ${WORK}/robot_scenarios.c RESULT_VARIABLE rc
    ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "firmware-config exited ${rc}: ${err}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/robot_scenarios.c ${COMMITTED}
    RESULT_VARIABLE differ)
if(NOT differ EQUAL 0)
    message(FATAL_ERROR "${COMMITTED} is not what the scenario files give: run\n"
        "  dynaqpc-sim firmware-config --out ${COMMITTED}")
endif()
message("up to date")
