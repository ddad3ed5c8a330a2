// plumb::autodiff: every built-in effect has its Jet form, found from the effect itself; an
// effect without one is refused by name; a program's effect gets one with RegisterJetForm; a
// model's terms on doubles give Model::Predict exactly and on Jets the same values.
#include "plumb/autodiff/differentiable_effect.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/model/model.h"
#include "plumb/model/registry.h"

namespace plumb::autodiff {
namespace {

/// A program's own effect, made here and never registered in the global catalogue (which the
/// other tests of this program read): y_a += k t.
class LocalDrift : public model::EffectBase<LocalDrift> {
 public:
  LocalDrift() : EffectBase(Describe()) {}
  static model::EffectInfo Describe() {
    model::EffectInfo info;
    info.name = "local_drift";
    info.prefix = info.name;
    info.sensor = model::Sensor::kAccel;
    info.term = "y_a += k t";
    info.parameters = model::AxisParameters("k", "m/s^3", 1e-4);
    return info;
  }
  template <typename T>
  void Term(const T* theta, const model::SensorInput<T>& in, model::SensorOutput<T>& out) const {
    out.acc += Eigen::Map<const Vec3T<T>>(theta) * in.dt_s;
  }
};

/// A second class, never given a Jet form.
class Unregistered : public model::EffectBase<Unregistered> {
 public:
  Unregistered() : EffectBase(LocalDrift::Describe()) {}
  template <typename T>
  void Term(const T*, const model::SensorInput<T>&, model::SensorOutput<T>&) const {}
};

TEST(DifferentiableEffect, EveryRegisteredEffectHasItsJetForm) {
  const auto& registry = model::Registry::Global();
  for (const std::string& name : registry.Names()) {
    const auto effect = registry.Make(name);
    EXPECT_NO_THROW(DifferentiableEffect{*effect}) << name;
  }
}

TEST(DifferentiableEffect, AnEffectWithoutAJetFormIsRefusedByName) {
  const Unregistered effect;
  try {
    DifferentiableEffect{effect};
    FAIL() << "an effect with no Jet form was accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'local_drift'"), std::string::npos) << what;
    EXPECT_NE(what.find("RegisterEffect"), std::string::npos) << what;
  }
}

TEST(DifferentiableEffect, RegisterJetFormGivesAProgramsEffectItsJetTerm) {
  const LocalDrift effect;
  RegisterJetForm<LocalDrift>();
  RegisterJetForm<LocalDrift>();  // again: nothing changes
  const DifferentiableEffect differentiable(effect);
  const double theta[3] = {1e-4, -2e-4, 3e-4};
  model::SensorInput<double> in;
  in.dt_s = 50.0;
  model::SensorOutput<double> y;
  differentiable.Apply(theta, in, y);
  Jet theta_jet[3] = {Jet(theta[0], 0), Jet(theta[1], 1), Jet(theta[2], 2)};
  model::SensorInput<Jet> in_jet;
  in_jet.dt_s = Jet(50.0);
  model::SensorOutput<Jet> y_jet;
  differentiable.Apply(theta_jet, in_jet, y_jet);
  for (int r = 0; r < 3; ++r) {
    EXPECT_DOUBLE_EQ(y_jet.acc[r].a, y.acc[r]);
    for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(y_jet.acc[r].v[c], r == c ? 50.0 : 0.0);
  }
}

TEST(DifferentiableModel, PredictOnDoublesIsTheModelsAndOnJetsTheSameValues) {
  model::Model m = model::Model::Parse(
      "base+accel_bias_drift+gyro_bias_drift+accel_temperature_bias:2+gyro_temperature_bias"
      "+gyro_g_sensitivity+accel_scale_nonlinearity+gyro_scale_nonlinearity+accel_size_effect"
      "+time_offset+earth_rate");
  model::ParameterBlocks theta = m.ZeroParameters();
  for (std::size_t t = 0; t < theta.size(); ++t) {
    for (std::size_t j = 0; j < theta[t].size(); ++j) {
      theta[t][j] = 1e-3 * (1.0 + 0.1 * static_cast<double>(t) - 0.07 * static_cast<double>(j));
    }
  }
  model::SensorInput<double> in;
  in.f_b = Vec3(0.3, -0.4, -9.7);
  in.omega_b = Vec3(0.2, -0.6, 0.5);
  in.alpha_b = Vec3(1.3, -0.7, 0.9);
  in.dt_s = 12.5;
  in.dtemp_c = 3.25;
  in.R_b_n = Mat3::Identity();
  const DifferentiableModel terms(m);
  ASSERT_EQ(terms.num_terms(), m.num_terms());
  std::vector<const double*> p;
  std::vector<std::vector<Jet>> jets(theta.size());
  std::vector<const Jet*> pj;
  for (std::size_t t = 0; t < theta.size(); ++t) {
    p.push_back(theta[t].data());
    for (double v : theta[t]) jets[t].push_back(Jet(v));
    pj.push_back(jets[t].data());
  }
  const auto expected = m.Predict(theta, in);
  const auto on_doubles = terms.Predict(p.data(), in);
  EXPECT_EQ(on_doubles.acc, expected.acc);
  EXPECT_EQ(on_doubles.gyr, expected.gyr);
  model::SensorInput<Jet> in_jet;
  in_jet.f_b = in.f_b.cast<Jet>();
  in_jet.omega_b = in.omega_b.cast<Jet>();
  in_jet.alpha_b = in.alpha_b.cast<Jet>();
  in_jet.dt_s = Jet(in.dt_s);
  in_jet.dtemp_c = Jet(in.dtemp_c);
  in_jet.R_b_n = in.R_b_n.cast<Jet>();
  const auto on_jets = terms.Predict(pj.data(), in_jet);
  for (int r = 0; r < 3; ++r) {
    EXPECT_NEAR(on_jets.acc[r].a, expected.acc[r], 1e-15 * (1.0 + std::abs(expected.acc[r])));
    EXPECT_NEAR(on_jets.gyr[r].a, expected.gyr[r], 1e-15 * (1.0 + std::abs(expected.gyr[r])));
  }
}

}  // namespace
}  // namespace plumb::autodiff
