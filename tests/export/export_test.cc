// plumb/export: temperature polynomial re-expansion, the firmware parameter files (written and
// read back), the error a diagonal firmware correction leaves on a session, Kalibr's noise.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>

#include "plumb/core/error.h"
#include "plumb/estimation/result.h"
#include "plumb/export/export.h"
#include "plumb/export/firmware.h"
#include "plumb/export/formats.h"
#include "plumb/export/kalibr.h"
#include "plumb/model/effects/accel_linear.h"
#include "plumb/model/model.h"

namespace plumb::exporter {
namespace {

using nlohmann::json;

constexpr double kG = 9.80665;

// ---- helpers --------------------------------------------------------------------------------

/// A hand-made calibration: `spec`'s model with the given blocks, one still segment per
/// specific force in `f_b` (100 samples each, noise-free outputs from the model), segment k at
/// temperature temps[k]. The series holds those samples; r.fit.still their means.
struct Session {
  estimation::CalibrationResult r;
  ImuSeries series;
};

Session MakeSession(const std::string& spec, const model::ParameterBlocks& theta,
                    const std::vector<Vec3>& f_b, const std::vector<double>& temps_c) {
  Session s;
  s.r.calibration.model = model::Model::Parse(spec);
  s.r.calibration.model.t_ref_s = 0.0;
  s.r.calibration.model.temp_ref_c = 25.0;
  s.r.calibration.theta = theta;
  s.r.calibration.has_gyro = s.r.calibration.model.has_gyro();
  const std::size_t per = 100;
  const double dt = 0.01;
  for (std::size_t k = 0; k < f_b.size(); ++k) {
    model::SensorInput<double> in;
    in.f_b = f_b[k];
    in.omega_b = Vec3(1e-5, -2e-5, 3e-5) * static_cast<double>(k + 1);
    in.dtemp_c = temps_c[k] - s.r.calibration.model.temp_ref_c;
    const auto out = s.r.calibration.model.Predict(s.r.calibration.theta, in);
    estimation::StillSegmentFit fit;
    fit.segment.begin = s.series.size();
    for (std::size_t i = 0; i < per; ++i) {
      s.series.t_s.push_back(static_cast<double>(s.series.size()) * dt);
      s.series.acc.push_back(out.acc.cast<float>());
      s.series.gyr.push_back(out.gyr.cast<float>());
      s.series.temp_c.push_back(static_cast<float>(temps_c[k]));
    }
    fit.segment.end = s.series.size();
    fit.t_mid_s = 0.0;  // no time-dependent terms in these models
    fit.acc_mean = out.acc;
    fit.gyr_mean = out.gyr;
    s.r.fit.still.push_back(fit);
  }
  return s;
}

/// Six faces: +-g along each axis.
std::vector<Vec3> SixFaces() {
  return {Vec3(0, 0, -kG), Vec3(0, 0, kG), Vec3(0, -kG, 0),
          Vec3(0, kG, 0),  Vec3(-kG, 0, 0), Vec3(kG, 0, 0)};
}

/// A firmware correction with temperature polynomials on both sensors.
FirmwareCorrection ThermalCorrection() {
  FirmwareCorrection fw;
  fw.has_gyro = true;
  fw.accel.scale = Vec3(1.01, 0.995, 1.002);
  fw.accel.offset = Vec3(0.12, -0.05, 0.31);
  fw.gyro.offset = Vec3(0.01, -0.02, 0.005);
  for (DiagonalCorrection* c : {&fw.accel, &fw.gyro}) {
    c->has_thermal = true;
    c->temp_min_c = 18.0;
    c->temp_max_c = 52.0;
    c->thermal.t0_c = 25.0;
    c->thermal.c[1] = Vec3(2e-3, -1e-3, 4e-3);
    c->thermal.c[2] = Vec3(-3e-5, 2e-5, 1e-5);
    c->thermal.c[3] = Vec3(4e-7, -2e-7, 1e-7);
  }
  return fw;
}

/// Largest difference between two corrections over outputs and temperatures (inside and
/// outside the clamp range).
double MaxDifference(const DiagonalCorrection& a, const DiagonalCorrection& b) {
  double worst = 0;
  for (double t : {0.0, 18.0, 25.0, 35.0, 44.5, 52.0, 70.0}) {
    for (const Vec3& y : {Vec3(0, 0, -9.8), Vec3(9.8, -0.3, 0.1), Vec3(0.02, 0.5, -0.01)}) {
      worst = std::max(worst, (a.Apply(y, t) - b.Apply(y, t)).cwiseAbs().maxCoeff());
    }
  }
  return worst;
}

// ---- temperature polynomial ------------------------------------------------------------------

TEST(TemperaturePolynomial, RebaseIsExactAtEveryTemperature) {
  std::mt19937_64 rng(20261122);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  TemperaturePolynomial p;
  p.t0_c = 25.0;
  for (int k = 0; k < 4; ++k) p.c[k] = Vec3(u(rng), u(rng), u(rng)) * std::pow(1e-2, k);
  const TemperaturePolynomial q = Rebase(p, 35.0);
  EXPECT_EQ(q.t0_c, 35.0);
  for (double t : {-20.0, 0.0, 25.0, 35.0, 47.3, 80.0}) {
    EXPECT_LT((p.At(t) - q.At(t)).cwiseAbs().maxCoeff(), 1e-12) << "T = " << t;
  }
  // q(35) is its constant term, p(35) by definition.
  EXPECT_LT((q.c[0] - p.At(35.0)).norm(), 1e-15);
}

TEST(TemperaturePolynomial, RebaseOfALineKeepsTheSlope) {
  TemperaturePolynomial p;
  p.t0_c = 25.0;
  p.c[1] = Vec3(2.0, -1.0, 0.5);
  const TemperaturePolynomial q = Rebase(p, 35.0);
  EXPECT_EQ(q.c[1], p.c[1]);
  EXPECT_EQ(q.c[0], Vec3(20.0, -10.0, 5.0));  // 10 degC above the old reference
  EXPECT_EQ(q.c[2], Vec3::Zero());
}

// ---- parameter files -------------------------------------------------------------------------

TEST(Ardupilot, ParameterFileRoundTripsAndReproducesTheCorrection) {
  const FirmwareCorrection fw = ThermalCorrection();
  const ParameterSet set = ArdupilotParameters(fw, 0);
  const std::string text = ArdupilotParamFile(set);
  const auto read = ReadArdupilotParamFile(text, "test.param");
  const auto written = set.Values();
  ASSERT_EQ(read.size(), written.size());
  for (const auto& [name, value] : written) {
    ASSERT_EQ(read.count(name), 1u) << name;
    EXPECT_NEAR(read.at(name), value, 1e-8 * std::max(1.0, std::abs(value))) << name;
  }
  const FirmwareCorrection back = ArdupilotCorrection(read, 0);
  EXPECT_LT(MaxDifference(back.accel, fw.accel), 1e-7);
  EXPECT_LT(MaxDifference(back.gyro, fw.gyro), 1e-7);
}

TEST(Ardupilot, NamesFollowTheInstanceAndTheTemperatureTermIsScaledAbout35C) {
  FirmwareCorrection fw;
  fw.has_gyro = true;
  fw.accel.offset = Vec3(0.1, 0.2, 0.3);
  fw.accel.has_thermal = true;
  fw.accel.temp_min_c = 20.0;
  fw.accel.temp_max_c = 40.0;
  fw.accel.thermal.t0_c = 25.0;
  fw.accel.thermal.c[1] = Vec3(1e-3, 0, 0);  // 1 mm/s^2 per degC on x
  const auto v = ArdupilotParameters(fw, 1).Values();
  EXPECT_EQ(v.at("INS_TCAL2_ENABLE"), 1.0);
  EXPECT_DOUBLE_EQ(v.at("INS_TCAL2_ACC1_X"), 1000.0);  // 1e-3 * 1e6
  EXPECT_EQ(v.at("INS_TCAL2_ACC2_X"), 0.0);
  EXPECT_EQ(v.at("INS_ACC2_CALTEMP"), 25.0);  // plumb's reference, inside [20, 40]
  EXPECT_DOUBLE_EQ(v.at("INS_ACC2OFFS_X"), 0.1);  // h(CALTEMP) = h(25) = 0
  EXPECT_EQ(v.count("INS_GYR2OFFS_X"), 1u);
  EXPECT_EQ(v.count("INS_ACCOFFS_X"), 0u);
  EXPECT_EQ(v.count("INS_GYR2_CALTEMP"), 0u);  // no gyro temperature term
  EXPECT_THROW(ArdupilotParameters(fw, 3), Error);
}

TEST(Ardupilot, ReferenceOutsideTheRangeMovesTheOffsetToTheCalibrationTemperature) {
  FirmwareCorrection fw = ThermalCorrection();
  fw.accel.thermal.t0_c = 10.0;  // below TMIN = 18: CALTEMP clamps to 18
  const auto v = ArdupilotParameters(fw, 0).Values();
  EXPECT_EQ(v.at("INS_ACC1_CALTEMP"), 18.0);
  EXPECT_NEAR(v.at("INS_ACCOFFS_Y"), fw.accel.offset.y() + fw.accel.thermal.At(18.0).y(), 1e-15);
  EXPECT_LT(MaxDifference(ArdupilotCorrection(v, 0).accel, fw.accel), 1e-12);
}

TEST(Ardupilot, MalformedLineIsAnInputErrorNamingTheLine) {
  try {
    ReadArdupilotParamFile("# c\nINS_ACCOFFS_X,0.1,2\n", "bad.param");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bad.param"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ReadArdupilotParamFile("INS_ACCOFFS_X nan\n", "bad.param"), InputError);
  EXPECT_EQ(ReadArdupilotParamFile("INS_ACCOFFS_X 0.25\n", "ok.param").at("INS_ACCOFFS_X"), 0.25);
}

TEST(Px4, ParameterFileRoundTripsAndReproducesTheCorrection) {
  const FirmwareCorrection fw = ThermalCorrection();
  const ParameterSet set = Px4Parameters(fw, Px4Slots::Same(2));
  const std::string text = Px4ParamsFile(set);
  EXPECT_NE(text.find("1\t1\tCAL_ACC2_XOFF\t"), std::string::npos) << text;
  EXPECT_NE(text.find("1\t1\tTC_A_ENABLE\t1\t6\n"), std::string::npos) << text;
  const auto read = ReadPx4ParamsFile(text, "test.params");
  for (const auto& [name, value] : set.Values()) {
    ASSERT_EQ(read.count(name), 1u) << name;
    EXPECT_NEAR(read.at(name), value, 1e-8 * std::max(1.0, std::abs(value))) << name;
  }
  EXPECT_EQ(read.at("TC_A2_TREF"), 25.0);
  const FirmwareCorrection back = Px4Correction(read, Px4Slots::Same(2));
  EXPECT_LT(MaxDifference(back.accel, fw.accel), 1e-7);
  EXPECT_LT(MaxDifference(back.gyro, fw.gyro), 1e-7);
  EXPECT_THROW(ReadPx4ParamsFile("1 1 CAL_ACC0_XOFF 0.1 9\n", "spaces.params"), InputError);
}

// ---- the error a diagonal correction leaves --------------------------------------------------

TEST(Evaluate, DiagonalModelLeavesNoErrorThroughEitherFile) {
  model::Model m = model::Model::Parse("base+accel_temperature_bias:2");
  model::ParameterBlocks theta = m.ZeroParameters();
  theta[0] = {0.01, 0, 0, -0.02, 0, 0.005, 0.15, -0.08, 0.3};  // F diagonal, b_a
  theta[1][9] = 0.01;  // gyro biases, E = I
  theta[1][10] = -0.02;
  theta[1][11] = 0.004;
  theta[2] = {2e-3, -1e-3, 5e-4, -2e-5, 1e-5, 3e-5};  // c1, c2
  const std::vector<double> temps = {20, 24, 29, 33, 38, 45};
  const Session s = MakeSession("base+accel_temperature_bias:2", theta, SixFaces(), temps);
  for (const char* format : {"ardupilot", "px4"}) {
    const ExportOutput out = Export(format, s.r.calibration, s.series, s.r.fit.still, ExportOptions{});
    const auto& a = out.json["accel_still"];
    EXPECT_EQ(a["segments"].get<int>(), 6);
    for (int i = 0; i < 3; ++i) {
      // float32 sample storage and 9-digit parameters: well under a micro-g.
      EXPECT_LT(a["max_abs"][i].get<double>(), 2e-6) << format << " axis " << i;
      EXPECT_LT(out.json["gyro_still"]["max_abs"][i].get<double>(), 1e-9) << format;
    }
    EXPECT_TRUE(out.json["dropped"].empty()) << out.json["dropped"].dump();
  }
}

/// Six faces between 20 and 45 degC with an accelerometer temperature bias: a session whose
/// export writes thermal terms (TC_A*, INS_TCAL*).
Session ThermalSession() {
  const model::Model m = model::Model::Parse("base+accel_temperature_bias");
  model::ParameterBlocks theta = m.ZeroParameters();
  theta[2] = {2e-3, -1e-3, 5e-4};
  return MakeSession("base+accel_temperature_bias", theta, SixFaces(), {20, 24, 29, 33, 38, 45});
}

TEST(VehicleState, TheFilesSayAndKeepWhatTheFirmwareWouldReplace) {
  // The boot-time gyro calibration (said, or turned off on request), the device ids the log
  // records (written, for the thermal terms too), the level left alone, the system id.
  const Session s = ThermalSession();
  ExportOptions options;
  options.log_params = {{"INS_GYR_CAL", 1}, {"SENS_IMU_AUTOCAL", 1}, {"CAL_ACC0_ID", 1245450},
                        {"CAL_GYRO0_ID", 2162688}};
  options.system_id = 7;
  const ExportOutput said = Export("ardupilot", s.r.calibration, s.series, s.r.fit.still, options);
  EXPECT_NE(said.text.find("while INS_GYR_CAL is 1 (the log: INS_GYR_CAL 1)"), std::string::npos) << said.text;
  EXPECT_NE(said.text.find("AHRS_TRIM_X/Y/Z"), std::string::npos);
  EXPECT_EQ(said.text.find("\nINS_GYR_CAL,"), std::string::npos);
  options.keep_gyro_offsets = true;
  const ExportOutput kept = Export("ardupilot", s.r.calibration, s.series, s.r.fit.still, options);
  EXPECT_NE(kept.text.find("\nINS_GYR_CAL,0\n"), std::string::npos) << kept.text;
  const ExportOutput px4 = Export("px4", s.r.calibration, s.series, s.r.fit.still, options);
  for (const char* line : {"\n7\t1\tSENS_IMU_AUTOCAL\t0\t6\n", "\n7\t1\tCAL_ACC0_ID\t1245450\t6\n",
                           "\n7\t1\tTC_A0_ID\t1245450\t6\n", "\n7\t1\tCAL_GYRO0_ID\t2162688\t6\n"}) {
    EXPECT_NE(px4.text.find(line), std::string::npos) << line << px4.text;
  }
  EXPECT_EQ(px4.text.find("TC_G0_ID"), std::string::npos);  // no gyro thermal term fitted
  // Without the log: the ids are not written and said so; system id 1, said so.
  const ExportOutput plain = Export("px4", s.r.calibration, s.series, s.r.fit.still, ExportOptions{});
  EXPECT_EQ(plain.text.find("_ID\t"), std::string::npos) << plain.text;
  EXPECT_NE(plain.text.find("are not written (the input does not record them)"), std::string::npos);
  EXPECT_NE(plain.text.find("\n1\t1\tCAL_ACC0_XOFF"), std::string::npos);
  EXPECT_NE(plain.text.find("ExportOptions::system_id = N gives it"), std::string::npos);
  // The advice carries its code and the option it points to, for a program to act on.
  const auto note = [](const ExportOutput& out, const std::string& code) -> const Notice* {
    for (const Notice& n : out.parameters->notes) {
      if (n.code == code) return &n;
    }
    return nullptr;
  };
  ASSERT_NE(note(said, "gyro_offsets_replaced"), nullptr);
  EXPECT_EQ(note(said, "gyro_offsets_replaced")->options, std::vector<Option>{Option::kKeepGyroOffsets});
  ASSERT_NE(note(kept, "gyro_offsets_kept"), nullptr);
  ASSERT_NE(note(plain, "system_id"), nullptr);
  EXPECT_EQ(note(plain, "system_id")->options, std::vector<Option>{Option::kSystemId});
  EXPECT_TRUE(note(px4, "system_id")->options.empty());  // given: nothing to point to
}

TEST(Px4, EachSensorsSlotIsTheOneHoldingItsDeviceId) {
  // PX4 finds a sensor's calibration by its device id (sensor_calibration/Utilities.cpp,
  // FindCurrentCalibrationIndex), not by its instance; a sensor no slot holds gets a free one,
  // its instance's first (FindAvailableCalibrationIndex).
  ExportOptions options;
  options.imu = 0;
  options.device_ids = {111.0, 222.0};
  options.log_params = {{"CAL_ACC0_ID", 999}, {"CAL_ACC1_ID", 111},  {"CAL_GYRO0_ID", 222},
                        {"CAL_GYRO1_ID", 999}, {"TC_A2_ID", 111},    {"TC_G0_ID", 0}};
  const Px4Slots slots = Px4SlotsOf(options);
  EXPECT_EQ(slots.acc, 1);
  EXPECT_EQ(slots.gyro, 0);
  EXPECT_EQ(slots.tc_acc, 2);
  EXPECT_EQ(slots.tc_gyro, 0);  // held by no device: the instance's, free
  // A new accelerometer: its instance's slot holds another device, so the first free one.
  options.device_ids.accel = 333.0;
  EXPECT_EQ(Px4SlotsOf(options).acc, 2);
  // Every slot another device's: refused, naming them.
  options.log_params["CAL_ACC2_ID"] = 444;
  options.log_params["CAL_ACC3_ID"] = 555;
  try {
    Px4SlotsOf(options);
    ADD_FAILURE() << "a calibration written over another sensor's slot";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no slot of CAL_ACC is free for device 333"),
              std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("CAL_ACC3_ID 555"), std::string::npos) << e.what();
  }
  // Without device ids: the instance's slots, as before.
  options.device_ids = {};
  options.imu = 3;
  const Px4Slots same = Px4SlotsOf(options);
  EXPECT_EQ(same.acc, 3);
  EXPECT_EQ(same.gyro, 3);
}

TEST(Px4, TheFileWritesEachSensorInItsOwnSlotWithItsDeviceId) {
  // Instance 0's accelerometer calibrated in slot 1, its gyroscope in slot 0: the file writes
  // CAL_ACC1_* and CAL_GYRO0_*, each with the sensor's device id, and reads back the same.
  const Session s = ThermalSession();
  ExportOptions options;
  options.device_ids = {1245450.0, 2162688.0};
  options.log_params = {{"CAL_ACC0_ID", 1310986}, {"CAL_ACC1_ID", 1245450},
                        {"CAL_GYRO0_ID", 2162688}, {"CAL_GYRO1_ID", 1310986}};
  const ExportOutput px4 = Export("px4", s.r.calibration, s.series, s.r.fit.still, options);
  for (const char* line : {"\n1\t1\tCAL_ACC1_XOFF\t", "\n1\t1\tCAL_ACC1_ID\t1245450\t6\n",
                           "\n1\t1\tCAL_GYRO0_ZOFF\t", "\n1\t1\tCAL_GYRO0_ID\t2162688\t6\n",
                           "\n1\t1\tTC_A0_ID\t1245450\t6\n"}) {
    EXPECT_NE(px4.text.find(line), std::string::npos) << line << px4.text;
  }
  for (const char* absent : {"CAL_ACC0_", "CAL_GYRO1_", "CAL_ACC0_ID"}) {
    EXPECT_EQ(px4.text.find(absent), std::string::npos) << absent << px4.text;
  }
  EXPECT_NE(px4.text.find("which the log's CAL_ACC1_ID holds"), std::string::npos) << px4.text;
  // What the file's correction leaves is plumb's (read back from the slots written).
  ASSERT_TRUE(px4.report.has_value());
  EXPECT_LT(px4.report->accel_still.max_abs.maxCoeff(), 1e-3);
}

TEST(VehicleState, AFirmwareWithoutTheBootCalibrationFlagGetsANoteInsteadOfIt) {
  // A PX4 log from before SENS_IMU_AUTOCAL (../shared/data/px4/sample_log_small.ulg): its
  // parameter table has the accelerometer calibration and not the flag, so the flag is not
  // written; an ArduPilot file from the same log says nothing of ArduPilot's table.
  const Session s = MakeSession("base", model::Model::Parse("base").ZeroParameters(), SixFaces(),
                                {25, 25, 25, 25, 25, 25});
  ExportOptions options;
  options.log_params = {{"CAL_ACC0_XOFF", 0.1}, {"CAL_ACC0_ID", 1245450}};
  options.keep_gyro_offsets = true;
  const ExportOutput px4 = Export("px4", s.r.calibration, s.series, s.r.fit.still, options);
  EXPECT_EQ(px4.text.find("\tSENS_IMU_AUTOCAL\t"), std::string::npos) << px4.text;
  EXPECT_NE(px4.text.find("the firmware of the log has no SENS_IMU_AUTOCAL"), std::string::npos)
      << px4.text;
  const ExportOutput ardupilot = Export("ardupilot", s.r.calibration, s.series, s.r.fit.still, options);
  EXPECT_NE(ardupilot.text.find("\nINS_GYR_CAL,0\n"), std::string::npos) << ardupilot.text;
}

TEST(Evaluate, OffDiagonalTermMatchesTheHandComputation) {
  model::Model m = model::Model::Parse("base");
  model::ParameterBlocks theta = m.ZeroParameters();
  theta[0][1] = 0.01;  // F_xy: y_a,x = f_x + 0.01 f_y
  const std::vector<Vec3> f = {Vec3(0, 0, -kG), Vec3(0, -kG, 0), Vec3(0, kG, 0)};
  const Session s = MakeSession("base", theta, f, {25, 25, 25});
  const FirmwareCorrection fw = BestDiagonal(s.r.calibration, SessionTemperatureRange(s.series));
  EXPECT_NEAR((fw.accel.scale - Vec3::Ones()).norm(), 0.0, 1e-15);  // diag(F^-1) = 1
  const ExportReport rep = Evaluate(s.r.calibration, s.series, s.r.fit.still, fw, "ardupilot", true);
  // Firmware: y - b = F f, plumb: f, so the x error is 0.01 f_y: 0, -0.01 g, +0.01 g.
  EXPECT_NEAR(rep.accel_still.rms.x(), 0.01 * kG * std::sqrt(2.0 / 3.0), 1e-6);
  EXPECT_NEAR(rep.accel_still.max_abs.x(), 0.01 * kG, 1e-6);
  EXPECT_LT(rep.accel_still.max_abs.y(), 1e-6);
  EXPECT_LT(rep.accel_still.max_abs.z(), 1e-6);
  EXPECT_NEAR(rep.accel_per_input(0, 1), 0.01, 1e-15);
}

TEST(Evaluate, EffectsTheTargetHasNoParameterForAreListed) {
  model::Model m = model::Model::Parse("base+gyro_g_sensitivity");
  model::ParameterBlocks theta = m.ZeroParameters();
  theta[2][0] = 1e-4;
  const Session s = MakeSession("base+gyro_g_sensitivity", theta, SixFaces(),
                                std::vector<double>(6, 25.0));
  const ExportReport rep =
      Evaluate(s.r.calibration, s.series, s.r.fit.still, BestDiagonal(s.r.calibration, SessionTemperatureRange(s.series)), "px4", true);
  ASSERT_EQ(rep.dropped.size(), 1u);
  EXPECT_EQ(rep.dropped[0].effect, "gyro_g_sensitivity");
  EXPECT_EQ(rep.dropped[0].values[0], 1e-4);
  // The g-sensitivity term G_xx f_x shows on the x gyro in the two x faces: 1e-4 g.
  EXPECT_NEAR(rep.gyro_still.max_abs.x(), 1e-4 * kG, 1e-7);
}

TEST(Evaluate, CountsAreRefused) {
  Session s = MakeSession("base", model::Model::Parse("base").ZeroParameters(), SixFaces(),
                          std::vector<double>(6, 25.0));
  s.r.calibration.acc_unit = "counts";
  EXPECT_THROW(BestDiagonal(s.r.calibration, TemperatureRange{}), Error);
  EXPECT_THROW(KalibrNoise(s.r.calibration, s.series, s.r.fit.still, "/imu0"), Error);
  EXPECT_THROW(Export("ardupilot", s.r.calibration, s.series, s.r.fit.still, ExportOptions{}), Error);
}

// ---- what each format would write, for a page ------------------------------------------------

TEST(PreviewExports, EveryFormatWithItsNumbersOrWhyNot) {
  model::Model m = model::Model::Parse("base");
  model::ParameterBlocks theta = m.ZeroParameters();
  theta[0][1] = 0.01;  // F_xy: what a diagonal correction cannot carry
  const std::vector<Vec3> f = {Vec3(0, 0, -kG), Vec3(0, -kG, 0), Vec3(0, kG, 0)};
  Session s = MakeSession("base", theta, f, {25, 25, 25});
  std::vector<ExportPreview> previews =
      PreviewExports(s.r.calibration, s.series, s.r.fit.still, ExportOptions{});
  ASSERT_EQ(previews.size(), 3u);
  EXPECT_EQ(previews[0].format, "ardupilot");
  EXPECT_EQ(previews[1].format, "px4");
  EXPECT_EQ(previews[2].format, "kalibr");
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE(previews[i].output) << previews[i].refused;
    const ExportOutput& out = *previews[i].output;
    ASSERT_TRUE(out.report && out.parameters);
    // The same numbers as Export()'s JSON, and the hand computation's (Evaluate test above).
    EXPECT_NEAR(out.report->accel_still.max_abs.x(), 0.01 * kG, 1e-6);
    EXPECT_EQ(out.json["accel_still"]["max_abs"][0].get<double>(), out.report->accel_still.max_abs.x());
    EXPECT_EQ(out.parameters->Values().count(i == 0 ? "INS_ACCSCAL_X" : "CAL_ACC0_XSCALE"), 1u);
  }
  // A reason known beforehand refuses the firmware formats without building them.
  previews = PreviewExports(s.r.calibration, s.series, s.r.fit.still, ExportOptions{},
                            "the log's rotation is not undone");
  EXPECT_FALSE(previews[0].output);
  EXPECT_EQ(previews[1].refused, "the log's rotation is not undone");
  EXPECT_NE(previews[2].refused, "the log's rotation is not undone");
  // What Export() refuses is carried, not thrown.
  estimation::ParameterEstimate lost;
  lost.name = "accel.bias.x";
  lost.place = {s.r.calibration.model.BaseTerm(model::Sensor::kAccel), model::accel_linear::kBias};
  lost.unit = "m/s^2";
  lost.observable = false;
  s.r.calibration.parameters = {lost};
  previews = PreviewExports(s.r.calibration, s.series, s.r.fit.still, ExportOptions{});
  EXPECT_FALSE(previews[0].output);
  EXPECT_NE(previews[0].refused.find("does not determine accel.bias.x"), std::string::npos)
      << previews[0].refused;
}

// ---- Kalibr ----------------------------------------------------------------------------------

/// Key -> value of a flat `key: value  # comment` YAML text.
std::map<std::string, std::string> FlatYaml(const std::string& text) {
  std::map<std::string, std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const auto colon = line.find(':');
    std::string value = line.substr(colon + 1);
    value = value.substr(0, value.find('#'));
    value.erase(0, value.find_first_not_of(' '));
    value.erase(value.find_last_not_of(' ') + 1);
    out[line.substr(0, colon)] = value;
  }
  return out;
}

