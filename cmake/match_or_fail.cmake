# SPDX-License-Identifier: MIT
# For the -P scripts that read a tool's output (size_report.cmake, bench_insn.cmake):
#   match_or_fail(<text> <regex> <why> <var>...)
# sets each <var>, in the caller, to the next group <regex> captured in <text>, in order; a text
# that does not match stops the script with <why>.
function(match_or_fail text regex why)
    if(NOT text MATCHES "${regex}")
        message(FATAL_ERROR "${why}")
    endif()
    set(group 1)
    foreach(var IN LISTS ARGN)
        set(${var} "${CMAKE_MATCH_${group}}" PARENT_SCOPE)
        math(EXPR group "${group} + 1")
    endforeach()
endfunction()
