# SPDX-License-Identifier: MIT
# cmake -DSIM=<dynaqpc-sim> -DWORK=<scratch dir> -DCHANGES=<host_sim/rooms/changes> -P check_change.cmake
# Rooms that change (docs/scenarios.md): `--change-at K --changed FILE`.
#  1. Before episode K nothing changes: the first K-1 rows are those of a run without a change.
#  2. From K on the world is FILE's: --change-at 1 gives byte for byte the run in FILE (train and
#     run --learn).
#  3. A change that blocks the learned path (paper-lab-box: a box in the passage north of the
#     partition): robots trained 19 episodes in paper-lab and then driven greedily in the changed
#     room from 40 starts each while still learning reach the goal from >= 95 % of all starts; the
#     same images frozen reach it from fewer (the change does block what they learned).
# Behaviour, not wall-clock: each run is a few seconds.
cmake_minimum_required(VERSION 3.25)
include(${CMAKE_CURRENT_LIST_DIR}/sim_common.cmake)
set(box "${CHANGES}/paper-lab-box.scn")

# 1. Nothing changes before K.
sim(train --scenario paper-lab --agent dyna-qpc --sets 1 --episodes 5 --seed 4 --no-wall-time --quiet --csv -)
set(plain "${out}")
sim(train --scenario paper-lab --agent dyna-qpc --sets 1 --episodes 5 --seed 4 --no-wall-time --quiet --csv -
    --changed "${box}" --change-at 4)
set(changed "${out}")
string(REGEX MATCH "^[^\n]*\n[^\n]*\n[^\n]*\n[^\n]*\n" plain_head "${plain}")
string(REGEX MATCH "^[^\n]*\n[^\n]*\n[^\n]*\n[^\n]*\n" changed_head "${changed}")
if(NOT plain_head STREQUAL changed_head OR plain_head STREQUAL "")
    message(FATAL_ERROR "episodes 1-3 differ with --change-at 4:\n${plain}\n---\n${changed}")
endif()

# 2. From K on the room is the changed file's.
sim(train --scenario "${box}" --agent dyna-qpc --sets 1 --episodes 4 --seed 4 --no-wall-time --quiet --csv -)
set(in_box "${out}")
sim(train --scenario paper-lab --agent dyna-qpc --sets 1 --episodes 4 --seed 4 --no-wall-time --quiet --csv -
    --changed "${box}" --change-at 1)
if(NOT out STREQUAL in_box)
    message(FATAL_ERROR "train --change-at 1 is not the run in the changed room:\n${out}\n---\n${in_box}")
endif()

# 3. Recovery after a change that blocks the learned path.
set(learn_reached 0)
set(frozen_reached 0)
set(total 0)
foreach(seed 31 32 33 34 35)
    set(image "${WORK}/lab-${seed}.flash")
    sim(train --scenario paper-lab --agent dyna-qpc --sets 1 --episodes 19 --seed ${seed} --quiet --save "${image}")
    sim(run --scenario paper-lab --load "${image}" --starts 40 --seed 7 --learn --changed "${box}" --change-at 1)
    set(learn_rows "${out}")
    if(seed EQUAL 31)
        sim(run --scenario "${box}" --load "${image}" --starts 40 --seed 7 --learn)
        if(NOT out STREQUAL learn_rows)
            message(FATAL_ERROR "run --change-at 1 is not the replay in the changed room")
        endif()
    endif()
    string(REGEX MATCHALL "\n[0-9]+,[0-9]+,1," hits "\n${learn_rows}")
    list(LENGTH hits n_learn)
    sim(run --scenario "${box}" --load "${image}" --starts 40 --seed 7)
    string(REGEX MATCHALL "\n[0-9]+,[0-9]+,1," hits "\n${out}")
    list(LENGTH hits n_frozen)
    message(STATUS "seed ${seed}: reached the goal from ${n_learn} of 40 starts learning, ${n_frozen} frozen")
    math(EXPR learn_reached "${learn_reached} + ${n_learn}")
    math(EXPR frozen_reached "${frozen_reached} + ${n_frozen}")
    math(EXPR total "${total} + 40")
endforeach()
math(EXPR need "(${total} * 95 + 99) / 100")
message(STATUS "after the box: learning ${learn_reached} of ${total} starts reached the goal (need ${need}), frozen ${frozen_reached}")
if(learn_reached LESS need)
    message(FATAL_ERROR "the learning robot reached the goal from ${learn_reached} of ${total} starts after the change, fewer than 95 %")
endif()
if(NOT frozen_reached LESS learn_reached)
    message(FATAL_ERROR "frozen ${frozen_reached} >= learning ${learn_reached}: the change did not block what was learned")
endif()
