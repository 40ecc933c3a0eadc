# SPDX-License-Identifier: MIT
# cmake -DNM=<nm> -DFILES=<a;b> -P check_no_allocator.cmake
# Fails if any of FILES defines or references an allocator symbol.
set(forbidden malloc free calloc realloc _sbrk _malloc_r _free_r _calloc_r _realloc_r)
foreach(file ${FILES})
    execute_process(COMMAND ${NM} ${file} OUTPUT_VARIABLE syms RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
        message(FATAL_ERROR "${NM} ${file} failed")
    endif()
    foreach(sym ${forbidden})
        if(syms MATCHES "[ \t][UTtWw] ${sym}\n")
            message(FATAL_ERROR "${file} defines or references ${sym}: the firmware must not allocate")
        endif()
    endforeach()
    string(REGEX MATCHALL "\n[^\n]*:\n" objects "\n${syms}")
    list(LENGTH objects n_objects)
    message(STATUS "${file}: ${n_objects} objects, no allocator symbol")
endforeach()
