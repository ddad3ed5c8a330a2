# plumb_link_dependencies_statically(TARGET): links the C++ libraries an executable takes from
# Debian (Ceres's dependencies, GeographicLib, yaml-cpp, and the C++ runtime) from their static
# archives instead of their shared objects (option PLUMB_STATIC_DEPENDENCIES, ON by default).
#
# Why: much of a short command's time is the process's start. Every shared object is found,
# mapped and relocated, and its symbols looked up, before main: `plumb --version` took 6.4-8.9
# ms linked against 27 shared libraries and 3.5-3.7 ms linked so, against 6 (libc, libm,
# libgomp, METIS, libunwind and liblzma, which Debian ships without archives or which are C
# and stay shared); docs/performance.md, "Threads (`--jobs`) and start-up", has the command.
#
# Only the target named gets this (the `plumb` command): the tests, the benchmarks, the Python
# module and an installed plumb's consumers (plumbConfig.cmake does not include this file) link
# as before. The switch is a target property, PLUMB_STATIC_LINK, read by generator expressions
# in the imported targets' link interfaces (Ceres's, GeographicLib's and yaml-cpp's wrapper,
# plumb_yaml::yaml-cpp), so the same imported targets serve both kinds. Call it after the
# target's target_link_libraries.
option(PLUMB_STATIC_DEPENDENCIES
       "Link the plumb command with Debian's static archives of its C++ dependencies" ON)

# The archive beside a shared object (libX.so[.N...] -> libX.a), or "" when there is none.
function(_plumb_archive_of out library)
  set(${out} "" PARENT_SCOPE)
  if(NOT library MATCHES "\\.so(\\.[0-9]+)*$")
    return()
  endif()
  string(REGEX REPLACE "\\.so(\\.[0-9]+)*$" ".a" archive "${library}")
  if(EXISTS "${archive}")
    set(${out} "${archive}" PARENT_SCOPE)
  endif()
endfunction()

# Where an imported target's file may be named (Debian's packages use one of these).
set(_PLUMB_LOCATIONS IMPORTED_LOCATION_RELEASE IMPORTED_LOCATION_NOCONFIG IMPORTED_LOCATION_NONE
                     IMPORTED_LOCATION)

# The archive of an imported target (its configuration's location), or "".
function(_plumb_archive_of_target out target)
  set(${out} "" PARENT_SCOPE)
  foreach(property IN LISTS _PLUMB_LOCATIONS)
    get_target_property(location ${target} ${property})
    if(location)
      _plumb_archive_of(archive "${location}")
      set(${out} "${archive}" PARENT_SCOPE)
      return()
    endif()
  endforeach()
endfunction()

# `entry` of a link interface as the static link takes it: a shared object's archive, followed
# by its own link interface taken the same way; an interface target's link interface taken
# the same way; `entry` itself where nothing has an archive.
function(_plumb_static_entry out entry)
  if(entry MATCHES "^\\$<LINK_ONLY:(.+)>$")  # an archive is linked only anyway
    set(linked "${CMAKE_MATCH_1}")
    _plumb_static_entry(static_linked "${linked}")
    if(NOT static_linked STREQUAL linked)
      set(entry "${static_linked}")
    endif()
    set(${out} "${entry}" PARENT_SCOPE)
    return()
  endif()
  if(NOT TARGET "${entry}")
    _plumb_archive_of(archive "${entry}")
    if(archive)
      set(entry "${archive}")
    endif()
    set(${out} "${entry}" PARENT_SCOPE)
    return()
  endif()
  _plumb_archive_of_target(archive "${entry}")
  get_target_property(type "${entry}" TYPE)
  if(NOT archive AND NOT type STREQUAL "INTERFACE_LIBRARY")
    set(${out} "${entry}" PARENT_SCOPE)  # a shared object without an archive, kept
    return()
  endif()
  set(converted ${archive})
  set(changed OFF)
  if(archive)
    set(changed ON)
  endif()
  get_target_property(deps "${entry}" INTERFACE_LINK_LIBRARIES)
  foreach(dep IN LISTS deps)
    if(dep)
      _plumb_static_entry(dep_static "${dep}")
      if(NOT dep_static STREQUAL dep)
        set(changed ON)
      endif()
      list(APPEND converted ${dep_static})
    endif()
  endforeach()
  if(changed)
    set(${out} "${converted}" PARENT_SCOPE)
  else()
    set(${out} "${entry}" PARENT_SCOPE)
  endif()
