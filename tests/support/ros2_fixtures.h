// tests/support/ros2_fixtures.h — the ROS 2 copies of ../shared/data/ros/ardrone_imu.bag (MCAP
// uncompressed, zstd and lz4, and .db3), made by an independent writer
// (tests/io/ros2_fixtures/make-fixtures: python3-rosbag reads the bag, @mcap/core and Python's
// sqlite3 write the copies) into PLUMB_ROS2_FIXTURES_DIR, once per test process. A target that
// includes this defines PLUMB_ROS2_FIXTURES_DIR, PLUMB_SHARED_DATA_DIR and PLUMB_SOURCE_DIR.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>

namespace plumb::testing {

/// The ROS 1 original.
inline const std::string& Ros2FixturesSourceBag() {
  static const std::string bag = std::string(PLUMB_SHARED_DATA_DIR) + "/ros/ardrone_imu.bag";
  return bag;
}

/// The copies' common prefix: PREFIX.mcap, PREFIX_zstd.mcap, PREFIX_lz4.mcap, PREFIX.db3.
inline const std::string& Ros2FixturesPrefix() {
  static const std::string prefix = std::string(PLUMB_ROS2_FIXTURES_DIR) + "/ardrone_imu";
  return prefix;
}

/// Makes the copies (once per process; the script keeps fresh ones): "" when they are there,
/// else why not (the shared data, npm packages or python3-rosbag absent), for GTEST_SKIP.
inline std::string MakeRos2Fixtures() {
  static const std::string why = [] {
    const std::string& bag = Ros2FixturesSourceBag();
    if (!std::filesystem::exists(bag)) return "shared data absent: " + bag;
    const std::string command = std::string(PLUMB_SOURCE_DIR) +
                                "/tests/io/ros2_fixtures/make-fixtures '" + bag + "' '" +
                                Ros2FixturesPrefix() + "' 2>&1";
    FILE* pipe = ::popen(command.c_str(), "r");
    if (pipe == nullptr) return std::string("cannot run ") + command;
    std::string out;
    char buffer[4096];
    std::size_t n = 0;
    while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) out.append(buffer, n);
    if (::pclose(pipe) == 0) return std::string();
    return "the fixtures were not made (" + command + "): " + out;
  }();
  return why;
}

}  // namespace plumb::testing
