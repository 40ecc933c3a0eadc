# SPDX-License-Identifier: MIT
# The simulated robot's devices for the emulated board's closed loop: dynaqpc-sim, built for the
# host from this source tree (Release, no tests) in <build>/host-sim. Sets DYNAQPC_EMU_SIM.
include(ExternalProject)
set(emu_host_dir ${CMAKE_BINARY_DIR}/host-sim)
if(NOT TARGET dynaqpc_emu_host_sim)
    ExternalProject_Add(dynaqpc_emu_host_sim
        SOURCE_DIR ${PROJECT_SOURCE_DIR}
        BINARY_DIR ${emu_host_dir}
        CMAKE_ARGS -DCMAKE_BUILD_TYPE=Release -DDYNAQPC_BUILD_TESTS=OFF -DDYNAQPC_BUILD_SIM=ON
        BUILD_COMMAND ${CMAKE_COMMAND} --build ${emu_host_dir} --target dynaqpc-sim
        INSTALL_COMMAND ""
        BUILD_ALWAYS ON)
endif()
set(DYNAQPC_EMU_SIM ${emu_host_dir}/bin/dynaqpc-sim)