TEST(Kalibr, WhiteNoiseDensityMatchesTheAllanDeviationAtOneSecond) {
  // One 120 s still segment of white noise at 100 Hz.
  const double dt = 0.01, sigma_a = 0.02, sigma_g = 0.001;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  Session s;
  s.r.calibration.model = model::Model::Parse("base");
  s.r.calibration.theta = s.r.calibration.model.ZeroParameters();
  s.r.calibration.has_gyro = true;
  for (int i = 0; i < 12000; ++i) {
    s.series.t_s.push_back(i * dt);
    s.series.acc.push_back(Vec3f(sigma_a * n(rng), sigma_a * n(rng), -kG + sigma_a * n(rng)));
    s.series.gyr.push_back(Vec3f(sigma_g * n(rng), sigma_g * n(rng), sigma_g * n(rng)));
  }
  estimation::StillSegmentFit fit;
  fit.segment.begin = 0;
  fit.segment.end = s.series.size();
  s.r.fit.still.push_back(fit);
  s.r.calibration.noise.acc = Vec3::Constant(sigma_a);
  s.r.calibration.noise.gyr = Vec3::Constant(sigma_g);
  const KalibrImu imu = KalibrNoise(s.r.calibration, s.series, s.r.fit.still, "/imu0");
  EXPECT_NEAR(imu.update_rate_hz, 100.0, 1e-6);
  EXPECT_TRUE(imu.accel.low_from_allan);
  EXPECT_NEAR(imu.accel.white_sample.x(), sigma_a * std::sqrt(dt), 1e-15);
  for (int i = 0; i < 3; ++i) {
    // White noise: ADEV(1 s) = sigma sqrt(dt), within the estimator's scatter.
    EXPECT_NEAR(imu.accel.white_low[i] / (sigma_a * std::sqrt(dt)), 1.0, 0.1) << i;
    EXPECT_NEAR(imu.gyro.white_low[i] / (sigma_g * std::sqrt(dt)), 1.0, 0.1) << i;
    // N is the IEEE fit's, resolved on every axis, and agrees with both fallbacks.
    EXPECT_TRUE(imu.gyro.white_from_ieee[i]) << i;
    EXPECT_EQ(imu.gyro.white[i], imu.gyro.white_ieee[i]);
    EXPECT_NEAR(imu.gyro.white[i] / (sigma_g * std::sqrt(dt)), 1.0, 0.03) << i;
    EXPECT_NEAR(imu.accel.white[i] / (sigma_a * std::sqrt(dt)), 1.0, 0.03) << i;
    EXPECT_FALSE(imu.accel.walk_from_ieee[i]) << i;
  }
  // White noise has no random walk: the bound is small but the +1/2 slope is not there.
  EXPECT_FALSE(imu.accel.walk_resolved);
  EXPECT_GT(imu.accelerometer_random_walk(), 0.0);
  EXPECT_LT(imu.accelerometer_random_walk(), sigma_a * std::sqrt(dt));

  const auto yaml = FlatYaml(KalibrYaml(imu));
  EXPECT_EQ(yaml.at("rostopic"), "/imu0");
  EXPECT_NEAR(std::stod(yaml.at("update_rate")), 100.0, 1e-4);
  EXPECT_NEAR(std::stod(yaml.at("accelerometer_noise_density")),
              imu.accelerometer_noise_density(), 1e-5 * imu.accelerometer_noise_density());  // 6 digits
  EXPECT_NEAR(std::stod(yaml.at("gyroscope_random_walk")), imu.gyroscope_random_walk(),
              1e-5 * imu.gyroscope_random_walk());
  EXPECT_NE(KalibrYaml(imu).find("upper bound"), std::string::npos);
}

