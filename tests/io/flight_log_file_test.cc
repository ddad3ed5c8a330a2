// FlightLog: every file in ../shared/data/{ardupilot,mavlink,px4} is recognised by content,
// summarised, and each of its selectable IMU streams becomes a session — or the log is
// rejected with an InputError that names the file and says why (issue 5's acceptance point).
#include "plumb/io/input/flight_log_file.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

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

// --- The board's other IMUs (FlightLogSelection::other_imus, SPEC "Several IMUs of one board")

bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// `a` and `b` hold the same samples, bit for bit (times, accelerometer, gyroscope,
/// temperature, units).
void ExpectIdentical(const ImuSeries& a, const ImuSeries& b) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.gyr.size(), b.gyr.size());
  ASSERT_EQ(a.temp_c.size(), b.temp_c.size());
  EXPECT_EQ(a.acc_unit, b.acc_unit);
  EXPECT_EQ(a.gyr_unit, b.gyr_unit);
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.t_s[i], b.t_s[i]) << "sample " << i;
    for (int k = 0; k < 3; ++k) {
      ASSERT_TRUE(SameBits(a.acc[i][k], b.acc[i][k])) << "sample " << i << " acc " << k;
      if (a.has_gyro()) ASSERT_TRUE(SameBits(a.gyr[i][k], b.gyr[i][k])) << "sample " << i;
    }
    if (a.has_temperature()) ASSERT_TRUE(SameBits(a.temp_c[i], b.temp_c[i])) << "sample " << i;
  }
}

/// `board` with IMU 0 as `base` selects it and `others` as the board's other IMUs.
FlightLogSelection Board(FlightLogSelection base, std::vector<int> others) {
  base.other_imus = std::move(others);
  return base;
}

/// Selects `base` with the board's `instances`, and checks that IMU 0 is what `base` alone
/// gives and that each other IMU is what selecting its instance alone gives (bit-identical
/// samples, the same firmware_left), named by its stream, with `samples` samples each. Returns
/// the board's session.
Session ExpectBoardAsAlone(const FlightLog& log, const FlightLogSelection& base,
                           const std::vector<int>& instances,
                           const std::vector<std::string>& names, std::size_t samples) {
  const Session board = log.Select(Board(base, instances));
  const Session imu0 = log.Select(base);
  ExpectIdentical(board.series, imu0.series);
  EXPECT_EQ(board.firmware_left, imu0.firmware_left);
  EXPECT_TRUE(imu0.other_imus.empty());
  EXPECT_EQ(board.source, imu0.source);
  EXPECT_EQ(board.log_params, imu0.log_params);
  if (board.other_imus.size() != instances.size()) {
    ADD_FAILURE() << log.source() << ": " << board.other_imus.size() << " other IMUs";
    return board;
  }
  for (std::size_t i = 0; i < instances.size(); ++i) {
    FlightLogSelection one = base;
    one.imu = instances[i];
    one.stream.clear();
    const Session alone = log.Select(one);
    const BoardImu& imu = board.other_imus[i];
    EXPECT_EQ(imu.instance, instances[i]);
    EXPECT_EQ(imu.name, names[i]);
    EXPECT_EQ(imu.series.size(), samples) << imu.name;
    ExpectIdentical(imu.series, alone.series);
    EXPECT_EQ(imu.firmware_left, alone.firmware_left);
  }
  return board;
}

/// True when some warning's message starts with `prefix` and contains `part`.
bool HasWarning(const Session& s, const std::string& prefix, const std::string& part) {
  for (const Notice& n : s.warnings) {
    if (n.message.rfind(prefix, 0) == 0 && n.message.find(part) != std::string::npos) return true;
  }
  return false;
}

