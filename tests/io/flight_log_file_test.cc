// FlightLog: every file in ../shared/data/{ardupilot,mavlink,px4} is recognised by content,
// summarised, and each of its selectable IMU streams becomes a session — or the log is
// rejected with an InputError that names the file and says why (issue 5's acceptance point).
#include "plumb/io/input/flight_log_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "io_test_util.h"
#include "plumb/core/error.h"

namespace plumb::io {
namespace {

const std::string kData = PLUMB_SHARED_DATA_DIR;

/// The format each shared log must be recognised as.
const std::map<std::string, FlightLogFormat>& ExpectedFormats() {
  static const std::map<std::string, FlightLogFormat> formats = {
      {"ardupilot/copter311_nan.log", FlightLogFormat::kDataflashText},
      {"ardupilot/copter31_no_imu_rows.log", FlightLogFormat::kDataflashText},
      {"ardupilot/copter344_pixhawk1_oldformat.bin", FlightLogFormat::kDataflashBinary},
      {"ardupilot/copter364_fmuv5.bin", FlightLogFormat::kDataflashBinary},
      {"ardupilot/copter36_chibios.bin", FlightLogFormat::kDataflashBinary},
      {"ardupilot/copter462_truncated_isbd.bin", FlightLogFormat::kDataflashBinary},
      {"ardupilot/plane382_pymavlink_test.BIN", FlightLogFormat::kDataflashBinary},
      {"ardupilot/plane408_centre_point.BIN", FlightLogFormat::kDataflashBinary},
      {"ardupilot/plane408_pilot_pos.BIN", FlightLogFormat::kDataflashBinary},
      {"mavlink/plane385_disarmed.tlog", FlightLogFormat::kMavlinkTlog},
      {"px4/sample.ulg", FlightLogFormat::kPx4ULog},
      {"px4/sample_appended_multiple.ulg", FlightLogFormat::kPx4ULog},
      {"px4/sample_log_small.ulg", FlightLogFormat::kPx4ULog},
      {"px4/sample_logging_tagged_and_default_params.ulg", FlightLogFormat::kPx4ULog},
      {"px4/sample_px4_events.ulg", FlightLogFormat::kPx4ULog},
  };
  return formats;
}

/// Opens `path`, summarises it and selects every stream that carries an accelerometer with
/// samples; returns how many sessions were made. A failure to select is an InputError naming
/// the log (never another exception).
std::size_t SessionsOf(const std::string& path) {
  const FlightLog log = FlightLog::Open(path);
  const FlightLogSummary summary = log.Summary();
  EXPECT_EQ(summary.format, FlightLogFormatName(log.format()));
  EXPECT_GT(summary.size_bytes, 0U);
  std::size_t sessions = 0;
  for (const ImuStreamInfo& info : summary.imus) {
    if (!info.has_accel || info.samples < 2) continue;
    FlightLogSelection pick;
    pick.imu = info.instance;
    pick.stream = info.name;
    try {
      const Session s = log.Select(pick);
      EXPECT_GE(s.series.size(), 2U) << path << " " << info.name;
      EXPECT_NE(s.source.find(path), std::string::npos);
      ++sessions;
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), path) << e.what();
    }
  }
  return sessions;
}

TEST(FlightLogFile, EverySharedLogIsRecognisedByContent) {
  for (const auto& [relative, format] : ExpectedFormats()) {
    const std::string path = kData + "/" + relative;
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
    EXPECT_EQ(SniffFlightLog(path), format) << relative;
  }
  // Every log in the three folders is in the table above (a new file must be added there).
  for (const char* folder : {"ardupilot", "mavlink", "px4"}) {
    for (const auto& e : std::filesystem::directory_iterator(kData + "/" + folder)) {
      const std::string relative = std::string(folder) + "/" + e.path().filename().string();
      EXPECT_EQ(ExpectedFormats().count(relative), 1U) << relative << " is not in the table";
    }
  }
}

TEST(FlightLogFile, EverySharedLogGivesASessionOrAClearReason) {
  for (const auto& [relative, format] : ExpectedFormats()) {
    const std::string path = kData + "/" + relative;
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
    if (relative == "ardupilot/copter31_no_imu_rows.log") {
      // The IMU format is defined but no IMU row was logged: the default selection says so.
      testing::ExpectInputError([&] { FlightLog::Open(path).Select({}); }, path, "",
                                {"defines IMU", "no IMU rows"});
      continue;
    }
    EXPECT_GE(SessionsOf(path), 1U) << relative;
  }
}

TEST(FlightLogFile, ATextTableIsNotAFlightLog) {
  testing::TempDir dir;
  const std::string path = (dir.path() / "table.csv").string();
  std::ofstream(path) << "time_s,acc_x,acc_y,acc_z\n0,0,0,-9.8\n";
  EXPECT_EQ(SniffFlightLog(path), FlightLogFormat::kNone);
  testing::ExpectInputError([&] { FlightLog::Open(path); }, path, "byte 0",
                            {"not a flight log"});
}

}  // namespace
}  // namespace plumb::io
