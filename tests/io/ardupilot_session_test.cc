// An ArduPilot log as a session (io/ardupilot_session.h): the INS_* correction undone, the
// time window, the site from the GPS, on a real still log.
#include "plumb/io/ardupilot_session.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "plumb/core/error.h"

namespace plumb::io {
namespace {

const std::string kLog =
    std::string(PLUMB_SHARED_DATA_DIR) + "/ardupilot/plane408_centre_point.BIN";

TEST(ArdupilotSession, UndoesTheInsCorrectionAndReadsTheSite) {
  if (!std::filesystem::exists(kLog)) GTEST_SKIP() << "shared data absent: " << kLog;
  const DataflashLog log = ReadDataflash(kLog);
  ArdupilotSessionOptions as_logged;
  as_logged.undo_correction = false;
  const Session logged = ArdupilotSession(log, as_logged);
  const Session raw = ArdupilotSession(log, ArdupilotSessionOptions{});
  ASSERT_EQ(logged.series.size(), raw.series.size());
  // raw = logged ./ INS_ACCSCAL + INS_ACCOFFS; gyro raw = logged + INS_GYROFFS (instance 0).
  for (int i = 0; i < 3; ++i) {
    const std::string axis = std::string("_") + "XYZ"[i];
    const double scal = log.params.at("INS_ACCSCAL" + axis);
    const double offs = log.params.at("INS_ACCOFFS" + axis);
    const double gyr = log.params.at("INS_GYROFFS" + axis);
    EXPECT_NEAR(raw.series.acc[10][i], logged.series.acc[10][i] / scal + offs, 1e-5);
    EXPECT_NEAR(raw.series.gyr[10][i], logged.series.gyr[10][i] + gyr, 1e-6);
  }
  bool said = false;
  for (const auto& w : raw.warnings) said = said || w.find("reconstructed") != std::string::npos;
  EXPECT_TRUE(said);
  // The log's README: GPS at 51.64 N; the site comes from its 3D fixes.
  ASSERT_TRUE(raw.site.has_value());
  EXPECT_EQ(raw.site->source, "gps");
  EXPECT_NEAR(raw.site->lat_deg, 51.64, 0.01);
}

TEST(ArdupilotSession, TimeWindowAndInstances) {
  if (!std::filesystem::exists(kLog)) GTEST_SKIP() << "shared data absent: " << kLog;
  const DataflashLog log = ReadDataflash(kLog);
  const Session all = ArdupilotSession(log, ArdupilotSessionOptions{});
  ArdupilotSessionOptions window;
  window.from_s = all.series.t_s.front() + 10.0;
  window.to_s = all.series.t_s.front() + 20.0;
  const Session part = ArdupilotSession(log, window);
  EXPECT_GE(part.series.t_s.front(), *window.from_s);
  EXPECT_LE(part.series.t_s.back(), *window.to_s);
  EXPECT_NEAR(part.series.duration_s(), 10.0, 0.1);
  ArdupilotSessionOptions second;
  second.imu = 1;  // IMU2
  EXPECT_GT(ArdupilotSession(log, second).series.size(), 100u);
  ArdupilotSessionOptions missing;
  missing.imu = 5;
  EXPECT_THROW(ArdupilotSession(log, missing), InputError);
  ArdupilotSessionOptions empty;
  empty.from_s = 1e9;
  EXPECT_THROW(ArdupilotSession(log, empty), InputError);
}

}  // namespace
}  // namespace plumb::io
