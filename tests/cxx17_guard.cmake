# tests/cxx17_guard.cmake — a pre-C++20 build of any public header stops with one clear message.
# For each header, a translation unit that includes it is compiled with -std=c++17: the compile
# must fail, its output must carry config.hpp's #error ("ibl requires C++20"), and that must be
# the only diagnostic (exactly one line with "error:"; the compiler's echo of the source line and
# clang's "1 error generated." summary have no colon after "error").
#
# usage: cmake -DCXX=<compiler> -DINCLUDE_DIR=<repo>/include -DGLM_INCLUDE=<dirs;...>
#              -DHEADERS_FILE=<file: one header a line, relative to INCLUDE_DIR> | -DHEADER=<header>
#              -DWORK_DIR=<scratch dir> -P cxx17_guard.cmake
cmake_minimum_required(VERSION 3.21)

if(DEFINED HEADERS_FILE)
    file(STRINGS ${HEADERS_FILE} headers)
else()
    set(headers ${HEADER})
endif()
list(LENGTH headers count)
if(count EQUAL 0)
    message(FATAL_ERROR "cxx17_guard: no headers to check")
endif()

file(MAKE_DIRECTORY ${WORK_DIR})
set(glm_flags "")
foreach(d IN LISTS GLM_INCLUDE)
    if(d)
        list(APPEND glm_flags "-I${d}")
    endif()
endforeach()

set(failed 0)
foreach(header IN LISTS headers)
    string(MAKE_C_IDENTIFIER ${header} id)
    set(tu ${WORK_DIR}/${id}.cpp)
    file(WRITE ${tu} "#include <${header}>\nint main() { return 0; }\n")
    execute_process(COMMAND ${CXX} -std=c++17 -fsyntax-only -I${INCLUDE_DIR} ${glm_flags} ${tu}
                    OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
    string(APPEND out "${err}")
    string(REGEX MATCHALL "[^\n]*error:[^\n]*" errors "${out}")
    list(LENGTH errors n_errors)
    if(rc EQUAL 0)
        message(SEND_ERROR "${header}: compiled under -std=c++17 (the C++20 guard did not fire)")
        set(failed 1)
    elseif(NOT out MATCHES "ibl requires C\\+\\+20")
        message(SEND_ERROR "${header}: -std=c++17 fails without the C++20 message:\n${out}")
        set(failed 1)
    elseif(NOT n_errors EQUAL 1)
        message(SEND_ERROR "${header}: ${n_errors} errors under -std=c++17, expected only the C++20 one:\n${out}")
        set(failed 1)
    endif()
endforeach()
if(failed)
    message(FATAL_ERROR "cxx17_guard: some headers do not stop with the one C++20 error")
endif()
message(STATUS "cxx17_guard: ${count} header(s) stop under -std=c++17 with exactly the C++20 #error")
