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

/// The role a parameter's full name implies (the names are SPEC section 2's contract): what
/// Model::Role must answer from the layout without reading the name.
ParameterRole RoleByName(const std::string& name) {
  const auto starts = [&](const char* prefix) { return name.rfind(prefix, 0) == 0; };
  if (starts("accel.bias.") || starts("gyro.bias.")) return ParameterRole::kBias;
  if (starts("accel.matrix.") || starts("gyro.matrix.")) {
    const std::string rc = name.substr(name.size() - 2);
    return rc[0] == rc[1] ? ParameterRole::kScale : ParameterRole::kCrossAxis;
  }
  if (starts("accel_temperature_bias.") || starts("gyro_temperature_bias.")) {
    return ParameterRole::kTemperatureBias;
  }
  return ParameterRole::kOther;
}

TEST(Model, LayoutAnswersWhatEachParameterIs) {
  std::vector<std::string> specs = {"base", "paper", "accel_linear:full+gyro_linear+gyro_bias_drift",
                                    "base+accel_temperature_bias:3+gyro_temperature_bias"};
  for (const std::string& effect : Registry::Global().CatalogueNames()) {
    specs.push_back("base+" + effect);
  }
  for (const std::string& spec : specs) {
    const Model m = Model::Parse(spec);
    const char* axes = "xyz";
    for (int t = 0; t < m.num_terms(); ++t) {
      const EffectInfo& info = m.terms()[static_cast<std::size_t>(t)].effect->info();
      for (int i = 0; i < info.size(); ++i) {
        const std::string name = info.ParameterName(i);
        const ParameterPlace place{t, i};
        EXPECT_EQ(m.Role(place), RoleByName(name)) << spec << " " << name;
        EXPECT_EQ(m.SensorOf(place), info.sensor) << spec << " " << name;
      }
    }
    for (const Sensor sensor : {Sensor::kAccel, Sensor::kGyro}) {
      const std::string prefix = sensor == Sensor::kAccel ? "accel.matrix." : "gyro.matrix.";
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
          const std::string name = prefix + axes[r] + axes[c];
          const auto by_name = m.FindParameter(name);
          const auto entry = m.MatrixEntry(sensor, r, c);
          ASSERT_EQ(entry.has_value(), by_name.has_value()) << spec << " " << name;
          if (entry) EXPECT_EQ(*entry, (ParameterPlace{by_name->first, by_name->second})) << name;
        }
      }
      const int thermal = m.TemperatureBiasTerm(sensor);
      EXPECT_EQ(thermal, m.FindTerm(sensor == Sensor::kAccel ? "accel_temperature_bias"
                                                             : "gyro_temperature_bias"))
          << spec;
    }
  }
}

TEST(Model, FixByPlaceIsFixByName) {
  Model by_name = Model::Parse("paper");
  Model by_place = by_name;
  by_name.Fix("accel.matrix.xy");
  by_place.Fix(*by_place.MatrixEntry(Sensor::kAccel, 0, 1));
  for (int t = 0; t < by_name.num_terms(); ++t) {
    EXPECT_EQ(by_name.terms()[static_cast<std::size_t>(t)].fixed,
              by_place.terms()[static_cast<std::size_t>(t)].fixed);
  }
  EXPECT_THROW(by_place.Fix(ParameterPlace{0, 99}), Error);
  EXPECT_THROW(by_place.Fix(ParameterPlace{7, 0}), Error);
}

}  // namespace
}  // namespace plumb::model
