# SPDX-License-Identifier: MIT
# cmake -DSIM=<dynaqpc-sim> -DWORK=<scratch dir> -P check_rooms.cmake
# dynaqpc-sim rooms: the same seed writes the same files, byte for byte, into another directory;
# room i does not depend on --count; another seed writes other rooms; and train takes a room by
# its path and learns on it.
cmake_minimum_required(VERSION 3.25)
include(${CMAKE_CURRENT_LIST_DIR}/sim_common.cmake)

foreach(robot paper-lab paper-sim)
    sim(rooms --robot ${robot} --seed 7 --count 3 --out "${WORK}/a")
    sim(rooms --robot ${robot} --seed 7 --count 3 --out "${WORK}/b")
    sim(rooms --robot ${robot} --seed 7 --count 4 --out "${WORK}/c")
    sim(rooms --robot ${robot} --seed 8 --count 3 --out "${WORK}/d")
    if(NOT out MATCHES "^file,walls,obstacles,draw,start_points,longest_path\n[^\n]*,[1-9][0-9]*\n")
        message(FATAL_ERROR "rooms: unexpected header:\n${out}")
    endif()
    foreach(i 001 002 003)
        set(name ${robot}-7-${i}.scn)
        foreach(dir b c)
            execute_process(COMMAND "${CMAKE_COMMAND}" -E compare_files "${WORK}/a/${name}" "${WORK}/${dir}/${name}"
                RESULT_VARIABLE differ)
            if(differ)
                message(FATAL_ERROR "same seed, different ${name} in a/ and ${dir}/")
            endif()
        endforeach()
        file(READ "${WORK}/a/${name}" mine)
        file(READ "${WORK}/d/${robot}-8-${i}.scn" other)
        string(REGEX REPLACE "^([^\n]*\n){4}" "" mine "${mine}")  # the header names the seed
        string(REGEX REPLACE "^([^\n]*\n){4}" "" other "${other}")
        if(mine STREQUAL other)
            message(FATAL_ERROR "seeds 7 and 8 give the same room ${i}")
        endif()
    endforeach()
    file(GLOB made "${WORK}/a/${robot}-*.scn")
    list(LENGTH made n)
    if(NOT n EQUAL 3)
        message(FATAL_ERROR "--count 3 wrote ${n} ${robot} files")
    endif()
endforeach()

# Far-goal rooms: --far mixed gives room i the family (i - 1) mod 4 names, and that room is the
# family's own room i; the same command writes the same bytes; each row ends in a longest path.
sim(rooms --robot paper-sim --far mixed --floor 16x4 --seed 7 --count 4 --out "${WORK}/far_a")
if(NOT out MATCHES "/paper-sim-hall-16x4-7-001\\.scn,[0-9]+,[0-9]+,[0-9]+,[1-9][0-9]*,[1-9][0-9]*\n.*/paper-sim-open-16x4-7-002\\.scn,.*/paper-sim-culdesac-16x4-7-003\\.scn,.*/paper-sim-serpentine-16x4-7-004\\.scn,")
    message(FATAL_ERROR "rooms --far mixed: unexpected rows:\n${out}")
endif()
sim(rooms --robot paper-sim --far mixed --floor 16x4 --seed 7 --count 4 --out "${WORK}/far_b")
sim(rooms --robot paper-sim --far culdesac --floor 16x4 --seed 7 --count 3 --out "${WORK}/far_c")
foreach(pair "far_b/paper-sim-hall-16x4-7-001" "far_b/paper-sim-serpentine-16x4-7-004" "far_c/paper-sim-culdesac-16x4-7-003")
    get_filename_component(name "${pair}" NAME)
    execute_process(COMMAND "${CMAKE_COMMAND}" -E compare_files "${WORK}/far_a/${name}.scn" "${WORK}/${pair}.scn"
        RESULT_VARIABLE differ)
    if(differ)
        message(FATAL_ERROR "far rooms: ${name} differs between far_a/ and ${pair}")
    endif()
endforeach()
file(READ "${WORK}/far_a/paper-sim-culdesac-16x4-7-003.scn" far)
if(NOT far MATCHES "\n# longest_path_actions [1-9][0-9]*: " OR NOT far MATCHES "\narena 16 4 " OR
   NOT far MATCHES "\nencode x 6 y 4 heading 4 sensor 4 ")
    message(FATAL_ERROR "far room: no longest path, arena or encoding line:\n${far}")
endif()
sim(rooms --check "${WORK}/far_a/paper-sim-culdesac-16x4-7-003.scn")
if(NOT out MATCHES "passages ok.*\n[^\n]*: longest path: [1-9][0-9]* actions from the farthest start")
    message(FATAL_ERROR "rooms --check on a far room: unexpected output:\n${out}")
endif()

# A room by its path: trains, and the robot gets to the goal.
sim(train --scenario "${WORK}/a/paper-lab-7-001.scn" --agent dyna-qpc --sets 1 --episodes 3 --seed 2
    --no-wall-time --quiet --csv -)
if(NOT out MATCHES "^agent,set,episode,[^\n]*\ndyna-qpc,1,1,[^\n]*\ndyna-qpc,1,2,[^\n]*\ndyna-qpc,1,3,[^\n]*\n$")
    message(FATAL_ERROR "train on a room: unexpected CSV:\n${out}")
endif()
if(NOT out MATCHES "\ndyna-qpc,1,[123],[0-9]+,-?[0-9]+,1,")
    message(FATAL_ERROR "train on a room: the goal never reached in 3 episodes:\n${out}")
endif()
message(STATUS "rooms are reproducible; train runs on a room")