endfunction()

# Rewrites `target`'s link interface: the entries with no archive stay; the others become
# $<IF:static,$<LINK_GROUP:RESCAN,their archives...,extra...>,the entries> on the consuming
# target's PLUMB_STATIC_LINK, `extra` being what the archives need that the shared objects
# brought along themselves.
function(_plumb_static_interface target extra)
  if(NOT TARGET ${target})
    return()
  endif()
  set(static "$<BOOL:$<TARGET_PROPERTY:PLUMB_STATIC_LINK>>")
  get_target_property(entries ${target} INTERFACE_LINK_LIBRARIES)
  set(shared "")
  set(archives "")
  set(kept "")
  if(entries)
    foreach(entry IN LISTS entries)
      _plumb_static_entry(static_entry "${entry}")
      if(static_entry STREQUAL entry)
        list(APPEND kept "${entry}")
      else()
        list(APPEND shared "${entry}")
        list(APPEND archives ${static_entry})
      endif()
    endforeach()
  endif()
  list(APPEND archives ${extra})
  list(REMOVE_DUPLICATES archives)
  # The archives as one group: they need each other in no single order (LAPACK's needs BLAS's,
  # which SuiteSparse's interfaces name earlier), so the linker goes over them until done.
  string(REPLACE ";" "," archives "${archives}")
  string(REPLACE ";" "$<SEMICOLON>" shared "${shared}")
  set(rewritten ${kept} "$<IF:${static},$<LINK_GROUP:RESCAN,${archives}>,${shared}>")
  set_target_properties(${target} PROPERTIES INTERFACE_LINK_LIBRARIES "${rewritten}")
endfunction()

function(plumb_link_dependencies_statically target)
  if(NOT PLUMB_STATIC_DEPENDENCIES)
    return()
  endif()
  # What the archives need that their shared objects brought along: LAPACK's and BLAS's
  # archives the Fortran runtime (the compiler's own archives), CHOLMOD's METIS (Debian ships
  # it shared only), glog's libunwind. Without them the command links as the tests do.
  set(extra "")
  foreach(runtime libgfortran.a libquadmath.a)
    execute_process(COMMAND ${CMAKE_CXX_COMPILER} -print-file-name=${runtime}
                    OUTPUT_VARIABLE path OUTPUT_STRIP_TRAILING_WHITESPACE)
    if(NOT IS_ABSOLUTE "${path}" OR NOT EXISTS "${path}")
      message(STATUS "plumb: no ${runtime}: the plumb command links its dependencies dynamically")
      return()
    endif()
    list(APPEND extra "${path}")
  endforeach()
  find_library(PLUMB_METIS_LIBRARY NAMES metis libmetis.so.5)
  if(NOT PLUMB_METIS_LIBRARY)
    message(STATUS "plumb: no METIS library: the plumb command links its dependencies dynamically")
    return()
  endif()
  list(APPEND extra "${PLUMB_METIS_LIBRARY}" unwind)
  get_property(done GLOBAL PROPERTY PLUMB_STATIC_INTERFACES_DONE)
  if(NOT done)
    _plumb_static_interface(Ceres::ceres "${extra}")
    _plumb_static_interface(GeographicLib::GeographicLib "")
    _plumb_static_interface(plumb_yaml::yaml-cpp "")
    set_property(GLOBAL PROPERTY PLUMB_STATIC_INTERFACES_DONE ON)
  endif()
  set_target_properties(${target} PROPERTIES PLUMB_STATIC_LINK ON)
  # With every C++ library an archive, the C++ runtime can be one too (a shared C++ library
  # left in would bring its own copy of libstdc++).
  target_link_options(${target} PRIVATE -static-libstdc++ -static-libgcc)
endfunction()
