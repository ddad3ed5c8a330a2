# plumb_module(NAME [DIR PATH] SOURCES ... HEADERS ... [INTERNAL_HEADERS ...] DEPS ...
#              [PRIVATE_DEPS ...]): one library per folder under lib/plumb/ (DIR, default NAME:
# e.g. `io/common` for module io_common), exported as plumb::NAME. Headers are included as
# <plumb/DIR/header.h>.
#
# Public and internal headers: HEADERS are the module's interface, installed under
# include/plumb/DIR (cmake/PlumbInstall.cmake); INTERNAL_HEADERS are its implementation's (a
# stage that exposes Ceres, a parser's pieces, *_internal.h), seen by the module and by the
# modules that link it in this build, and never installed. Every header of the folder is to
# be one or the other (paths relative to the folder, e.g. effects/accel_linear.h), and no
# installed header may include an internal one: tests/consumer fails on a header the library's
# sources or headers include that neither list names, and on a public header that includes an
# internal one, and compiles every installed header alone against the installed package.
#
# Layering the build enforces: a module's include root holds only its own folder. At configure
# time the build tree gets `include/NAME/plumb/DIR`, a link to lib/plumb/DIR, and that root
# (not lib/) is the module's include directory. A source therefore finds the headers of its own
# module and of the modules it links (DEPS, and what they link publicly) and no others: an
# include of a module it does not declare fails to compile (tests/layering checks this).
function(plumb_module name)
  cmake_parse_arguments(ARG "" "DIR" "SOURCES;HEADERS;INTERNAL_HEADERS;DEPS;PRIVATE_DEPS"
                        ${ARGN})
  if(NOT ARG_DIR)
    set(ARG_DIR ${name})
  endif()
  foreach(_header IN LISTS ARG_HEADERS ARG_INTERNAL_HEADERS)
    if(NOT EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${_header})
      message(FATAL_ERROR "plumb_module(${name}): no header ${CMAKE_CURRENT_SOURCE_DIR}/${_header}")
    endif()
  endforeach()
  foreach(_header IN LISTS ARG_INTERNAL_HEADERS)
    if(_header IN_LIST ARG_HEADERS)
      message(FATAL_ERROR "plumb_module(${name}): ${_header} is both public and internal")
    endif()
  endforeach()
  set(_root ${PROJECT_BINARY_DIR}/include/${name})
  set(_link ${_root}/plumb/${ARG_DIR})
  get_filename_component(_parent ${_link} DIRECTORY)
  file(MAKE_DIRECTORY ${_parent})
  if(NOT IS_SYMLINK ${_link})
    file(CREATE_LINK ${PROJECT_SOURCE_DIR}/lib/plumb/${ARG_DIR} ${_link} SYMBOLIC)
  endif()
  add_library(plumb_${name} ${ARG_SOURCES})
  add_library(plumb::${name} ALIAS plumb_${name})
  set_target_properties(plumb_${name} PROPERTIES EXPORT_NAME ${name}
                        POSITION_INDEPENDENT_CODE ON)
  target_include_directories(plumb_${name} PUBLIC
    $<BUILD_INTERFACE:${_root}>
    $<INSTALL_INTERFACE:include>)
  target_link_libraries(plumb_${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  target_compile_options(plumb_${name} PRIVATE -Wall -Wextra)
  set_property(GLOBAL APPEND PROPERTY PLUMB_MODULES plumb_${name})
  # For the install (PlumbInstall.cmake) and tests/consumer: headers as plumb/DIR/header.h, the
  # sources as absolute paths.
  set(_public "")
  set(_internal "")
  set(_sources "")
  foreach(_header IN LISTS ARG_HEADERS)
    list(APPEND _public plumb/${ARG_DIR}/${_header})
  endforeach()
  foreach(_header IN LISTS ARG_INTERNAL_HEADERS)
    list(APPEND _internal plumb/${ARG_DIR}/${_header})
  endforeach()
  foreach(_source IN LISTS ARG_SOURCES)
    if(IS_ABSOLUTE ${_source})
      list(APPEND _sources ${_source})
    else()
      list(APPEND _sources ${CMAKE_CURRENT_SOURCE_DIR}/${_source})
    endif()
  endforeach()
  set_property(GLOBAL APPEND PROPERTY PLUMB_PUBLIC_HEADERS ${_public})
  set_property(GLOBAL APPEND PROPERTY PLUMB_INTERNAL_HEADERS ${_internal})
  set_property(GLOBAL APPEND PROPERTY PLUMB_MODULE_SOURCES ${_sources})
endfunction()

# plumb_test(NAME SOURCES ... DEPS ... [LABELS ...]): one GoogleTest executable registered with
# CTest, its tests labelled LABELS (e.g. reality).
function(plumb_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests)
  target_compile_definitions(${name} PRIVATE
    PLUMB_SHARED_DATA_DIR="${PLUMB_SHARED_DATA_DIR}"
    PLUMB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  if(ARG_LABELS)
    gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES LABELS "${ARG_LABELS}")
  else()
    gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60)
  endif()
endfunction()