TEST(FlightLogBoard, ArduPilotPlaneReadsIMU2BesideIMU) {
  const std::string path = testing::SharedLogPath("ardupilot", "plane408_centre_point.BIN");
  PLUMB_SKIP_IF_ABSENT(path);
  const FlightLog log = FlightLog::Open(path);
  // IMU3 is declared by the log's formats with no row: not one of the board's IMUs.
  EXPECT_EQ(BoardInstances(log.Summary(), 0), std::vector<int>{1});
  EXPECT_EQ(BoardInstances(log.Summary(), 1), std::vector<int>{0});
  const Session s = ExpectBoardAsAlone(log, {}, {1}, {"IMU2"}, 2216);
  ASSERT_EQ(s.other_imus.size(), 1U);
  EXPECT_EQ(s.series.size(), 2216U);
  // Both on the log's clock, 49.99 Hz over the same span.
  const ImuSeries& imu2 = s.other_imus[0].series;
  EXPECT_NEAR((imu2.size() - 1) / (imu2.t_s.back() - imu2.t_s.front()), 49.988, 1e-3);
  EXPECT_NEAR(imu2.t_s.front(), s.series.t_s.front(), 0.02);
  EXPECT_NEAR(imu2.t_s.back(), s.series.t_s.back(), 0.02);
  // IMU2's own correction (INS_ACC2*) is said, under its stream and instance.
  EXPECT_TRUE(HasWarning(s, "IMU2 of IMU instance 1: ", "INS_ACC2")) << s.warnings.size();
}

TEST(FlightLogBoard, ADeclaredInstanceWithoutRowsIsAnErrorNamingIt) {
  const std::string path = testing::SharedLogPath("ardupilot", "plane408_centre_point.BIN");
  PLUMB_SKIP_IF_ABSENT(path);
  const FlightLog log = FlightLog::Open(path);
  try {
    log.Select(Board({}, {1, 2}));
    ADD_FAILURE() << "IMU3 has no rows";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find("IMU3"), std::string::npos) << e.what();
  }
  try {
    log.Select(Board({}, {7}));
    ADD_FAILURE() << "no instance 7";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find("7"), std::string::npos) << e.what();
  }
}

