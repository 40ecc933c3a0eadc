# SPDX-License-Identifier: MIT
# cmake -DSIM=<dynaqpc-sim> -DROOMS=<host_sim/rooms> -DWORK=<scratch dir> -P check_run_step_cap.cmake
# A frozen sonar robot whose goal is closed off bumps to the step cap: an episode of 5,000 steps
# across paper-sim's fitted 0.6 m cells, hundreds of them bumps and back-offs. The run ends that
# episode at the cap and goes on; the host's bound on an episode's robot time (a hang check) once
# counted a step as action_periods alone and stopped the run with an error. (The room with two of
# the ring's gaps closed did it once; the replay now leaves its loops there and finds a way.)
cmake_minimum_required(VERSION 3.25)
include(${CMAKE_CURRENT_LIST_DIR}/sim_common.cmake)
set(image "${WORK}/sim.flash")

sim(train --scenario paper-sim --agent dyna-qpc --planning 1000 --sets 1 --episodes 19 --seed 9104 --quiet
    --save "${image}")
sim(run --scenario "${CMAKE_CURRENT_LIST_DIR}/rooms/paper-sim-closed.scn" --load "${image}" --starts 2 --seed 7)
if(NOT out MATCHES "\n1,5000,0,[1-9][0-9][0-9]+,[0-9.]+\n2,5000,0,[1-9][0-9][0-9]+,[0-9.]+\n")
    message(FATAL_ERROR "expected both starts to run to the 5,000-step cap, bumping hundreds of times:\n${out}")
endif()
message(STATUS "both starts ran to the step cap and the run ended normally")
