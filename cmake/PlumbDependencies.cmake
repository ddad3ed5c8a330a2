# Finds plumb's dependencies (all from Debian packages) and exposes them as targets.
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(Ceres 2.0 REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
# Boost.Math (header-only): the exact chi-square quantile of the Allan deviation's intervals.
find_package(Boost 1.71 REQUIRED)
# yaml-cpp: YAML study files (study/study_file.h), turned into the JSON the library takes.
# Wrapped in an interface target, as GeographicLib below, so that the plumb command can link
# its archive (PlumbStaticDependencies.cmake) while shared objects (the Python module) link its
# shared object.
find_package(yaml-cpp REQUIRED)
if(NOT TARGET plumb_yaml::yaml-cpp)
  add_library(plumb_yaml::yaml-cpp INTERFACE IMPORTED)
  set_target_properties(plumb_yaml::yaml-cpp PROPERTIES INTERFACE_LINK_LIBRARIES yaml-cpp)
endif()

# libbz2, liblz4 and libzstd (C libraries): the bz2 and lz4 chunks of ROS 1 bags and the zstd
# and lz4 chunks of MCAP files (io/ros), found as plain libraries (Debian ships no CMake
# package for liblz4) and linked privately by io_ros. libsqlite3: ROS 2 .db3 bags (io/ros).
# libdeflate: the CRC-32 of an MCAP chunk's records (libdeflate_crc32, carry-less multiplication:
# about 3 times zlib 1.2.13's crc32; its cost in a read is in docs/performance.md).
find_path(PLUMB_BZ2_INCLUDE_DIR bzlib.h REQUIRED)
find_library(PLUMB_BZ2_LIBRARY bz2 REQUIRED)
find_path(PLUMB_LZ4_INCLUDE_DIR lz4frame.h REQUIRED)
find_library(PLUMB_LZ4_LIBRARY lz4 REQUIRED)
find_path(PLUMB_ZSTD_INCLUDE_DIR zstd.h REQUIRED)
find_library(PLUMB_ZSTD_LIBRARY zstd REQUIRED)
find_path(PLUMB_SQLITE3_INCLUDE_DIR sqlite3.h REQUIRED)
find_library(PLUMB_SQLITE3_LIBRARY sqlite3 REQUIRED)
find_path(PLUMB_DEFLATE_INCLUDE_DIR libdeflate.h REQUIRED)
find_library(PLUMB_DEFLATE_LIBRARY deflate REQUIRED)

# Debian ships GeographicLib with a Find module only; wrap it in an imported target.
if(NOT TARGET GeographicLib::GeographicLib)
  list(APPEND CMAKE_MODULE_PATH /usr/share/cmake/geographiclib)
  find_package(GeographicLib 1.49 REQUIRED)
  add_library(GeographicLib::GeographicLib INTERFACE IMPORTED)
  set_target_properties(GeographicLib::GeographicLib PROPERTIES
    INTERFACE_LINK_LIBRARIES "${GeographicLib_LIBRARIES}"
    INTERFACE_INCLUDE_DIRECTORIES "${GeographicLib_INCLUDE_DIRS}")
endif()
