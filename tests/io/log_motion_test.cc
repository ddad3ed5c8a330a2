// What a flight log says the vehicle did (core/log_motion.h): the GPS runs and land-detector
// intervals every reader builds (io/common/log_common.h), and what each reader finds in the
// real logs of ../shared/data. The real figures were read off the logs by decoders written
// apart from plumb's (a DataFlash record walker in Python; tests/data/px4/decode_golden.py for
// the ULog topics): ArduPilot EV Id 28 NOT_LANDED, 18 LAND_COMPLETE, 11 DISARMED (AP_Logger's
// LogEvent); GPS Status >= 3, Spd, VZ; PX4 vehicle_land_detected.landed.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "plumb/core/log_motion.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/input/flight_log_file.h"
#include "plumb/io/mavlink/mavlink_session.h"
#include "tlog_builder.h"

namespace plumb::io {
namespace {

const std::string kData = PLUMB_SHARED_DATA_DIR;

#define SKIP_IF_ABSENT(path) \
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << (path)

GpsVelocity Report(double t, double speed, double climb = 0.0, bool fix = true) {
  return {t, fix, speed, climb};
}

TEST(GpsMotion, ARunOfTwoMovingReportsIsMotionOneIsAGlitch) {
  const std::vector<GpsVelocity> one = {Report(0.0, 0.1), Report(0.2, 3.0), Report(0.4, 0.1)};
  EXPECT_TRUE(GpsMotion(one, "GPS").empty());
  const std::vector<GpsVelocity> two = {Report(0.0, 0.1), Report(0.2, 3.0), Report(0.4, 2.0),
                                        Report(0.6, 0.1)};
  const std::vector<LogMotion> m = GpsMotion(two, "GPS");
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].evidence, LogMotion::Evidence::kGpsMoving);
  EXPECT_DOUBLE_EQ(m[0].t_begin_s, 0.2);
  EXPECT_DOUBLE_EQ(m[0].t_end_s, 0.4);
  EXPECT_DOUBLE_EQ(m[0].max_ground_speed_m_s, 3.0);
  EXPECT_DOUBLE_EQ(m[0].ground_distance_m, 0.5 * (3.0 + 2.0) * 0.2);
  EXPECT_EQ(m[0].source, "GPS");
}

TEST(GpsMotion, AClimbCountsAndAReportWithoutAFixDoesNot) {
  const std::vector<GpsVelocity> climb = {Report(0.0, 0.0, -1.5), Report(1.0, 0.0, -1.6)};
  const std::vector<LogMotion> m = GpsMotion(climb, "GPS");
  ASSERT_EQ(m.size(), 1u);
  EXPECT_DOUBLE_EQ(m[0].max_climb_m_s, 1.6);
  const std::vector<GpsVelocity> no_fix = {Report(0.0, 9.0, 0.0, false),
                                           Report(1.0, 9.0, 0.0, false)};
  EXPECT_TRUE(GpsMotion(no_fix, "GPS").empty());
  // At the threshold is not above it: a receiver at rest never reaches it.
  const std::vector<GpsVelocity> at = {Report(0.0, kGpsMovingSpeed), Report(1.0, kGpsMovingSpeed)};
  EXPECT_TRUE(GpsMotion(at, "GPS").empty());
}

TEST(GpsMotion, RunsCloserThanTheGapAreOneInterval) {
  std::vector<GpsVelocity> r = {Report(0.0, 2.0), Report(0.5, 2.0), Report(1.0, 0.2),
                                Report(1.5, 2.0), Report(2.0, 2.0),  // 1 s after: joined
                                Report(2.5, 0.2), Report(5.0, 0.2),
                                Report(5.5, 4.0), Report(6.0, 4.0)};  // 3.5 s after: apart
  const std::vector<LogMotion> m = GpsMotion(r, "GPS");
  ASSERT_EQ(m.size(), 2u);
  EXPECT_DOUBLE_EQ(m[0].t_begin_s, 0.0);
  EXPECT_DOUBLE_EQ(m[0].t_end_s, 2.0);
  EXPECT_DOUBLE_EQ(m[1].t_begin_s, 5.5);
  EXPECT_DOUBLE_EQ(m[1].max_ground_speed_m_s, 4.0);
}

