# SPDX-License-Identifier: MIT
# The host port's virtual CAN bus (python-can udp_multicast wire format) and pty serial line.
# Included from hal/ports/host/CMakeLists.txt. POSIX C99; no heap.
add_library(dynaqpc_vcan STATIC
    ${CMAKE_CURRENT_LIST_DIR}/vcan.c
    ${CMAKE_CURRENT_LIST_DIR}/pty.c)
target_include_directories(dynaqpc_vcan PUBLIC ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(dynaqpc_vcan PUBLIC dynaqpc_hal PRIVATE dynaqpc_c_flags m)