/// An accelerometer-only session of `samples` white samples (sigma) every dt, cut into still
/// segments of `segment` samples, whose calibration states the noise sigma and the
/// correlation time tau (samples).
Session AccelOnly(std::size_t samples, std::size_t segment, double dt, double sigma, double tau) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0.0, sigma);
  Session s;
  s.r.calibration.model = model::Model::Parse("base");
  s.r.calibration.model.DropGyro();
  s.r.calibration.theta = s.r.calibration.model.ZeroParameters();
  for (std::size_t i = 0; i < samples; ++i) {
    s.series.t_s.push_back(static_cast<double>(i) * dt);
    s.series.acc.push_back(Vec3f(n(rng), n(rng), -kG + n(rng)));
  }
  for (std::size_t begin = 0; begin + segment <= samples; begin += segment) {
    estimation::StillSegmentFit fit;
    fit.segment.begin = begin;
    fit.segment.end = begin + segment;
    s.r.fit.still.push_back(fit);
  }
  s.r.calibration.noise.acc = Vec3::Constant(sigma);
  s.r.calibration.noise.tau_acc = tau;
  return s;
}

TEST(Kalibr, ShortSegmentsFallBackToTheAutocorrelationTime) {
  // Still segments of 6 samples (30 ms): too short for ADEV at 1 s and for the IEEE terms; the
  // low-frequency level is then sigma sqrt(tau dt), which the stated correlation time
  // (tau = 4 samples) makes the larger.
  const double dt = 0.005, sigma = 0.01, tau = 4.0;
  const Session s = AccelOnly(400, 6, dt, sigma, tau);
  const KalibrImu imu = KalibrNoise(s.r.calibration, s.series, s.r.fit.still, "/imu");
  EXPECT_FALSE(imu.accel.low_from_allan);
  EXPECT_FALSE(imu.accel.white_from_ieee[0]);
  EXPECT_NEAR(imu.accelerometer_noise_density(), sigma * std::sqrt(tau * dt), 1e-15);
  EXPECT_FALSE(imu.has_gyro);
  const std::string yaml = KalibrYaml(imu);
  EXPECT_EQ(yaml.find("gyroscope"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("rostopic: /imu\n"), std::string::npos) << yaml;
  EXPECT_EQ(yaml.find("N of the IEEE noise fit"), std::string::npos) << yaml;
  const json j = ToJson(imu);
  EXPECT_EQ(j["accel"]["noise_density_source"][0], "fallback");
  bool said = false;
  for (const Notice& note : imu.notes) {
    said = said || (note.code == "noise_terms_unresolved" &&
                     note.message.find("no IEEE noise terms") == 0);
  }
  EXPECT_TRUE(said);
}

TEST(Kalibr, NoiseDensityOfTheIeeeFitWhereItIsResolved) {
  // 2 s of white still data: too short for ADEV at 1 s, long enough for the white noise's
  // -1/2 slope: N is the IEEE fit's, sigma sqrt(dt), not the stated correlation's larger level.
  const double dt = 0.005, sigma = 0.01, tau = 4.0;
  const Session s = AccelOnly(400, 400, dt, sigma, tau);
  const KalibrImu imu = KalibrNoise(s.r.calibration, s.series, s.r.fit.still, "/imu");
  EXPECT_FALSE(imu.accel.low_from_allan);
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(imu.accel.white_from_ieee[i]) << i;
    EXPECT_NEAR(imu.accel.white[i] / (sigma * std::sqrt(dt)), 1.0, 0.1) << i;
  }
  EXPECT_NE(KalibrYaml(imu).find("N of the IEEE noise fit"), std::string::npos);
  const json j = ToJson(imu);
  EXPECT_EQ(j["accel"]["noise_density_source"], json({"ieee_fit", "ieee_fit", "ieee_fit"}));
}

