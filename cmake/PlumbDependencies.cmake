# Finds plumb's dependencies (all from Debian packages) and exposes them as targets.
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(Ceres 2.0 REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
# Boost.Math (header-only): the exact chi-square quantile of the Allan deviation's intervals.
find_package(Boost 1.71 REQUIRED)

# Debian ships GeographicLib with a Find module only; wrap it in an imported target.
if(NOT TARGET GeographicLib::GeographicLib)
  list(APPEND CMAKE_MODULE_PATH /usr/share/cmake/geographiclib)
  find_package(GeographicLib 1.49 REQUIRED)
  add_library(GeographicLib::GeographicLib INTERFACE IMPORTED)
  set_target_properties(GeographicLib::GeographicLib PROPERTIES
    INTERFACE_LINK_LIBRARIES "${GeographicLib_LIBRARIES}"
    INTERFACE_INCLUDE_DIRECTORIES "${GeographicLib_INCLUDE_DIRS}")
endif()
