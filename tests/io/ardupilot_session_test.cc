// An ArduPilot log as a session (io/ardupilot/ardupilot_session.h): the INS_* correction undone,
// the time window, the site from the GPS, on a real still log; ArduPilot's rotation table and
// temperature polynomial (io/ardupilot/ardupilot_correction.h); the undo of AHRS_ORIENTATION and
// INS_TCAL on synthetic logs made with ArduPilot's forward correction, and on a real rotated log.
#include "plumb/io/ardupilot/ardupilot_session.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/io/ardupilot/ardupilot_correction.h"

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
  for (const auto& w : raw.warnings) {
    if (w.message.find("reconstructed") == std::string::npos) continue;
    said = true;
    EXPECT_EQ(w.code, "correction_undone");
  }
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

// --- AHRS_ORIENTATION and INS_TCAL (ardupilot_correction.h) ---------------------------------

namespace plumb::io {
namespace {

TEST(ArdupilotRotation, EveryTableEntryIsAProperRotation) {
  for (int r = 0; r <= 43; ++r) {
    const std::optional<Mat3> R = ArdupilotRotation(r);
    ASSERT_TRUE(R.has_value()) << r;
    EXPECT_LT((*R * R->transpose() - Mat3::Identity()).norm(), 1e-12) << r;
    EXPECT_NEAR(R->determinant(), 1.0, 1e-12) << r;
    EXPECT_NE(ArdupilotRotationName(r), "unknown") << r;
  }
  for (int r : {-1, 44, 99, 100, 101, 102, 103}) EXPECT_FALSE(ArdupilotRotation(r)) << r;
  EXPECT_EQ(ArdupilotRotationName(101), "CUSTOM");
}

TEST(ArdupilotRotation, EntriesMatchArduPilotsVectorRotate) {
  // Vector3::rotate in AP_Math (rotations as ArduPilot writes them out component-wise).
  const Vec3 x(1, 0, 0), y(0, 1, 0);
  EXPECT_EQ(*ArdupilotRotation(8), Vec3(1, -1, -1).asDiagonal().toDenseMatrix());  // ROLL_180
  EXPECT_EQ(*ArdupilotRotation(2) * x, Vec3(0, 1, 0));   // YAW_90: x' = -y, y' = x
  EXPECT_EQ(*ArdupilotRotation(24) * x, Vec3(0, 0, -1));  // PITCH_90: x' = z, z' = -x
  EXPECT_EQ(*ArdupilotRotation(16) * y, Vec3(0, 0, 1));   // ROLL_90: y' = -z, z' = y
  const double h = std::sqrt(0.5);
  EXPECT_LT((*ArdupilotRotation(1) * x - Vec3(h, h, 0)).norm(), 1e-15);  // YAW_45
  // ROTATION_ROLL_90_PITCH_68_YAW_293: ArduPilot's hard-coded first row.
  const Vec3 row0(0.14303897231223747, 0.36877648650320382, -0.91844638134308709);
  EXPECT_LT((ArdupilotRotation(38)->row(0).transpose() - row0).norm(), 1e-15);
  // ROTATION_PITCH_7: sin(7 deg) = 0.12186934340514748.
  EXPECT_NEAR((*ArdupilotRotation(41))(2, 0), -0.12186934340514748, 1e-15);
}

TEST(ArdupilotRotation, ApplyThenInvertIsTheIdentity) {
  std::mt19937_64 rng(4242);
  std::normal_distribution<double> n(0.0, 3.0);
  for (int r = 0; r <= 43; ++r) {
    const Mat3 R = *ArdupilotRotation(r);
    const Vec3 v(n(rng), n(rng), n(rng));
    EXPECT_LT((R.transpose() * (R * v) - v).norm(), 1e-12) << r;
  }
}

TEST(ArdupilotTempCal, PolynomialAndClamping) {
  ArdupilotTempCal t;
  t.t_min_degc = 10;
  t.t_max_degc = 50;
  const std::array<Vec3, 3> c{Vec3(1e4, 0, 0), Vec3(0, 100, 0), Vec3(0, 0, 1)};
  // P(d) = (c1 + (c2 + c3 d) d) d * 1e-6, d = T - 35.
  EXPECT_LT((ArdupilotTcalPolynomial(c, 5.0) - Vec3(0.05, 2.5e-3, 1.25e-4)).norm(), 1e-15);
  // T = 60 clamps to 50; T_cal = -300 clamps to 10.
  const Vec3 expected = ArdupilotTcalPolynomial(c, 15.0) - ArdupilotTcalPolynomial(c, -25.0);
  EXPECT_LT((ArdupilotTcalCorrection(t, c, 60.0, -300.0) - expected).norm(), 1e-15);
}

/// A text log: PARMs, then IMU rows "TimeUS, I, GyrX..Z, AccX..Z, T".
std::string SyntheticLog(const std::map<std::string, double>& params,
                         const std::vector<std::array<double, 7>>& rows) {
  std::string text =
      "FMT, 128, 89, FMT, BBnNZ, Type,Length,Name,Format,Columns\n"
      "FMT, 129, 23, PARM, Nf, Name,Value\n"
      "FMT, 130, 40, IMU, QBfffffff, TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,T\n";
  char line[256];
  for (const auto& [name, value] : params) {
    std::snprintf(line, sizeof line, "PARM, %s, %.9g\n", name.c_str(), value);
    text += line;
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    std::snprintf(line, sizeof line, "IMU, %zu, 0, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g\n",
                  1000000 + 10000 * i, r[0], r[1], r[2], r[3], r[4], r[5], r[6]);
    text += line;
  }
  return text;
}

std::map<std::string, double> CalibrationParams(int orientation) {
  std::map<std::string, double> p = {
      {"AHRS_ORIENTATION", orientation},
      {"INS_ACCOFFS_X", 0.3}, {"INS_ACCOFFS_Y", -0.2}, {"INS_ACCOFFS_Z", 0.5},
      {"INS_ACCSCAL_X", 1.02}, {"INS_ACCSCAL_Y", 0.97}, {"INS_ACCSCAL_Z", 1.01},
      {"INS_GYROFFS_X", 0.01}, {"INS_GYROFFS_Y", -0.02}, {"INS_GYROFFS_Z", 0.005},
      {"INS_TCAL1_ENABLE", 1}, {"INS_TCAL1_TMIN", 10}, {"INS_TCAL1_TMAX", 50},
      {"INS_ACC1_CALTEMP", 25}, {"INS_GYR1_CALTEMP", 30}};
  const char* axes[3] = {"_X", "_Y", "_Z"};
  for (int k = 1; k <= 3; ++k) {
    for (int a = 0; a < 3; ++a) {
      const double scale = k == 1 ? 2e3 : k == 2 ? 50 : 2;  // ~0.002 m/s^2 per degC
      p["INS_TCAL1_ACC" + std::to_string(k) + axes[a]] = scale * (a + 1);
      p["INS_TCAL1_GYR" + std::to_string(k) + axes[a]] = -0.1 * scale * (a + 1);
    }
  }
  return p;
}

/// ArduPilot's forward correction (AP_InertialSensor_Backend::_rotate_and_correct_*, with the
/// temperature step of AP_InertialSensor_tempcal.cpp), written out from the equations.
std::array<double, 7> ForwardCorrection(const std::map<std::string, double>& p, const Vec3& acc,
                                        const Vec3& gyr, double temp_c) {
  const auto triad = [&](const std::string& name) {
    return Vec3(p.at(name + "_X"), p.at(name + "_Y"), p.at(name + "_Z"));
  };
  const auto poly = [&](const std::string& kind, double t) {
    const double d = std::clamp(t, p.at("INS_TCAL1_TMIN"), p.at("INS_TCAL1_TMAX")) - 35.0;
    const Vec3 c1 = triad("INS_TCAL1_" + kind + "1"), c2 = triad("INS_TCAL1_" + kind + "2"),
               c3 = triad("INS_TCAL1_" + kind + "3");
    return Vec3((c1 * d + c2 * d * d + c3 * d * d * d) * 1e-6);
  };
  const Mat3 R = *ArdupilotRotation(static_cast<int>(p.at("AHRS_ORIENTATION")));
  const Vec3 a_t = acc - poly("ACC", temp_c) + poly("ACC", p.at("INS_ACC1_CALTEMP"));
  const Vec3 a_log = R * (a_t - triad("INS_ACCOFFS")).cwiseProduct(triad("INS_ACCSCAL"));
  const Vec3 g_t = gyr - poly("GYR", temp_c) + poly("GYR", p.at("INS_GYR1_CALTEMP"));
  const Vec3 g_log = R * (g_t - triad("INS_GYROFFS"));
  return {g_log.x(), g_log.y(), g_log.z(), a_log.x(), a_log.y(), a_log.z(), temp_c};
}

TEST(ArdupilotSession, UndoRecoversRawSamplesForEveryRotation) {
  std::mt19937_64 rng(20260101);
  std::normal_distribution<double> acc(0.0, 6.0), gyr(0.0, 0.5);
  std::uniform_real_distribution<double> temp(0.0, 60.0);  // beyond TMIN/TMAX both sides
  for (int orientation : {0, 2, 8, 12, 25, 36, 38, 41, 43}) {
    const std::map<std::string, double> params = CalibrationParams(orientation);
    std::vector<Vec3> raw_acc, raw_gyr;
    std::vector<std::array<double, 7>> rows;
    for (int i = 0; i < 20; ++i) {
      raw_acc.emplace_back(acc(rng), acc(rng), acc(rng));
      raw_gyr.emplace_back(gyr(rng), gyr(rng), gyr(rng));
      rows.push_back(ForwardCorrection(params, raw_acc.back(), raw_gyr.back(), temp(rng)));
    }
    const std::string text = SyntheticLog(params, rows);
    const DataflashLog log = ParseDataflashText(text.data(), text.size(), "synthetic.log");
    const Session s = ArdupilotSession(log, FlightLogSelection{});
    ASSERT_EQ(s.series.size(), 20u);
    for (int i = 0; i < 20; ++i) {
      EXPECT_LT((s.series.acc[i].cast<double>() - raw_acc[i]).norm(), 2e-5) << orientation;
      EXPECT_LT((s.series.gyr[i].cast<double>() - raw_gyr[i]).norm(), 2e-6) << orientation;
    }
    bool tcal_said = false;
    for (const auto& w : s.warnings) {
      tcal_said = tcal_said || w.message.find("INS_TCAL1 temperature calibration undone") !=
                                   std::string::npos;
    }
    EXPECT_TRUE(tcal_said) << orientation;
  }
}

TEST(ArdupilotSession, CustomOrientationIsNotUndoneAndSaysSo) {
  const std::map<std::string, double> params = CalibrationParams(0);
  std::map<std::string, double> custom = params;
  custom["AHRS_ORIENTATION"] = 101;
  const std::vector<std::array<double, 7>> rows = {{0.1, 0.2, 0.3, 1, 2, -9.8, 30},
                                                   {0.1, 0.2, 0.3, 1, 2, -9.8, 30}};
  const std::string text = SyntheticLog(custom, rows);
  const DataflashLog log = ParseDataflashText(text.data(), text.size(), "custom.log");
  const Session s = ArdupilotSession(log, FlightLogSelection{});
  EXPECT_EQ(s.series.acc[0], Vec3f(1, 2, -9.8f));  // as logged
  bool said = false;
  for (const auto& w : s.warnings) {
    said = said || (w.message.find("AHRS_ORIENTATION = 101 (CUSTOM)") != std::string::npos &&
                    w.message.find("not undone") != std::string::npos);
  }
  EXPECT_TRUE(said);
  EXPECT_FALSE(DataflashImuStreams(log)[0].undoable);
  ASSERT_EQ(s.firmware_left.size(), 1u);  // the whole correction stays in the samples
  EXPECT_NE(s.firmware_left[0].find("INS_ACCOFFS"), std::string::npos) << s.firmware_left[0];
}

TEST(ArdupilotSession, ACorrectionChangedDuringTheLogIsSaid) {
  const std::vector<std::array<double, 7>> rows = {{0.1, 0.2, 0.3, 1, 2, -9.8, 30},
                                                   {0.1, 0.2, 0.3, 1, 2, -9.8, 30}};
  std::string text = SyntheticLog(CalibrationParams(0), rows);
  text += "PARM, INS_ACCOFFS_X, 0.75\n";  // recalibrated while logging
  const DataflashLog log = ParseDataflashText(text.data(), text.size(), "recal.log");
  const Session s = ArdupilotSession(log, FlightLogSelection{});
  bool said = false;
  for (const auto& w : s.warnings) {
    if (w.message.find("changed during the log (INS_ACCOFFS_X)") == std::string::npos) continue;
    said = true;
    EXPECT_EQ(w.code, "correction_changed");
  }
  EXPECT_TRUE(said);
  const Session same = ArdupilotSession(
      [&] {
        const std::string t = SyntheticLog(CalibrationParams(0), rows);
        return ParseDataflashText(t.data(), t.size(), "steady.log");
      }(),
      FlightLogSelection{});
  for (const auto& w : same.warnings) EXPECT_EQ(w.message.find("changed during the log"), std::string::npos);
}

TEST(ArdupilotSession, ANonFiniteParameterIsNotUsedAndSaysWhatStays) {
  std::map<std::string, double> params = CalibrationParams(0);
  params["INS_ACCSCAL_Y"] = std::nan("");
  const std::vector<std::array<double, 7>> rows = {{0.1, 0.2, 0.3, 1, 2, -9.8, 30},
                                                   {0.1, 0.2, 0.3, 1, 2, -9.8, 30}};
  const std::string text = SyntheticLog(params, rows);
  const DataflashLog log = ParseDataflashText(text.data(), text.size(), "nan.log");
  EXPECT_FALSE(ArdupilotCorrectionFor(log.params, 0).acc_scale.has_value());
  const Session s = ArdupilotSession(log, FlightLogSelection{});
  EXPECT_TRUE(s.series.acc[0].allFinite());
  bool acc_left = false;
  for (const auto& l : s.firmware_left) {
    acc_left = acc_left || l.find("INS_ACCOFFS/INS_ACCSCAL") != std::string::npos;
  }
  EXPECT_TRUE(acc_left);
}

TEST(ArdupilotSession, TemperatureCalibrationWithoutTemperatureIsSaid) {
  std::map<std::string, double> params = CalibrationParams(0);
  std::string text = SyntheticLog(params, {});
  text += "FMT, 131, 35, ACC, QBQfff, TimeUS,I,SampleUS,AccX,AccY,AccZ\n"
          "ACC, 1000, 0, 1000, 0, 0, -9.8\n"
          "ACC, 2000, 0, 2000, 0, 0, -9.8\n";
  const DataflashLog log = ParseDataflashText(text.data(), text.size(), "acc.log");
  FlightLogSelection acc;
  acc.stream = "ACC";
  const Session s = ArdupilotSession(log, acc);
  bool said = false;
  for (const auto& w : s.warnings) {
    said = said || w.message.find("INS_TCAL1_ENABLE = 1 but the stream has no temperature") !=
                       std::string::npos;
  }
  EXPECT_TRUE(said);
  EXPECT_FALSE(s.series.has_gyro());
  EXPECT_NEAR(s.series.acc[0].z(), -9.8 / 1.01 + 0.5, 1e-5);  // offsets/scales still undone
}

TEST(ArdupilotSession, UndoesAhrsOrientationOfARealLog) {
  const std::string path =
      std::string(PLUMB_SHARED_DATA_DIR) + "/ardupilot/plane382_pymavlink_test.BIN";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
  const DataflashLog log = ReadDataflash(path);
  ASSERT_EQ(log.params.at("AHRS_ORIENTATION"), 8.0);  // ROLL_180: R = diag(1, -1, -1)
  const ImuSeries logged = ImuFromDataflash(log, 0);
  const Session raw = ArdupilotSession(log, FlightLogSelection{});
  const Vec3 sign(1, -1, -1);
  for (int i = 0; i < 3; ++i) {
    const std::string axis = std::string("_") + "XYZ"[i];
    const double scal = log.params.at("INS_ACCSCAL" + axis);
    const double offs = log.params.at("INS_ACCOFFS" + axis);
    const double gyr = log.params.at("INS_GYROFFS" + axis);
    EXPECT_NEAR(raw.series.acc[5][i], sign[i] * logged.acc[5][i] / scal + offs, 1e-5);
    EXPECT_NEAR(raw.series.gyr[5][i], sign[i] * logged.gyr[5][i] + gyr, 1e-6);
  }
  bool said = false;
  for (const auto& w : raw.warnings) {
    said = said || w.message.find("AHRS_ORIENTATION = 8 (ROLL_180) undone") != std::string::npos;
  }
  EXPECT_TRUE(said);
}

}  // namespace
}  // namespace plumb::io
