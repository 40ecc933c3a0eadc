# SPDX-License-Identifier: MIT
# cmake -DSIM=<dynaqpc-sim> -DWORK=<scratch dir> -P check_run_model.cmake
# An image learned with the paper's model (train --model paper) replays with run --model paper,
# and is refused, in one line and exit 2, under our model: the two models save other tables.
cmake_minimum_required(VERSION 3.25)
include(${CMAKE_CURRENT_LIST_DIR}/sim_common.cmake)
set(image "${WORK}/paper.flash")

sim(train --scenario paper-lab --agent dyna-qpc --model paper --sets 1 --episodes 3 --planning 5 --seed 5
    --quiet --save "${image}")
sim(run --scenario paper-lab --model paper --load "${image}" --starts 2 --seed 2)
if(NOT err MATCHES "\\(frozen\\): reached the goal from [0-2] of 2 starts")
    message(FATAL_ERROR "replay with --model paper: unexpected report: ${err}")
endif()
execute_process(COMMAND "${SIM}" run --scenario paper-lab --load "${image}" --starts 2
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
if(NOT rc EQUAL 2 OR NOT err MATCHES "^[^\n]*--load: [^\n]*holds no record this firmware can restore[^\n]*\n$")
    message(FATAL_ERROR "replay under our model: exit ${rc}, expected 2 and one line: ${err}")
endif()
message(STATUS "the paper's image replays with --model paper and is refused without it")
