# tests/header_deps.cmake — the include-dependency rules of the library's layers (pay
# only for what you include). The layers, bottom up (docs/ARCHITECTURE.md, "Layers"):
#     core < brdf, sampling, env < sh, batch < runtime < bake < reference
# For each layer header and each header under a layer folder, the compiler's dependency list
# (-M: every file the preprocessor opens) must contain only ibl headers under the allowed
# prefixes: a layer that starts including a higher one (runtime/ pulling in a baker, bake/ pulling
# in a reference, sh/ pulling in prefilter code) fails this test. Finer rules inside a layer:
#
#   ibl/sh.hpp               core/ sh/ env/cube_geometry.hpp (no batch/ or prefilter code)
#   runtime/shade.hpp        core/ brdf/           (takes products as values, reads no table code)
#   runtime/lookup.hpp       core/ brdf/ env/ runtime/ (no integrator, no table builder)
#   bake/plan.hpp            core/ runtime/roughness_mip.hpp bake/plan_tables.hpp (the plan is
#                            arithmetic on its measured data, no integrator)
#   bake/plan_tables.hpp     core/ (data only: the tables research/plan_measure.cpp writes)
#   batch/**.hpp             core/ brdf/ sampling/ env/ batch/ (kernels; never bake/, which calls them)
#
# Research (the top-level research/ folder: studies, baselines, tuning programs) is never
# included by an installed header: every file under include/ibl is scanned for an #include
# that names research/.
#
# A header field with a '*' is a glob (relative to include/ibl, recursive): each match is checked.
# usage: cmake -DCXX=<compiler> -DINCLUDE_DIR=<repo>/include -DGLM_INCLUDE=<dirs;...>
#              -DWORK_DIR=<scratch dir> -P header_deps.cmake
cmake_minimum_required(VERSION 3.21)

set(rules
    "core.hpp|core/"
    "core/*.hpp|core/"
    "brdf.hpp|core/ brdf/"
    "sampling.hpp|core/ brdf/ sampling/"
    "env.hpp|core/ env/"
    "sh.hpp|core/ sh/ env/cube_geometry.hpp"
    "batch.hpp|core/ brdf/ sampling/ env/ batch/"
    "batch/*.hpp|core/ brdf/ sampling/ env/ batch/"
    "runtime.hpp|core/ brdf/ sampling/ env/ sh/ batch/ runtime/"
    "runtime/*.hpp|core/ brdf/ sampling/ env/ sh/ batch/ runtime/"
    "runtime/shade.hpp|core/ brdf/"
    "runtime/lookup.hpp|core/ brdf/ env/ runtime/"
    "bake.hpp|core/ brdf/ sampling/ env/ sh/ batch/ runtime/ bake/"
    "bake/*.hpp|core/ brdf/ sampling/ env/ sh/ batch/ runtime/ bake/"
    "bake/plan.hpp|core/ runtime/roughness_mip.hpp bake/plan_tables.hpp"
    "bake/plan_tables.hpp|core/"
    "reference.hpp|core/ brdf/ sampling/ env/ sh/ batch/ runtime/ bake/ reference/"
    "reference/*.hpp|core/ brdf/ sampling/ env/ sh/ batch/ runtime/ bake/ reference/")

# No installed header includes research/.
file(GLOB_RECURSE installed RELATIVE ${INCLUDE_DIR} ${INCLUDE_DIR}/ibl/*)
set(research_failed 0)
foreach(f IN LISTS installed)
    file(STRINGS ${INCLUDE_DIR}/${f} hits REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"].*research")
    if(hits)
        message(SEND_ERROR "${f} includes research code: ${hits}")
        set(research_failed 1)
    endif()
endforeach()

file(MAKE_DIRECTORY ${WORK_DIR})
file(REAL_PATH ${INCLUDE_DIR}/ibl IBL_DIR)
set(glm_flags "")
foreach(d IN LISTS GLM_INCLUDE)
    if(d)
        list(APPEND glm_flags "-I${d}")
    endif()
endforeach()
set(failed ${research_failed})
set(expanded "")
foreach(rule IN LISTS rules)
    string(REPLACE "|" ";" parts "${rule}")
    list(GET parts 0 pattern)
    list(GET parts 1 allowed)
    if(pattern MATCHES "\\*")
        file(GLOB_RECURSE matches RELATIVE ${IBL_DIR} ${IBL_DIR}/${pattern})
        if(NOT matches)
            message(SEND_ERROR "${pattern}: no header matches (the check is broken)")
            set(failed 1)
        endif()
        list(SORT matches)
        foreach(m IN LISTS matches)
            list(APPEND expanded "${m}|${allowed}")
        endforeach()
    else()
        list(APPEND expanded "${rule}")
    endif()
endforeach()
foreach(rule IN LISTS expanded)
    string(REPLACE "|" ";" parts "${rule}")
    list(GET parts 0 header)
    list(GET parts 1 allowed)
    string(REPLACE " " ";" allowed "${allowed}")
    string(MAKE_C_IDENTIFIER ${header} id)
    set(tu ${WORK_DIR}/${id}.cpp)
    file(WRITE ${tu} "#include <ibl/${header}>\n")
    execute_process(COMMAND ${CXX} -std=c++20 -I${INCLUDE_DIR} ${glm_flags} -M ${tu}
                    OUTPUT_VARIABLE deps ERROR_VARIABLE err RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
        message(SEND_ERROR "ibl/${header}: preprocessing failed:\n${err}")
        set(failed 1)
        continue()
    endif()
    string(REPLACE "\\\n" " " deps "${deps}")
    string(REGEX REPLACE "[ \t\r\n]+" ";" deps "${deps}")
    set(bad "")
    set(seen 0)
    foreach(dep IN LISTS deps)
        if(NOT dep MATCHES "\\.(hpp|h)$")
            continue()
        endif()
        file(REAL_PATH ${dep} real)
        string(FIND "${real}" "${IBL_DIR}/" pos)
        if(NOT pos EQUAL 0)
            continue() # not an ibl header (GLM, the standard library)
        endif()
        string(LENGTH "${IBL_DIR}/" plen)
        string(SUBSTRING "${real}" ${plen} -1 rel)
        math(EXPR seen "${seen} + 1")
        if(rel STREQUAL header)
            continue()
        endif()
        set(ok 0)
        foreach(prefix IN LISTS allowed)
            string(FIND "${rel}" "${prefix}" p)
            if(p EQUAL 0)
                set(ok 1)
            endif()
        endforeach()
        if(NOT ok)
            list(APPEND bad ${rel})
        endif()
    endforeach()
    if(seen EQUAL 0)
        message(SEND_ERROR "ibl/${header}: no ibl header in the dependency list (the check is broken)")
        set(failed 1)
    elseif(bad)
        list(REMOVE_DUPLICATES bad)
        message(SEND_ERROR "ibl/${header} may include only [${allowed}] but pulls in: ${bad}")
        set(failed 1)
    else()
        message(STATUS "ibl/${header}: ${seen} ibl headers, all within [${allowed}]")
    endif()
endforeach()
if(failed)
    message(FATAL_ERROR "header dependency rules violated")
endif()
