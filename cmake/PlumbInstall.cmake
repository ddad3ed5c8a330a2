# Installs the libraries, headers, the command and a CMake package config so that
# find_package(plumb) gives plumb::core ... plumb::plumb (tests/consumer checks this).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)
get_property(_plumb_modules GLOBAL PROPERTY PLUMB_MODULES)
install(TARGETS ${_plumb_modules} plumb_all EXPORT plumbTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY lib/plumb DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h")
install(EXPORT plumbTargets NAMESPACE plumb::
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/plumb)
configure_package_config_file(cmake/plumbConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/plumbConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/plumb)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/plumbConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/plumbConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/plumbConfigVersion.cmake
              cmake/PlumbDependencies.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/plumb)