TEST(Kalibr, RandomWalkOfTheIeeeFitWhereItIsResolved) {
  // Ten minutes of still data at 100 Hz with a bias random walk K on white noise N: the +1/2
  // slope shows from sqrt(3) N / K = 6 s on, and K comes from the fit.
  const double dt = 0.01, n_a = 1e-3, k_a = 3e-4;
  std::mt19937_64 rng(12);
  std::normal_distribution<double> e(0.0, 1.0);
  Session s;
  s.r.calibration.model = model::Model::Parse("base");
  s.r.calibration.model.DropGyro();
  s.r.calibration.theta = s.r.calibration.model.ZeroParameters();
  Vec3 bias = Vec3::Zero();
  for (int i = 0; i < 60000; ++i) {
    for (int a = 0; a < 3; ++a) bias[a] += k_a * std::sqrt(dt) * e(rng);
    const Vec3 white(e(rng), e(rng), e(rng));
    s.series.t_s.push_back(i * dt);
    s.series.acc.push_back((bias + n_a / std::sqrt(dt) * white + Vec3(0, 0, -kG)).cast<float>());
  }
  estimation::StillSegmentFit fit;
  fit.segment.end = s.series.size();
  s.r.fit.still.push_back(fit);
  s.r.calibration.noise.acc = Vec3::Constant(n_a / std::sqrt(dt));
  const KalibrImu imu = KalibrNoise(s.r.calibration, s.series, s.r.fit.still, "/imu0");
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(imu.accel.walk_from_ieee[i]) << i;
    EXPECT_EQ(imu.accel.walk[i], imu.accel.walk_ieee[i]) << i;
    // One realisation of ten minutes: K to about 10 % (one sigma), 0.61 on y here (its long
    // clusters happen to sit low); the statistics are tested in tests/signal.
    EXPECT_NEAR(imu.accel.walk[i] / k_a, 1.0, 0.5) << i;
    EXPECT_NEAR(imu.accel.white[i] / n_a, 1.0, 0.03) << i;
  }
  EXPECT_TRUE(imu.accel.walk_resolved);
  EXPECT_EQ(KalibrYaml(imu).find("upper bound"), std::string::npos);
  EXPECT_EQ(ToJson(imu)["accel"]["random_walk_source"][2], "ieee_fit");
}