TEST(FlightLogBoard, IMU0OrAnInstanceListedTwiceIsRefused) {
  const std::string path = testing::SharedLogPath("ardupilot", "plane408_centre_point.BIN");
  PLUMB_SKIP_IF_ABSENT(path);
  const FlightLog log = FlightLog::Open(path);
  const auto expect_error = [&](const FlightLogSelection& pick, const std::string& part) {
    try {
      log.Select(pick);
      ADD_FAILURE() << "expected plumb::Error with " << part;
    } catch (const InputError& e) {
      ADD_FAILURE() << "an InputError (the log is fine): " << e.what();
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  expect_error(Board({}, {0}), "IMU instance 0 is IMU 0");
  expect_error(Board({}, {1, 1}), "IMU instance 1 is listed twice");
  FlightLogSelection second;  // IMU 0 is then instance 1: instance 0 is another IMU
  second.imu = 1;
  expect_error(Board(second, {1}), "IMU instance 1 is IMU 0");
  const Session swapped = log.Select(Board(second, {0}));
  ASSERT_EQ(swapped.other_imus.size(), 1U);
  EXPECT_EQ(swapped.other_imus[0].name, "IMU");
}

TEST(FlightLogBoard, ArduPilotCopterReadsIMU2BesideIMU) {
  const std::string path = testing::SharedLogPath("ardupilot", "copter36_chibios.bin");
  PLUMB_SKIP_IF_ABSENT(path);
  const FlightLog log = FlightLog::Open(path);
  const std::vector<int> all = BoardInstances(log.Summary(), 0);
  EXPECT_EQ(all, std::vector<int>{1});
  ExpectBoardAsAlone(log, {}, all, {"IMU2"}, 6113);
  // As logged: what the firmware applied stays, said per IMU.
  FlightLogSelection as_logged;
  as_logged.undo_correction = false;
  const Session s = ExpectBoardAsAlone(log, as_logged, all, {"IMU2"}, 6113);
  ASSERT_EQ(s.other_imus.size(), 1U);
  EXPECT_FALSE(s.other_imus[0].firmware_left.empty());
}

TEST(FlightLogBoard, TlogReadsTheScaledImusBesideRawImu) {
  const std::string path = testing::SharedLogPath("mavlink", "plane385_disarmed.tlog");
  PLUMB_SKIP_IF_ABSENT(path);
  const FlightLog log = FlightLog::Open(path);
  const std::vector<int> all = BoardInstances(log.Summary(), 0);
  EXPECT_EQ(all, (std::vector<int>{1, 2}));
  const Session s = ExpectBoardAsAlone(log, {}, all, {"SCALED_IMU2", "SCALED_IMU3"}, 301);
  // Their correction (INS_ACC2OFFS, INS_ACC3OFFS, ...) undone, each said under its instance.
  EXPECT_TRUE(HasWarning(s, "SCALED_IMU2 instance 1: ", "INS_ACC2OFFS"));
  EXPECT_TRUE(HasWarning(s, "SCALED_IMU3 instance 2: ", "INS_ACC3OFFS"));
  for (const BoardImu& imu : s.other_imus) EXPECT_TRUE(imu.firmware_left.empty()) << imu.name;
  // In reverse order: as listed.
  const Session reversed = log.Select(Board({}, {2, 1}));
  ASSERT_EQ(reversed.other_imus.size(), 2U);
  EXPECT_EQ(reversed.other_imus[0].name, "SCALED_IMU3");
  EXPECT_EQ(reversed.other_imus[1].name, "SCALED_IMU2");
}

TEST(FlightLogBoard, TheWindowAppliesToEveryImu) {
  const std::string path = testing::SharedLogPath("mavlink", "plane385_disarmed.tlog");
  PLUMB_SKIP_IF_ABSENT(path);
  const FlightLog log = FlightLog::Open(path);
  FlightLogSelection window;
  window.from_s = 1560.0;
  window.to_s = 1600.0;
  const Session s = log.Select(Board(window, {1, 2}));
  ASSERT_EQ(s.other_imus.size(), 2U);
  for (const BoardImu& imu : s.other_imus) {
    FlightLogSelection alone = window;
    alone.imu = imu.instance;
    ExpectIdentical(imu.series, log.Select(alone).series);
    ASSERT_GE(imu.series.size(), 2U);
    EXPECT_LT(imu.series.size(), 301U) << imu.name;
    EXPECT_GE(imu.series.t_s.front(), 1560.0);
    EXPECT_LE(imu.series.t_s.back(), 1600.0);
  }
}

TEST(FlightLogBoard, ULogReadsVehicleImuOfInstancesOneAndTwo) {
  const std::string path = testing::SharedLogPath("px4", "sample_log_small.ulg");
  PLUMB_SKIP_IF_ABSENT(path);
  const FlightLog log = FlightLog::Open(path);
  const std::vector<int> all = BoardInstances(log.Summary(), 0);
  EXPECT_EQ(all, (std::vector<int>{1, 2}));
  // IMU 0's default is sensor_combined (200 Hz); instances 1 and 2 have vehicle_imu (2 Hz)
  // and sensor_accel (1 Hz), vehicle_imu the default.
  const Session s = ExpectBoardAsAlone(log, {}, all, {"vehicle_imu", "vehicle_imu"}, 12);
  EXPECT_EQ(s.series.size(), 1298U);
  // A window that leaves IMU 0 (200 Hz) samples but an other IMU (2 Hz, from 20.828 s) one:
  // an error naming the log and that IMU's stream and instance.
  FlightLogSelection early;
  early.from_s = 20.0;
  early.to_s = 21.0;
  EXPECT_GE(log.Select(early).series.size(), 2U);
  testing::ExpectInputError([&] { log.Select(Board(early, {1})); }, path,
                            "vehicle_imu instance 1", {"20"});
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
