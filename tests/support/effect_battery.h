// tests/support/effect_battery.h — the invariants every effect must satisfy, as the
// value-parameterised GoogleTest suite `EffectInvariants` over EffectCase {name, option}:
//
//   ZeroParametersAreTheIdentity          an all-zero block changes no prediction;
//   CorrectInvertsPredict                 Model::Correct undoes Model::Predict (1e-9 relative);
//   JetPredictionAndDerivativeMatchDoubles  the effect's Jet form (plumb::autodiff) gives the
//                                         double value, and the Jet derivative of every
//                                         parameter matches a central difference (1e-6
//                                         relative);
//   InfoIsComplete                        name, prefix, term, excitation, units, typical > 0,
//                                         unique parameter names;
//   EveryParameterChangesAnExcitedPrediction  no parameter is a silent no-op.
//
// The effect is tested inside "base" (appended to accel_linear + gyro_linear), with its
// parameters drawn around zero at their typical size. Include this header in exactly ONE .cc
// of a test executable (it defines the tests) and instantiate the suite with the cases:
//
//   using plumb::testing::EffectInvariants;
//   INSTANTIATE_TEST_SUITE_P(Mine, EffectInvariants,
//                            ::testing::Values(plumb::testing::EffectCase{"my_effect", ""}),
//                            plumb::testing::EffectCaseName);
//
// The effect must be registered (Registry::Global(), with its Jet form: a program's own effect
// through plumb::autodiff::RegisterEffect) before the tests run.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <ostream>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "plumb/autodiff/differentiable_effect.h"
#include "plumb/model/model.h"

