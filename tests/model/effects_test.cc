// Invariants that every registered effect must satisfy. The battery (tests/support/
// effect_battery.h, shared with tests/extension/) is instantiated over
// Registry::Global().Names(), so an effect added to effects/effects.cmake is tested here
// without touching this file. Effects with options are tested with each option listed in
// ExtraOptions() as well as with the default one.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/model/effects/accel_linear.h"
#include "plumb/model/model.h"
#include "plumb/model/registry.h"
#include "support/effect_battery.h"

namespace plumb::model {
namespace {

using ::plumb::testing::EffectCase;
using ::plumb::testing::EffectCaseName;
using ::plumb::testing::EffectInvariants;

/// Options tested besides the default one (keyed by effect name).
const std::map<std::string, std::vector<std::string>>& ExtraOptions() {
  static const std::map<std::string, std::vector<std::string>> extra = {
      {"accel_linear", {"full"}},
      {"gyro_linear", {"triangular"}},
      {"accel_temperature_bias", {"2", "3"}},
      {"gyro_temperature_bias", {"2", "3"}}};
  return extra;
}

std::vector<EffectCase> AllCases() {
  std::vector<EffectCase> cases;
  for (const auto& name : Registry::Global().Names()) {
    cases.push_back({name, ""});
    const auto it = ExtraOptions().find(name);
    if (it == ExtraOptions().end()) continue;
    for (const auto& option : it->second) cases.push_back({name, option});
  }
  return cases;
}

INSTANTIATE_TEST_SUITE_P(AllEffects, EffectInvariants, ::testing::ValuesIn(AllCases()),
                         EffectCaseName);

TEST(Registry, NamesAreUniqueAndCoverTheCatalogue) {
  const auto names = Registry::Global().Names();
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size());
  for (const char* expected :
       {"accel_bias_drift", "gyro_bias_drift", "accel_temperature_bias", "gyro_temperature_bias",
        "gyro_g_sensitivity", "accel_scale_nonlinearity", "gyro_scale_nonlinearity",
        "accel_size_effect", "time_offset"}) {
    EXPECT_TRUE(Registry::Global().Contains(expected)) << expected;
  }
}

TEST(TemperatureBias, OrderSetsTheParameterCountAndBadOrdersThrow) {
  EXPECT_EQ(Registry::Global().Make("accel_temperature_bias")->info().size(), 3);
  EXPECT_EQ(Registry::Global().Make("gyro_temperature_bias", "3")->info().size(), 9);
  EXPECT_EQ(Registry::Global().Make("accel_temperature_bias", "2")->info().ParameterName(4),
            "accel_temperature_bias.c2.y");
  EXPECT_THROW(Registry::Global().Make("accel_temperature_bias", "4"), Error);
  EXPECT_EQ(Model::Parse("base+gyro_temperature_bias:1").spec(), "base+gyro_temperature_bias");
  EXPECT_EQ(Model::Parse("base+gyro_temperature_bias:2").spec(), "base+gyro_temperature_bias:2");
}

TEST(TemperatureBias, CubicTermFollowsThePolynomial) {
  const Model m = Model::Parse("base+accel_temperature_bias:3");
  ParameterBlocks theta = m.ZeroParameters();
  theta[2] = {1e-3, 0, 0, 2e-5, 0, 0, -3e-7, 0, 0};
  SensorInput<double> in;
  in.dtemp_c = -8.0;
  const double expected = 1e-3 * -8.0 + 2e-5 * 64.0 - 3e-7 * -512.0;
  EXPECT_NEAR(m.Predict(theta, in).acc.x(), expected, 1e-15);
}

TEST(GyroGSensitivity, RowMajorMatrixTimesSpecificForce) {
  const Model m = Model::Parse("base+gyro_g_sensitivity");
  ParameterBlocks theta = m.ZeroParameters();
  theta[2][1] = 1e-3;  // G.xy: gyro x responds to f_b.y
  SensorInput<double> in;
  in.f_b = Vec3(0.0, 2.0, -9.8);
  EXPECT_NEAR(m.Predict(theta, in).gyr.x(), 2e-3, 1e-15);
  EXPECT_EQ(m.Predict(theta, in).gyr.y(), 0.0);
}

TEST(AccelSizeEffect, CentripetalAccelerationOfTheLeverArm) {
  const Model m = Model::Parse("base+accel_size_effect");
  ParameterBlocks theta = m.ZeroParameters();
  theta[2][1] = 0.01;  // r_y.y: the y accelerometer sits 1 cm along y
  SensorInput<double> in;
  in.omega_b = Vec3(0.0, 0.0, 2.0);  // spinning about z at 2 rad/s
  // Centripetal acceleration towards the axis: -omega^2 r = -0.04 m/s^2 along y.
  EXPECT_NEAR(m.Predict(theta, in).acc.y(), -0.04, 1e-15);
  EXPECT_EQ(m.Predict(theta, in).acc.x(), 0.0);
}

TEST(TimeOffset, FirstOrderShiftOfTheRate) {
  const Model m = Model::Parse("base+time_offset");
  ParameterBlocks theta = m.ZeroParameters();
  theta[2][0] = 0.002;
  SensorInput<double> in;
  in.omega_b = Vec3(0.1, 0.0, 0.0);
  in.alpha_b = Vec3(3.0, 0.0, 0.0);
  EXPECT_NEAR(m.Predict(theta, in).gyr.x(), 0.1 + 3.0 * 0.002, 1e-15);
}

}  // namespace
}  // namespace plumb::model

namespace plumb::model {
namespace {

TEST(AccelLinearBlock, MatrixRowAndColumnNameTheEntryEachValueMoves) {
  // The block layout of accel_linear.h, as SubtractForceJacobian reads it: value j moves
  // F(MatrixRow(j), MatrixCol(j)) and nothing else.
  for (const bool full : {false, true}) {
    const int size = full ? accel_linear::kSizeFull : accel_linear::kSize;
    for (int j = 0; j < size; ++j) {
      if (j >= accel_linear::kBias && j < accel_linear::kLower) continue;
      std::vector<double> block(static_cast<std::size_t>(size), 0.0);
      block[static_cast<std::size_t>(j)] = 0.5;
      Mat3 expected = Mat3::Identity();
      expected(accel_linear::MatrixRow(j), accel_linear::MatrixCol(j)) += 0.5;
      EXPECT_EQ(accel_linear::Matrix(block.data(), full), expected) << "value " << j;
    }
  }
}

}  // namespace
}  // namespace plumb::model