TEST(AirborneIntervals, FromNotLandedToLandedOrTheLogsEnd) {
  const std::vector<LandedState> events = {{1.0, false, "landed"},
                                           {10.0, true, "NOT_LANDED"},
                                           {12.0, true, "NOT_LANDED"},  // repeated: no new one
                                           {20.0, false, "LAND_COMPLETE"},
                                           {30.0, true, "NOT_LANDED"}};
  const std::vector<LogMotion> m = AirborneIntervals(events, 40.0, "EV");
  ASSERT_EQ(m.size(), 2u);
  EXPECT_DOUBLE_EQ(m[0].t_begin_s, 10.0);
  EXPECT_DOUBLE_EQ(m[0].t_end_s, 20.0);
  EXPECT_EQ(m[0].source, "EV NOT_LANDED .. LAND_COMPLETE");
  EXPECT_DOUBLE_EQ(m[1].t_begin_s, 30.0);
  EXPECT_DOUBLE_EQ(m[1].t_end_s, 40.0);
  EXPECT_EQ(m[1].source, "EV NOT_LANDED .. the log's end");
  EXPECT_EQ(Describe(m[0]), "airborne 10.0-20.0 s (EV NOT_LANDED .. LAND_COMPLETE)");
  // Landed only: never airborne.
  EXPECT_TRUE(AirborneIntervals({{1.0, false, "landed"}, {2.0, false, "landed"}}, 9.0, "x").empty());
}

TEST(LogMotion, CoversMoreThanItsEdgesOrWhatLiesInside) {
  LogMotion m;
  m.t_begin_s = 10.0;
  m.t_end_s = 20.0;
  EXPECT_FALSE(m.Covers(0.0, 10.5));   // a hold ending as the motors spin up
  EXPECT_FALSE(m.Covers(19.5, 30.0));  // a hold starting as the detector says landed
  EXPECT_TRUE(m.Covers(0.0, 11.5));
  EXPECT_TRUE(m.Covers(12.0, 12.5));   // inside, however short
  EXPECT_TRUE(m.Covers(0.0, 30.0));
  EXPECT_FALSE(m.Covers(20.0, 30.0));
  EXPECT_FALSE(m.Covers(0.0, 5.0));
}

/// The log's motion as its summary and the session of IMU instance 0 give it: the same.
std::vector<LogMotion> MotionOf(const std::string& path) {
  const FlightLog log = FlightLog::Open(path);
  const std::vector<LogMotion> summary = log.Summary().motion;
  const Session s = log.Select(FlightLogSelection{});
  EXPECT_EQ(s.log_motion.size(), summary.size()) << path;
  return summary;
}

const LogMotion* First(const std::vector<LogMotion>& m, LogMotion::Evidence e) {
  for (const LogMotion& x : m) {
    if (x.evidence == e) return &x;
  }
  return nullptr;
}

TEST(LogMotionReal, ArdupilotCopterTakeOffAndLandingFromItsEvents) {
  const std::string path = kData + "/ardupilot/copter344_pixhawk1_oldformat.bin";
  SKIP_IF_ABSENT(path);
  const std::vector<LogMotion> m = MotionOf(path);
  const LogMotion* air = First(m, LogMotion::Evidence::kAirborne);
  ASSERT_NE(air, nullptr);
  EXPECT_NEAR(air->t_begin_s, 228.075573, 1e-6);  // EV 28 NOT_LANDED
  EXPECT_NEAR(air->t_end_s, 375.270177, 1e-6);    // EV 18 LAND_COMPLETE
  // The GPS: the last run climbs and lands, 369.3-373.7 s, up to 5.6 m/s over ground.
  const LogMotion& last = m.back();
  EXPECT_EQ(last.evidence, LogMotion::Evidence::kGpsMoving);
  EXPECT_NEAR(last.t_end_s, 373.72926, 1e-5);
  EXPECT_NEAR(last.max_ground_speed_m_s, 5.6022, 1e-3);
  EXPECT_NEAR(last.max_climb_m_s, 6.19, 1e-3);
  for (const LogMotion& x : m) EXPECT_GE(x.t_begin_s, 228.0) << Describe(x);
}

TEST(LogMotionReal, ArdupilotTextLogTakesItsGpsBootTime) {
  // The oldest layout: GPS TimeMS is the GPS's time of week; T is the boot time, in ms.
  const std::string path = kData + "/ardupilot/copter31_no_imu_rows.log";
  SKIP_IF_ABSENT(path);
  const FlightLog log = FlightLog::Open(path);
  const std::vector<LogMotion> m = log.Summary().motion;
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].evidence, LogMotion::Evidence::kGpsMoving);
  EXPECT_GT(m[0].t_begin_s, 60.0);
  EXPECT_LT(m[0].t_end_s, 200.0);
  EXPECT_NEAR(m[0].max_ground_speed_m_s, 12.2, 0.05);
}

