# Way (b) of docs/extending.md, checked without changing the library: adding a built-in effect
# takes one new file in lib/plumb/model/effects/ and one line in effects/effects.cmake.
#
# A throwaway source tree gets verbatim copies of cmake/PlumbHelpers.cmake, lib/plumb/core,
# lib/plumb/model, lib/plumb/autodiff (the effects' Jet forms, generated from the same list),
# tests/model/effects_test.cc and tests/support/effect_battery.h, plus a
# small top-level project (PROJECT_TEMPLATE_DIR). Then exactly two edits are made:
#   1. EFFECT_FILE is copied into lib/plumb/model/effects/;
#   2. the line `accel_scale_temperature` is added to lib/plumb/model/effects/effects.cmake.
# The tree is configured and built with the library's own CMakeLists.txt of those modules,
# and must then
#   - list the effect in the generated registration list (effect_list.inc);
#   - make it by name from Registry::Global() and parse it in a model spec (builtin_check);
#   - pass the invariant battery of tests/model/effects_test.cc, which iterates over every
#     registered name and so picks the new effect up unchanged.
# Any failing step fails the test.
file(REMOVE_RECURSE ${WORK_DIR})
set(src ${WORK_DIR}/src)
set(bin ${WORK_DIR}/build)

function(step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "step failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  string(REPLACE ";" " " command "${ARGN}")
  message(STATUS "ok: ${command}")
endfunction()

# The library as it is.
file(COPY ${PLUMB_SOURCE_DIR}/cmake/PlumbHelpers.cmake DESTINATION ${src}/cmake)
file(COPY ${PLUMB_SOURCE_DIR}/lib/plumb/core ${PLUMB_SOURCE_DIR}/lib/plumb/model
          ${PLUMB_SOURCE_DIR}/lib/plumb/autodiff
     DESTINATION ${src}/lib/plumb)
file(COPY ${PLUMB_SOURCE_DIR}/tests/model/effects_test.cc DESTINATION ${src}/tests/model)
file(COPY ${PLUMB_SOURCE_DIR}/tests/support/effect_battery.h DESTINATION ${src}/tests/support)
file(COPY ${PROJECT_TEMPLATE_DIR}/CMakeLists.txt ${PROJECT_TEMPLATE_DIR}/builtin_check.cc
     DESTINATION ${src})

# Edit 1: the one new file.
file(COPY ${EFFECT_FILE} DESTINATION ${src}/lib/plumb/model/effects)

# Edit 2: the one new line, before the closing parenthesis of set(PLUMB_EFFECTS ...).
set(list_file ${src}/lib/plumb/model/effects/effects.cmake)
file(STRINGS ${list_file} lines_before)
file(READ ${list_file} text)
string(REGEX MATCHALL "\n\\)" closers "${text}")
list(LENGTH closers n_closers)
if(NOT n_closers EQUAL 1)
  message(FATAL_ERROR "${list_file}: expected one line ')' closing set(PLUMB_EFFECTS ...), "
                      "found ${n_closers}")
endif()
string(REPLACE "\n)" "\n  accel_scale_temperature\n)" text "${text}")
file(WRITE ${list_file} "${text}")
file(STRINGS ${list_file} lines_after)
list(LENGTH lines_before n_before)
list(LENGTH lines_after n_after)
math(EXPR added "${n_after} - ${n_before}")
if(NOT added EQUAL 1)
  message(FATAL_ERROR "${list_file}: the edit added ${added} lines, expected 1")
endif()

# Build the copy with the library's own CMake logic.
set(config_args)
if(CMAKE_CXX_COMPILER)
  list(APPEND config_args -DCMAKE_CXX_COMPILER=${CMAKE_CXX_COMPILER})
endif()
step(${CMAKE_COMMAND} -S ${src} -B ${bin} ${config_args})
file(STRINGS ${bin}/lib/plumb/model/generated/plumb/model/effect_list.inc generated
     REGEX "^PLUMB_EFFECT\\(accel_scale_temperature\\)$")
if(NOT generated)
  message(FATAL_ERROR "the generated registration list does not name accel_scale_temperature")
endif()
step(${CMAKE_COMMAND} --build ${bin} --parallel 2)
step(${bin}/builtin_check)
step(${bin}/effects_test --gtest_brief=1)
message(STATUS "accel_scale_temperature became a built-in effect with one file and one line")