namespace plumb::testing {

/// One case of the battery: an effect name and the option it is made with.
struct EffectCase {
  std::string name;
  std::string option;  ///< "" = the default option
};

inline void PrintTo(const EffectCase& c, std::ostream* os) {
  *os << c.name << (c.option.empty() ? "" : ":" + c.option);
}

/// Test name suffix: "name" or "name_option".
inline std::string EffectCaseName(const ::testing::TestParamInfo<EffectCase>& info) {
  return info.param.name + (info.param.option.empty() ? "" : "_" + info.param.option);
}

/// The base model with the effect under test: the base effects themselves are made with the
/// case's option; any other effect is appended to "base".
inline model::Model ModelWith(const EffectCase& c) {
  model::Model m;
  m.Add("accel_linear", c.name == "accel_linear" ? c.option : "");
  m.Add("gyro_linear", c.name == "gyro_linear" ? c.option : "");
  if (!m.has_effect(c.name)) m.Add(c.name, c.option);
  return m;
}

/// An input that excites every effect: tilted specific force, rotation, angular acceleration,
/// time and temperature away from their references, a known attitude.
inline model::SensorInput<double> ExcitedInput() {
  model::SensorInput<double> in;
  in.R_b_n = Eigen::AngleAxisd(0.7, Vec3(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  in.f_b = Vec3(1.3, -2.1, -9.4);
  in.omega_b = Vec3(0.8, -0.5, 1.1);
  in.alpha_b = Vec3(-1.7, 2.3, 0.9);
  in.dt_s = 120.0;
  in.dtemp_c = 11.0;
  return in;
}

/// Parameter blocks drawn around zero with sigma = scale * typical; fixed parameters stay 0.
inline model::ParameterBlocks RandomBlocks(const model::Model& m, double scale,
                                           std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  model::ParameterBlocks theta = m.ZeroParameters();
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
inline Eigen::Matrix<double, 6, 1> Stack(const model::SensorOutput<double>& out) {
  Eigen::Matrix<double, 6, 1> y;
  y << out.acc, out.gyr;
  return y;
}

inline model::SensorInput<autodiff::Jet> ToJet(const model::SensorInput<double>& in) {
  model::SensorInput<autodiff::Jet> j;
  j.f_b = in.f_b.cast<autodiff::Jet>();
  j.omega_b = in.omega_b.cast<autodiff::Jet>();
  j.alpha_b = in.alpha_b.cast<autodiff::Jet>();
  j.dt_s = autodiff::Jet(in.dt_s);
  j.dtemp_c = autodiff::Jet(in.dtemp_c);
  j.R_b_n = in.R_b_n.cast<autodiff::Jet>();
  return j;
}

/// Jet-valued blocks equal to theta, with the infinitesimals seeded on parameters
/// [first, first + kJetStride) of block `seeded`.
inline std::vector<std::vector<autodiff::Jet>> SeededJets(const model::ParameterBlocks& theta,
                                                       std::size_t seeded, std::size_t first) {
  std::vector<std::vector<autodiff::Jet>> blocks;
  for (std::size_t k = 0; k < theta.size(); ++k) {
    std::vector<autodiff::Jet> block;
    for (std::size_t i = 0; i < theta[k].size(); ++i) {
      autodiff::Jet v(theta[k][i]);
      if (k == seeded && i >= first && i < first + autodiff::kJetStride) {
        v.v[static_cast<int>(i - first)] = 1.0;
      }
      block.push_back(v);
    }
    blocks.push_back(block);
  }
  return blocks;
}

inline model::SensorOutput<autodiff::Jet> PredictJet(
    const model::Model& m, const std::vector<std::vector<autodiff::Jet>>& blocks,
    const model::SensorInput<autodiff::Jet>& in) {
  std::vector<const autodiff::Jet*> ptr;
  for (const auto& b : blocks) ptr.push_back(b.data());
  return autodiff::DifferentiableModel(m).Predict(ptr.data(), in);
}

/// Index of the case's term in ModelWith(case).
inline std::size_t TermIndex(const model::Model& m, const EffectCase& c) {
  return static_cast<std::size_t>(m.FindTerm(c.name));
}

class EffectInvariants : public ::testing::TestWithParam<EffectCase> {};

TEST_P(EffectInvariants, ZeroParametersAreTheIdentity) {
  const model::Model m = ModelWith(GetParam());
  const model::SensorInput<double> in = ExcitedInput();
  const auto out = m.Predict(m.ZeroParameters(), in);
  EXPECT_EQ(out.acc, in.f_b);
  EXPECT_EQ(out.gyr, in.omega_b);
}

TEST_P(EffectInvariants, CorrectInvertsPredict) {
  const model::Model m = ModelWith(GetParam());
  std::mt19937_64 rng(20240611);
  for (int trial = 0; trial < 5; ++trial) {
    const model::ParameterBlocks theta = RandomBlocks(m, 1.0, rng);
    const model::SensorInput<double> in = ExcitedInput();
    const auto out = m.Predict(theta, in);
    const auto [f_b, omega_b] = m.Correct(theta, out.acc, out.gyr, in);
    EXPECT_LT((f_b - in.f_b).norm(), 1e-9 * in.f_b.norm()) << "trial " << trial;
    EXPECT_LT((omega_b - in.omega_b).norm(), 1e-9 * in.omega_b.norm()) << "trial " << trial;
  }
}

TEST_P(EffectInvariants, JetPredictionAndDerivativeMatchDoubles) {
  const model::Model m = ModelWith(GetParam());
  const std::size_t k = TermIndex(m, GetParam());
  std::mt19937_64 rng(77);
  const model::ParameterBlocks theta = RandomBlocks(m, 1.0, rng);
  const model::SensorInput<double> in = ExcitedInput();
  const auto y = Stack(m.Predict(theta, in));
  for (std::size_t first = 0; first < theta[k].size(); first += autodiff::kJetStride) {
    const auto jet_out = PredictJet(m, SeededJets(theta, k, first), ToJet(in));
    const std::size_t last = std::min(theta[k].size(), first + autodiff::kJetStride);
    for (std::size_t i = first; i < last; ++i) {
      // Central difference with a step of 1e-3 of the typical size.
      const double h = 1e-3 * m.terms()[k].effect->info().parameters[i].typical;
      model::ParameterBlocks plus = theta, minus = theta;
      plus[k][i] += h;
      minus[k][i] -= h;
      const Eigen::Matrix<double, 6, 1> numeric =
          (Stack(m.Predict(plus, in)) - Stack(m.Predict(minus, in))) / (2 * h);
      for (int r = 0; r < 6; ++r) {
        const autodiff::Jet& yr = r < 3 ? jet_out.acc(r) : jet_out.gyr(r - 3);
        EXPECT_NEAR(yr.a, y(r), 1e-12 * (1.0 + std::abs(y(r)))) << "output " << r;
        const double analytic = yr.v[static_cast<int>(i - first)];
        EXPECT_NEAR(analytic, numeric(r), 1e-6 * (1.0 + std::abs(numeric(r))))
            << m.terms()[k].effect->info().ParameterName(static_cast<int>(i)) << " output " << r;
      }
    }
  }
}

TEST_P(EffectInvariants, InfoIsComplete) {
  const model::Model m = ModelWith(GetParam());
  const auto& info = m.terms()[TermIndex(m, GetParam())].effect->info();
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
  const model::Model m = ModelWith(GetParam());
  const std::size_t k = TermIndex(m, GetParam());
  const auto& info = m.terms()[k].effect->info();
  const model::SensorInput<double> in = ExcitedInput();
  const auto y0 = Stack(m.Predict(m.ZeroParameters(), in));
  for (int i = 0; i < info.size(); ++i) {
    model::ParameterBlocks theta = m.ZeroParameters();
    const double typical = info.parameters[static_cast<std::size_t>(i)].typical;
    theta[k][static_cast<std::size_t>(i)] = typical;
    const auto y = Stack(m.Predict(theta, in));
    // Every input of ExcitedInput() is of order one or more, so a live parameter moves the
    // prediction by at least a fraction of its typical size.
    EXPECT_GT((y - y0).norm(), 1e-2 * typical) << info.ParameterName(i) << " is a silent no-op";
  }
}

}  // namespace plumb::testing