TEST(Kalibr, EveryNumberReadsAsAYamlFloat) {
  // Kalibr reads its yaml with PyYAML's safe_load (YAML 1.1), which takes "5e-05" for a string
  // and "5.0e-05" for a float; a string then fails Kalibr's check `value <= 0.0`.
  KalibrBoardImu board_imu;
  KalibrImu& imu = board_imu.noise;
  imu.has_gyro = true;
  imu.update_rate_hz = 100.0;
  imu.accel.white = Vec3(1e-5, 2e-6, 3e-6);
  imu.accel.walk = Vec3::Constant(4e-4);
  imu.gyro.white = Vec3::Constant(2.5e-5);
  imu.gyro.walk = Vec3::Constant(3.0);
  board_imu.time_offset_s = 5e-5;  // one sample at 20 kHz
  const std::string set = KalibrImuSetYaml({board_imu});
  for (const char* line : {"update_rate: 100.0  #", "accelerometer_noise_density: 1.0e-05  #",
                           "accelerometer_random_walk: 0.0004  #",
                           "gyroscope_noise_density: 2.5e-05  #",
                           "gyroscope_random_walk: 3.0  #", "time_offset: 5.0e-05  #"}) {
    EXPECT_NE(set.find(line), std::string::npos) << line << "\n" << set;
  }
  EXPECT_NE(KalibrYaml(imu).find("accelerometer_noise_density: 1.0e-05  #"), std::string::npos);
}

TEST(Kalibr, WhatKalibrCannotReadIsRefused) {
  // Kalibr reads a gyroscope's noise for every IMU, and refuses a random walk of 0: an
  // accelerometer-only session, or one with nothing still, is refused with the reason.
  const Session accel_only = AccelOnly(400, 400, 0.005, 0.01, 1.0);
  try {
    Export("kalibr", accel_only.r.calibration, accel_only.series, accel_only.r.fit.still, {});
    ADD_FAILURE() << "an accelerometer-only session exported to Kalibr";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no gyroscope"), std::string::npos) << e.what();
  }
  try {
    KalibrNoise(accel_only.r.calibration, accel_only.series, {}, "/imu0");
    ADD_FAILURE() << "a session with no still segment measured for Kalibr";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no still segment"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace plumb::exporter
