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
  // The option's held parameters are the effect's own (EffectInfo::held), by layout.
  const ModelTerm& gyro = m.terms()[static_cast<std::size_t>(m.BaseTerm(Sensor::kGyro))];
  for (int j = 0; j < gyro.effect->info().size(); ++j) {
    const std::string name = gyro.effect->info().ParameterName(j);
    const bool lower = name == "gyro.matrix.yx" || name == "gyro.matrix.zx" || name == "gyro.matrix.zy";
    EXPECT_EQ(gyro.fixed[static_cast<std::size_t>(j)], lower) << name;
  }
}

// Each alias is written back as itself, with or without terms after it, and its terms spelled
// out read as the alias.
TEST(Model, AliasesReadAndWriteAsThemselves) {
  for (const std::string spec : {"base", "paper", "base+accel_bias_drift", "paper+gyro_bias_drift"}) {
    EXPECT_EQ(Model::Parse(spec).spec(), spec);
  }
  EXPECT_EQ(Model::Parse("accel_linear+gyro_linear:triangular+accel_bias_drift").spec(),
            "paper+accel_bias_drift");
  EXPECT_EQ(Model::Parse("accel_linear+gyro_linear").spec(), "base");
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
