# SPDX-License-Identifier: MIT
# The emulated board's tests, with the image at DYNAQPC_EMU_ELF (set by the includer: this port's
# own build, or the cortex-m4 preset's build of it, targets/CMakeLists.txt). Needs DYNAQPC_EMU_SIM,
# a host dynaqpc-sim, for the closed loop.
#   cortex-m4.emu.boot         QEMU alone, 3 s of firmware time: the image starts, its scheduler runs
#                              the control task, no fault, no miss, a final report (exit 0). The
#                              clock is QEMU's instruction count alone (-icount sleep=off: idle
#                              time is skipped), so the run is the same on a loaded machine
#   cortex-m4.emu.closed_loop  QEMU + dynaqpc-sim devices + the SLCAN bridge in a private network
#                              namespace (closed_loop.sh): fails on no frame, no planning update,
#                              a deadline miss, a hard fault, or no finished episode. Skipped
#                              (77) without the project's venv (tools/dev.sh setup).
#   cortex-m4.emu.closed_loop_idle_planning  the same with Dyna-Q: fails unless the idle loop
#                              made at least 1,000 planning updates
#   cortex-m4.emu.closed_loop_real  the same on the realistic robot (scenario paper-lab-real: wheels
#                              that do not match, motor noise and deadband, slip, a gyro scale
#                              error, Cricket dropouts and outliers), the board closing its motions
find_program(DYNAQPC_QEMU NAMES qemu-system-arm)
find_program(DYNAQPC_TIMEOUT NAMES timeout)
if(NOT DYNAQPC_QEMU OR NOT DYNAQPC_TIMEOUT)
    return()
endif()
add_test(NAME cortex-m4.emu.boot
    COMMAND ${DYNAQPC_TIMEOUT} 60 ${DYNAQPC_QEMU} -icount shift=3,sleep=off -M netduinoplus2 -display none -monitor none
        -chardev stdio,id=sh0 -semihosting-config enable=on,target=native,chardev=sh0
        -serial null -serial null -kernel ${DYNAQPC_EMU_ELF} -append "duration_s=3 report_s=1")
set_tests_properties(cortex-m4.emu.boot PROPERTIES
    PASS_REGULAR_EXPRESSION "final: .*control_runs=1[5-7] .*misses=0 "
    FAIL_REGULAR_EXPRESSION "HARD FAULT|UNEXPECTED")
add_test(NAME cortex-m4.emu.closed_loop
    COMMAND ${CMAKE_CURRENT_LIST_DIR}/closed_loop.sh ${DYNAQPC_EMU_ELF} ${DYNAQPC_EMU_SIM} ${PROJECT_SOURCE_DIR})
# The idle hand-off itself: Dyna-Q's table never runs dry, so the idle loop must plan (Dyna-QPC's
# 64 updates before acting usually empty its queue in a short run; docs/realtime.md).
add_test(NAME cortex-m4.emu.closed_loop_idle_planning
    COMMAND ${CMAKE_CURRENT_LIST_DIR}/closed_loop.sh ${DYNAQPC_EMU_ELF} ${DYNAQPC_EMU_SIM} ${PROJECT_SOURCE_DIR}
        --agent dyna-q --min-idle-loop-updates 1000)
add_test(NAME cortex-m4.emu.closed_loop_real
    COMMAND ${CMAKE_CURRENT_LIST_DIR}/closed_loop.sh ${DYNAQPC_EMU_ELF} ${DYNAQPC_EMU_SIM} ${PROJECT_SOURCE_DIR}
        --scenario paper-lab-real)
set_tests_properties(cortex-m4.emu.closed_loop cortex-m4.emu.closed_loop_idle_planning cortex-m4.emu.closed_loop_real PROPERTIES
    SKIP_RETURN_CODE 77 TIMEOUT 180 RESOURCE_LOCK emu_cpu)
