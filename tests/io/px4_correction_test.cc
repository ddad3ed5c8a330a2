// PX4's correction as functions of the parameters (io/px4/px4_correction.h): the rotation
// table, choosing CAL_*n by device id, the thermal polynomial, and the undo inverting PX4's
// forward correction.
#include "plumb/io/px4/px4_correction.h"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

namespace plumb::io {
namespace {

using Params = std::map<std::string, double>;

TEST(Px4Correction, RotationTable) {
  EXPECT_EQ(*Px4RotationEuler(0), Vec3(0, 0, 0));
  EXPECT_EQ(*Px4RotationEuler(12), Vec3(0, 180, 0));
  EXPECT_EQ(*Px4RotationEuler(25), Vec3(0, 270, 0));
  EXPECT_FALSE(Px4RotationEuler(26).has_value());
  EXPECT_FALSE(Px4RotationEuler(1.5).has_value());
  EXPECT_FALSE(Px4RotationEuler(-1).has_value());
  // Yaw 90: x forward becomes y.
  const Vec3 v = Px4EulerRotation(Vec3(0, 0, 90)) * Vec3::UnitX();
  EXPECT_NEAR(v.y(), 1.0, 1e-15);
  EXPECT_NEAR(v.x(), 0.0, 1e-15);
}

TEST(Px4Correction, CalibrationChosenByDeviceId) {
  Params p = {{"CAL_ACC0_ID", 11}, {"CAL_ACC1_ID", 22}, {"CAL_ACC1_XOFF", 0.1},
              {"CAL_ACC1_YOFF", 0.2}, {"CAL_ACC1_ZOFF", 0.3}, {"CAL_ACC1_XSCALE", 1.01},
              {"SENS_BOARD_ROT", 4}};
  std::string why;
  const auto c = Px4CalibrationFor(p, "ACC", 22.0, "test", &why);
  ASSERT_TRUE(c.has_value()) << why;
  EXPECT_EQ(c->prefix, "CAL_ACC1");
  EXPECT_EQ(c->offset, Vec3(0.1, 0.2, 0.3));
  EXPECT_EQ(c->scale, Vec3(1.01, 1.0, 1.0));
  EXPECT_NEAR((c->rotation * Vec3::UnitX()).x(), -1.0, 1e-15);  // yaw 180
  EXPECT_FALSE(Px4CalibrationFor(p, "ACC", 33.0, "test", &why).has_value());
  EXPECT_EQ(why, "no CAL_ACCn_ID equals the device id 33 (from test)");
  EXPECT_FALSE(Px4CalibrationFor(p, "ACC", std::nullopt, "test", &why).has_value());
  EXPECT_EQ(why, "the log does not say which sensor it is (no device id)");
  EXPECT_FALSE(Px4CalibrationFor(p, "ACC", 11.0, "test", &why).has_value());
  EXPECT_EQ(why, "CAL_ACC0_XOFF is not in the log");
}

TEST(Px4Correction, ThermalPolynomialClampsTheTemperature) {
  Px4Thermal t;
  t.t_ref_c = 25;
  t.t_min_c = 0;
  t.t_max_c = 50;
  t.x = {Vec3(1, 0, 0), Vec3(0.1, 0, 0), Vec3(0.01, 0, 0), Vec3(0.001, 0, 0)};
  EXPECT_DOUBLE_EQ(t.Offset(25).x(), 1.0);
  EXPECT_DOUBLE_EQ(t.Offset(35).x(), 1.0 + 1.0 + 1.0 + 1.0);
  EXPECT_DOUBLE_EQ(t.Offset(90).x(), t.Offset(50).x());
}

TEST(Px4Correction, UndoInvertsTheForwardCorrection) {
  Params p = {{"CAL_ACC0_ID", 7},        {"CAL_ACC0_XOFF", 0.2},  {"CAL_ACC0_YOFF", -0.1},
              {"CAL_ACC0_ZOFF", 0.05},   {"CAL_ACC0_XSCALE", 1.02}, {"CAL_ACC0_YSCALE", 0.98},
              {"CAL_ACC0_ZSCALE", 1.01}, {"SENS_BOARD_ROT", 2},    {"SENS_BOARD_X_OFF", 1.5}};
  Px4Sensors sensors;
  sensors.acc_id = 7;
  sensors.acc_id_source = "test";
  sensors.temperature = [](bool, double) { return std::optional<Px4TemperatureTrack>(); };
  std::string why;
  const auto c = Px4CalibrationFor(p, "ACC", 7.0, "test", &why);
  ASSERT_TRUE(c.has_value()) << why;
  const Vec3 m(0.3, -0.2, -9.7);  // the sensor's own output
  ImuSeries s;
  s.t_s = {0.0};
  s.acc = {(c->rotation * (m - c->offset).cwiseProduct(c->scale)).cast<float>()};  // logged
  std::vector<Notice> warnings;
  std::vector<std::string> left;
  UndoPx4Correction(p, sensors, "acc: ", &s, &warnings, &left);
  EXPECT_NEAR(s.acc[0].x(), m.x(), 1e-5);
  EXPECT_NEAR(s.acc[0].y(), m.y(), 1e-5);
  EXPECT_NEAR(s.acc[0].z(), m.z(), 1e-5);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].message.rfind("acc: accelerometer reconstructed", 0), 0u)
      << warnings[0].message;
  EXPECT_EQ(warnings[0].code, "correction_undone");
  EXPECT_TRUE(left.empty());
  EXPECT_EQ(Px4AppliedText(p, sensors), "CAL_ACC0_*, CAL_GYROn_*, board rotation");
  EXPECT_TRUE(Px4Undoable(p, sensors, false));
  EXPECT_FALSE(Px4Undoable(p, sensors, true));
}

}  // namespace
}  // namespace plumb::io
