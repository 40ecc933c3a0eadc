# SPDX-License-Identifier: MIT
# cmake -DSIM=<dynaqpc-sim> -DWORK=<scratch dir> -DROOMS=<host_sim/rooms> -P check_rooms_train.cmake
# Every committed room is accepted by train as well as by the parser (train also applies the
# firmware's limits and robot_config_check): one short episode each, a CSV row each. The far-goal
# rooms of far-tune/ and far-eval/ with Dyna-QPC, whose model's tables are the ones a larger floor
# can overflow (docs/scenarios.md, "Far-goal rooms"; far-large-*/, on the paper-sim-large profile, are not here: hours a set).
cmake_minimum_required(VERSION 3.25)
include(${CMAKE_CURRENT_LIST_DIR}/sim_common.cmake)
file(GLOB rooms "${ROOMS}/tune/*.scn" "${ROOMS}/eval/*.scn")
file(GLOB far_rooms "${ROOMS}/far-tune/*.scn" "${ROOMS}/far-eval/*.scn")
list(LENGTH rooms n)
list(LENGTH far_rooms n_far)
if(n LESS 40 OR n_far LESS 48)
    message(FATAL_ERROR "only ${n} rooms and ${n_far} far-goal rooms under ${ROOMS}")
endif()
foreach(room ${rooms} ${far_rooms})
    set(agent q)
    if(room IN_LIST far_rooms)
        set(agent dyna-qpc)
    endif()
    execute_process(COMMAND "${SIM}" train --scenario "${room}" --agent ${agent} --sets 1 --episodes 1 --step-cap 3
            --quiet --csv "${WORK}/out.csv"
        RESULT_VARIABLE rc ERROR_VARIABLE err TIMEOUT 60)
    if(NOT rc EQUAL 0)
        message(FATAL_ERROR "train --scenario ${room}: exit ${rc}\n${err}")
    endif()
    file(STRINGS "${WORK}/out.csv" lines)
    list(LENGTH lines k)
    if(NOT k EQUAL 2)
        message(FATAL_ERROR "train --scenario ${room}: ${k} CSV lines, expected 2")
    endif()
endforeach()
message(STATUS "train accepts all ${n} rooms and ${n_far} far-goal rooms")
