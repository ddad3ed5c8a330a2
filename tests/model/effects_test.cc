// Invariants that every registered effect must satisfy. The battery is parameterised over
// Registry::Global().Names(), so an effect added to effects/effects.cmake is tested here
// without touching this file. Effects with options are tested with each option listed in
// kExtraOptions as well as with the default one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <ostream>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/model/model.h"
#include "plumb/model/registry.h"

namespace plumb::model {
namespace {

/// One case of the battery: an effect name and the option it is made with.
struct EffectCase {
  std::string name;
  std::string option;
};

void PrintTo(const EffectCase& c, std::ostream* os) {
  *os << c.name << (c.option.empty() ? "" : ":" + c.option);
}

std::string CaseName(const testing::TestParamInfo<EffectCase>& info) {
  return info.param.name + (info.param.option.empty() ? "" : "_" + info.param.option);
}

/// Options tested besides the default one (keyed by effect name).
const std::map<std::string, std::vector<std::string>>& ExtraOptions() {
  static const std::map<std::string, std::vector<std::string>> extra = {
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

/// The base model with the effect under test: the base effects themselves are made with the
/// case's option; any other effect is appended to "base".
Model ModelWith(const EffectCase& c) {
  Model m;
  m.Add("accel_linear", c.name == "accel_linear" ? c.option : "");
  m.Add("gyro_linear", c.name == "gyro_linear" ? c.option : "");
  if (!m.has_effect(c.name)) m.Add(c.name, c.option);
  return m;
}

/// An input that excites every effect: tilted specific force, rotation, angular acceleration,
/// time and temperature away from their references.
SensorInput<double> ExcitedInput() {
  SensorInput<double> in;
  in.f_b = Vec3(1.3, -2.1, -9.4);
  in.omega_b = Vec3(0.8, -0.5, 1.1);
  in.alpha_b = Vec3(-1.7, 2.3, 0.9);
  in.dt_s = 120.0;
  in.dtemp_c = 11.0;
  return in;
}

/// Parameter blocks drawn around zero with sigma = scale * typical; fixed parameters stay 0.
ParameterBlocks RandomParameters(const Model& m, double scale, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  ParameterBlocks theta = m.ZeroParameters();
  for (std::size_t k = 0; k < theta.size(); ++k) {
    const auto& term = m.terms()[k];
    for (std::size_t i = 0; i < theta[k].size(); ++i) {
      if (term.fixed[i]) continue;
      theta[k][i] = scale * term.effect->info().parameters[i].typical * normal(rng);
    }
  }
  return theta;
}

/// Stacked prediction (y_a, y_g) as one 6-vector.
Eigen::Matrix<double, 6, 1> Stack(const SensorOutput<double>& out) {
  Eigen::Matrix<double, 6, 1> y;
  y << out.acc, out.gyr;
  return y;
}

SensorInput<Jet> ToJet(const SensorInput<double>& in) {
  SensorInput<Jet> j;
  j.f_b = in.f_b.cast<Jet>();
  j.omega_b = in.omega_b.cast<Jet>();
  j.alpha_b = in.alpha_b.cast<Jet>();
  j.dt_s = Jet(in.dt_s);
  j.dtemp_c = Jet(in.dtemp_c);
  return j;
}

/// Jet-valued blocks equal to theta, with the infinitesimals seeded on parameters
/// [first, first + kJetStride) of block `seeded`.
std::vector<std::vector<Jet>> SeededJets(const ParameterBlocks& theta, std::size_t seeded,
                                         std::size_t first) {
  std::vector<std::vector<Jet>> blocks;
  for (std::size_t k = 0; k < theta.size(); ++k) {
    std::vector<Jet> block;
    for (std::size_t i = 0; i < theta[k].size(); ++i) {
      Jet v(theta[k][i]);
      if (k == seeded && i >= first && i < first + kJetStride) {
        v.v[static_cast<int>(i - first)] = 1.0;
      }
      block.push_back(v);
    }
    blocks.push_back(block);
  }
  return blocks;
}

SensorOutput<Jet> PredictJet(const Model& m, const std::vector<std::vector<Jet>>& blocks,
                             const SensorInput<Jet>& in) {
  std::vector<const Jet*> ptr;
  for (const auto& b : blocks) ptr.push_back(b.data());
  return m.Predict<Jet>(ptr.data(), in);
}

class EffectInvariants : public testing::TestWithParam<EffectCase> {};

TEST_P(EffectInvariants, ZeroParametersAreTheIdentity) {
  const Model m = ModelWith(GetParam());
  const SensorInput<double> in = ExcitedInput();
  const auto out = m.Predict(m.ZeroParameters(), in);
  EXPECT_EQ(out.acc, in.f_b);
  EXPECT_EQ(out.gyr, in.omega_b);
}

TEST_P(EffectInvariants, CorrectInvertsPredict) {
  const Model m = ModelWith(GetParam());
  std::mt19937_64 rng(20240611);
  for (int trial = 0; trial < 5; ++trial) {
    const ParameterBlocks theta = RandomParameters(m, 1.0, rng);
    const SensorInput<double> in = ExcitedInput();
    const auto out = m.Predict(theta, in);
    const auto [f_b, omega_b] = m.Correct(theta, out.acc, out.gyr, in);
    EXPECT_LT((f_b - in.f_b).norm(), 1e-9 * in.f_b.norm()) << "trial " << trial;
    EXPECT_LT((omega_b - in.omega_b).norm(), 1e-9 * in.omega_b.norm()) << "trial " << trial;
  }
}

TEST_P(EffectInvariants, JetPredictionAndDerivativeMatchDoubles) {
  const Model m = ModelWith(GetParam());
  const std::size_t k = static_cast<std::size_t>(m.FindTerm(GetParam().name));
  std::mt19937_64 rng(77);
  const ParameterBlocks theta = RandomParameters(m, 1.0, rng);
  const SensorInput<double> in = ExcitedInput();
  const auto y = Stack(m.Predict(theta, in));
  for (std::size_t first = 0; first < theta[k].size(); first += kJetStride) {
    const auto jet_out = PredictJet(m, SeededJets(theta, k, first), ToJet(in));
    const std::size_t last = std::min(theta[k].size(), first + kJetStride);
    for (std::size_t i = first; i < last; ++i) {
      // Central difference with a step of 1e-3 of the typical size.
      const double h = 1e-3 * m.terms()[k].effect->info().parameters[i].typical;
      ParameterBlocks plus = theta, minus = theta;
      plus[k][i] += h;
      minus[k][i] -= h;
      const Eigen::Matrix<double, 6, 1> numeric =
          (Stack(m.Predict(plus, in)) - Stack(m.Predict(minus, in))) / (2 * h);
      for (int r = 0; r < 6; ++r) {
        const Jet& yr = r < 3 ? jet_out.acc(r) : jet_out.gyr(r - 3);
        EXPECT_NEAR(yr.a, y(r), 1e-12 * (1.0 + std::abs(y(r)))) << "output " << r;
        const double analytic = yr.v[static_cast<int>(i - first)];
        EXPECT_NEAR(analytic, numeric(r), 1e-6 * (1.0 + std::abs(numeric(r))))
            << m.terms()[k].effect->info().ParameterName(static_cast<int>(i)) << " output " << r;
      }
    }
  }
}

TEST_P(EffectInvariants, InfoIsComplete) {
  const Model m = ModelWith(GetParam());
  const auto& info = m.terms()[static_cast<std::size_t>(m.FindTerm(GetParam().name))].effect->info();
  EXPECT_EQ(info.name, GetParam().name);
  EXPECT_FALSE(info.prefix.empty());
  EXPECT_FALSE(info.term.empty());
  const auto& x = info.excitation;
  EXPECT_TRUE(x.still_orientations || x.rotation || x.angular_acceleration || x.temperature ||
              x.time)
      << "an effect must say what data excites it";
  std::set<std::string> names;
  for (int i = 0; i < info.size(); ++i) {
    const auto& p = info.parameters[static_cast<std::size_t>(i)];
    EXPECT_FALSE(p.name.empty());
    EXPECT_FALSE(p.unit.empty()) << p.name;
    EXPECT_GT(p.typical, 0.0) << p.name;
    EXPECT_TRUE(names.insert(p.name).second) << "duplicate parameter " << p.name;
  }
  // Full names are unique across the whole model.
  const auto all = m.ParameterNames();
  EXPECT_EQ(std::set<std::string>(all.begin(), all.end()).size(), all.size());
}

TEST_P(EffectInvariants, EveryParameterChangesAnExcitedPrediction) {
  const Model m = ModelWith(GetParam());
  const std::size_t k = static_cast<std::size_t>(m.FindTerm(GetParam().name));
  const auto& info = m.terms()[k].effect->info();
  const SensorInput<double> in = ExcitedInput();
  const auto y0 = Stack(m.Predict(m.ZeroParameters(), in));
  for (int i = 0; i < info.size(); ++i) {
    ParameterBlocks theta = m.ZeroParameters();
    const double typical = info.parameters[static_cast<std::size_t>(i)].typical;
    theta[k][static_cast<std::size_t>(i)] = typical;
    const auto y = Stack(m.Predict(theta, in));
    // Every input of ExcitedInput() is of order one or more, so a live parameter moves the
    // prediction by at least a fraction of its typical size.
    EXPECT_GT((y - y0).norm(), 1e-2 * typical) << info.ParameterName(i) << " is a silent no-op";
  }
}

INSTANTIATE_TEST_SUITE_P(AllEffects, EffectInvariants, testing::ValuesIn(AllCases()), CaseName);

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