TEST(LogMotionReal, APlaneOnTheGroundSaysNothing) {
  const std::string path = kData + "/ardupilot/plane408_centre_point.BIN";
  SKIP_IF_ABSENT(path);
  EXPECT_TRUE(MotionOf(path).empty());  // GPS at most 0.05 m/s: it never moved
}

TEST(LogMotionReal, Px4LandDetectorAndGps) {
  const std::string path = kData + "/px4/sample_px4_events.ulg";
  SKIP_IF_ABSENT(path);
  const std::vector<LogMotion> m = MotionOf(path);
  const LogMotion* air = First(m, LogMotion::Evidence::kAirborne);
  ASSERT_NE(air, nullptr);
  EXPECT_NEAR(air->t_begin_s, 1710773367.086, 1e-3);
  EXPECT_NEAR(air->t_end_s, 1710773378.478, 1e-3);
  EXPECT_EQ(air->source, "vehicle_land_detected not landed .. landed");
  // vehicle_gps_position: 1.01-1.05 m/s of climb for 7 reports, 1710773370.498-.810.
  const LogMotion* gps = First(m, LogMotion::Evidence::kGpsMoving);
  ASSERT_NE(gps, nullptr);
  EXPECT_NEAR(gps->t_begin_s, 1710773370.498, 1e-3);
  EXPECT_NEAR(gps->t_end_s, 1710773370.810, 1e-3);
  EXPECT_NEAR(gps->max_climb_m_s, 1.05, 1e-3);
}

// A tlog's GPS_RAW_INT carries no time the IMU's clock shares (time_usec may count from boot
// or from the unix epoch): each report is placed by the IMU frame received nearest to it.
TEST(TlogMotion, TheGpsIsPlacedOnTheImusClockByTheTlogTime) {
  using namespace testing;  // tlog_builder.h
  Bytes b;
  Append(&b, Record({0, Heartbeat(3)}));
  constexpr std::uint64_t kBoot_us = 5'000'000;  // the IMU's time since boot at the tlog's kT0
  for (int k = 0; k <= 100; ++k) {  // RAW_IMU at 10 Hz over 10 s of tlog time
    const std::uint64_t dt = static_cast<std::uint64_t>(k) * 100'000;
    FrameSpec imu{kMavRawImu, RawImu(kBoot_us + dt, {0, 0, -1000, 0, 0, 0, 0, 0, 0})};
    imu.time_us = kT0_us + dt;
    Append(&b, Record(imu));
    if (k % 2 == 0) {  // GPS at 5 Hz: moving at 5 m/s from 4 s to 6 s of tlog time
      const bool moving = k >= 40 && k <= 60;
      FrameSpec gps{kMavGpsRawInt, GpsRawInt(515000000, -25000000, 10000, 3,
                                             moving ? 500 : 5)};
      gps.time_us = kT0_us + dt + 30'000;  // received 30 ms after the IMU frame
      Append(&b, Record(gps));
    }
  }
  const MavlinkLog log = ParseTlog(b.data(), b.size(), "gps.tlog");
  const Session s = TlogSession(log, FlightLogSelection{});
  ASSERT_EQ(s.log_motion.size(), 1u);
  EXPECT_EQ(s.log_motion[0].source, "GPS_RAW_INT");
  EXPECT_NEAR(s.log_motion[0].t_begin_s, 5.0 + 4.03, 1e-6);
  EXPECT_NEAR(s.log_motion[0].t_end_s, 5.0 + 6.03, 1e-6);
  EXPECT_NEAR(s.log_motion[0].max_ground_speed_m_s, 5.0, 1e-9);
  EXPECT_NEAR(s.log_motion[0].ground_distance_m, 10.0, 1e-6);
}

TEST(LogMotionReal, ADisarmedTlogSaysNothing) {
  const std::string path = kData + "/mavlink/plane385_disarmed.tlog";
  SKIP_IF_ABSENT(path);
  EXPECT_TRUE(MotionOf(path).empty());
}

}  // namespace
}  // namespace plumb::io
