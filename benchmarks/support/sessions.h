// benchmarks/support/sessions.h — the real sessions the benchmarks run on: the bundled mikoff
// imu0 (always there) and imu_tk's own data (../shared/data, optional: check ImuTkPresent()).
#pragma once

#include <filesystem>
#include <string>

#include "plumb/core/session.h"
#include "plumb/io/text/text_table.h"

namespace plumb::bench {

inline std::string SharedData() { return PLUMB_SHARED_DATA_DIR; }

/// data/mikoff/imu0.log: `ax ay az wx wy wz` at 100 Hz, no time column.
inline Session ReadMikoff() {
  io::TextTableOptions o;
  o.acc.axes = {0, 1, 2};
  o.gyr.axes = {3, 4, 5};
  o.rate_hz = 100;
  return io::ReadTextTable(std::string(PLUMB_SOURCE_DIR) + "/data/mikoff/imu0.log", o);
}

inline bool ImuTkPresent() {
  return std::filesystem::exists(SharedData() + "/multipose/imu_tk/xsens_acc.mat");
}

/// imu_tk's xsens_acc.mat and xsens_gyro.mat: `t x y z` in raw counts.
inline Session ReadImuTk() {
  io::TextTableOptions o;
  o.time = 0;
  o.acc.axes = {1, 2, 3};
  o.gyr.axes = {1, 2, 3};
  return io::ReadSplitTables(SharedData() + "/multipose/imu_tk/xsens_acc.mat",
                             SharedData() + "/multipose/imu_tk/xsens_gyro.mat", o);
}

}  // namespace plumb::bench
