# SPDX-License-Identifier: MIT
# cmake -DSIM=<dynaqpc-sim> -DWORK=<scratch dir> -P check_run_learn.cmake
# A trained image replayed frozen and with --learn: the frozen replay updates nothing, the learning
# one does, and the image file is byte-for-byte what train --save wrote (a replay never writes
# it). The arena file carries paper-lab's two goal cells.
cmake_minimum_required(VERSION 3.25)
include(${CMAKE_CURRENT_LIST_DIR}/sim_common.cmake)
set(image "${WORK}/lab.flash")

sim(train --scenario paper-lab --agent dyna-qpc --sets 1 --episodes 4 --seed 5 --quiet --save "${image}")
file(SHA256 "${image}" trained)
sim(run --scenario paper-lab --load "${image}" --starts 3 --seed 2 --arena "${WORK}/arena.json")
file(READ "${WORK}/arena.json" arena)
if(NOT arena MATCHES "\"cells\":\\[\\[3\\.225,2\\.4,3\\.7625,2\\.8\\],\\[3\\.7625,2\\.4,4\\.3,2\\.8\\]\\]")
    message(FATAL_ERROR "arena JSON without paper-lab's goal cells: ${arena}")
endif()
if(NOT err MATCHES "\\(frozen\\): reached the goal from [0-3] of 3 starts.*; Q updates 0\n")
    message(FATAL_ERROR "frozen replay: unexpected report: ${err}")
endif()
sim(run --scenario paper-lab --load "${image}" --starts 3 --seed 2 --learn --planning 0)
if(NOT err MATCHES "\\(learning\\): reached the goal from [0-3] of 3 starts.*; Q updates [1-9][0-9]*\n")
    message(FATAL_ERROR "learning replay: unexpected report: ${err}")
endif()
string(REGEX MATCHALL "\n[0-9]+,[0-9]+,[01]," rows "\n${out}")
list(LENGTH rows n)
if(NOT n EQUAL 3)
    message(FATAL_ERROR "learning replay: ${n} result rows, not 3:\n${out}")
endif()
file(SHA256 "${image}" after)
if(NOT trained STREQUAL after)
    message(FATAL_ERROR "the replays changed ${image}")
endif()
message(STATUS "both replays ran; ${image} unchanged (${after})")
