#include "plumb/model/model.h"

#include <gtest/gtest.h>

#include "plumb/core/error.h"
#include "plumb/model/registry.h"

namespace plumb::model {
namespace {

TEST(Model, BaseSpecHasTheLinearEffects) {
  const Model m = Model::Parse("base");
  EXPECT_EQ(m.spec(), "base");
  ASSERT_EQ(m.num_terms(), 2);
  EXPECT_EQ(m.num_parameters(), 21);
  EXPECT_TRUE(m.has_gyro());
  EXPECT_EQ(m.ParameterNames()[1], "accel.matrix.xy");
  EXPECT_EQ(m.ParameterNames()[20], "gyro.bias.z");
}

TEST(Model, PaperSpecFixesTheLowerTriangleOfE) {
  const Model m = Model::Parse("paper");
  EXPECT_EQ(m.spec(), "paper");
  EXPECT_EQ(m.num_free_parameters(), 18);
}

TEST(Model, UnknownEffectNamesTheCatalogue) {
  try {
    Model::Parse("base+nonsense");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("accel_bias_drift"), std::string::npos);
  }
}

TEST(Model, ZeroParametersGiveIdentity) {
  const Model m = Model::Parse("base+accel_bias_drift");
  SensorInput<double> in;
  in.f_b = Vec3(0.1, -0.2, -9.8);
  in.omega_b = Vec3(0.3, 0.2, -0.1);
  in.dt_s = 12.0;
  const auto out = m.Predict(m.ZeroParameters(), in);
  EXPECT_LT((out.acc - in.f_b).norm(), 1e-15);
  EXPECT_LT((out.gyr - in.omega_b).norm(), 1e-15);
}

}  // namespace
}  // namespace plumb::model
