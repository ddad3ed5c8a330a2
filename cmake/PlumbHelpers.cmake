# plumb_module(NAME SOURCES ... DEPS ...): one library per folder under lib/plumb/,
# exported as plumb::NAME. Headers are included as <plumb/NAME/header.h>.
function(plumb_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(plumb_${name} ${ARG_SOURCES})
  add_library(plumb::${name} ALIAS plumb_${name})
  set_target_properties(plumb_${name} PROPERTIES EXPORT_NAME ${name}
                        POSITION_INDEPENDENT_CODE ON)
  target_include_directories(plumb_${name} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/lib>
    $<INSTALL_INTERFACE:include>)
  target_link_libraries(plumb_${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  target_compile_options(plumb_${name} PRIVATE -Wall -Wextra)
  set_property(GLOBAL APPEND PROPERTY PLUMB_MODULES plumb_${name})
endfunction()

# plumb_test(NAME SOURCES ... DEPS ...): one GoogleTest executable registered with CTest.
function(plumb_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests)
  target_compile_definitions(${name} PRIVATE
    PLUMB_SHARED_DATA_DIR="${PLUMB_SHARED_DATA_DIR}"
    PLUMB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60)
endfunction()
