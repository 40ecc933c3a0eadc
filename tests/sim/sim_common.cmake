# SPDX-License-Identifier: MIT
# What the check_*.cmake scripts share: include(${CMAKE_CURRENT_LIST_DIR}/sim_common.cmake) after
# -DSIM=<dynaqpc-sim> -DWORK=<scratch dir>. The scratch directory starts empty.
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

# sim(<args>...): runs dynaqpc-sim, fails the test unless it exits 0; sets `out` and `err`.
function(sim)
    execute_process(COMMAND "${SIM}" ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
        TIMEOUT 300)
    if(NOT rc EQUAL 0)
        message(FATAL_ERROR "dynaqpc-sim ${ARGN}: exit ${rc}\n${err}")
    endif()
    set(out "${out}" PARENT_SCOPE)
    set(err "${err}" PARENT_SCOPE)
endfunction()
