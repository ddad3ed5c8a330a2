// The strapdown core (residuals/strapdown.h) with the model's inverse (residuals/
// corrected_rates.h): for the base model and every catalogue effect, the propagated Jacobians
// of the attitude change (right perturbation) and the velocity change with respect to the
// model's parameters and the start attitude against central differences of the value alone.
#include "plumb/residuals/strapdown.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "plumb/core/so3.h"
#include "plumb/model/registry.h"
#include "plumb/residuals/corrected_rates.h"

namespace plumb::residuals {
namespace {

using strapdown::Sensitivity;

/// A turn about an axis that itself turns, 1 s at 100 Hz (rates to about 2 rad/s, angular
/// acceleration, a warming sensor), seen as outputs of the identity sensor.
MotionSamples TurningSamples() {
  MotionSamples s;
  const int n = 101;
  for (int i = 0; i < n; ++i) {
    const double t = 0.01 * i;
    const Vec3 w(1.5 * std::sin(3.0 * t), 0.8 * std::cos(2.0 * t), 2.0 * t * (1.0 - t));
    const Vec3 alpha(4.5 * std::cos(3.0 * t), -1.6 * std::sin(2.0 * t), 2.0 - 4.0 * t);
    s.dt_s.push_back(t);
    s.gyr.push_back(w);
    s.acc.push_back(Vec3(0.4 * std::sin(5.0 * t), -0.3, -9.81 + 0.2 * t));
    s.alpha_b.push_back(alpha);
    s.dtemp_c.push_back(1.5 + 0.8 * t);
  }
  return s;
}

/// Parameter values off zero: F and E near the identity, biases, and each catalogue parameter
/// at a third of its typical size with alternating signs.
model::ParameterBlocks Values(const model::Model& m) {
  model::ParameterBlocks theta = m.ZeroParameters();
  for (int t = 0; t < m.num_terms(); ++t) {
    const auto& info = m.terms()[static_cast<std::size_t>(t)].effect->info();
    auto& block = theta[static_cast<std::size_t>(t)];
    for (int j = 0; j < info.size(); ++j) {
      const double sign = j % 2 == 0 ? 1.0 : -1.0;
      const double size =
          info.linear_stage ? 0.01 : info.parameters[static_cast<std::size_t>(j)].typical / 3.0;
      block[static_cast<std::size_t>(j)] = sign * size * (1.0 + 0.1 * j);
    }
  }
  return theta;
}

/// Unknowns: the model's parameters (block order), then the start attitude's left
/// perturbation in NED.
struct Unknowns {
  model::ParameterBlocks theta;
  Vec3 attitude = Vec3::Zero();
};

Unknowns Moved(const Unknowns& x, int column, double step, const ModelColumns& columns) {
  Unknowns moved = x;
  if (column >= columns.parameters) {
    moved.attitude[column - columns.parameters] += step;
  } else {
    const auto [t, j] = columns.parameter_of[static_cast<std::size_t>(column)];
    moved.theta[static_cast<std::size_t>(t)][static_cast<std::size_t>(j)] += step;
  }
  return moved;
}

/// An Earth rate far above the real one (rad/s), so that the start attitude's columns stand
/// well above rounding in a 1 s interval.
const Vec3 kOmegaN(0.02, -0.01, 0.03);
const Mat3 kR_n_b0 = so3::Exp(Vec3(0.3, -0.2, 0.5));

struct Problem {
  explicit Problem(const std::string& spec) : model(model::Model::Parse(spec)), s(TurningSamples()) {}
  model::Model model;
  MotionSamples s;

  std::vector<const double*> Pointers(const model::ParameterBlocks& theta) const {
    std::vector<const double*> p;
    for (const auto& b : theta) p.push_back(b.data());
    return p;
  }
  /// Corrected force and rate of sample i at theta (the model's inverse, to its fixed point).
  std::pair<Vec3, Vec3> Corrected(const model::ParameterBlocks& theta, std::size_t i) const {
    const auto p = Pointers(theta);
    const model::SensorOutput<double> at_zero = model.Predict(p.data(), model::SensorInput<double>());
    model::SensorInput<double> in;
    in.alpha_b = s.alpha_b[i];
    in.dt_s = s.dt_s[i];
    in.dtemp_c = s.dtemp_c[i];
    return model.CorrectToFixedPoint(p.data(), s.acc[i], s.gyr[i], in, at_zero.F.inverse(),
                                     at_zero.E.inverse(), 8, 1e-15);
  }
  Vec3 OmegaB0(const Vec3& attitude) const {
    return (so3::Exp(attitude) * kR_n_b0).transpose() * kOmegaN;
  }
  /// (dR, dv) without Jacobians.
  std::pair<Mat3, Vec3> Value(const Unknowns& x) const {
    return strapdown::IntegratedChange(s.dt_s, OmegaB0(x.attitude),
                                       [&](std::size_t i) { return Corrected(x.theta, i); });
  }
};

/// Norm-relative error of `analytic` against `numeric`.
double RelativeError(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& numeric) {
  return (analytic - numeric).norm() / std::max(1e-12, numeric.norm());
}

/// The core's Jacobians for `spec` and their central differences: errors of dR_H_x and
/// dv_H_x, each over the model's columns and the start attitude's.
struct Errors {
  double dR_theta, dR_attitude, dv_theta, dv_attitude;
};

Errors CoreJacobianErrors(const std::string& spec) {
  const Problem problem(spec);
  const RateCorrection correction(problem.model);
  const ModelColumns& columns = correction.columns();
  const int P = columns.parameters;
  const Unknowns x{Values(problem.model)};
  const std::size_t n = problem.s.size();
  constexpr double kStep = 1e-6;

  // The forces' Jacobians by central differences (the core takes them as given).
  std::vector<Sensitivity> f_H_x(n, Sensitivity::Zero(3, P + 3));
  for (int c = 0; c < P; ++c) {
    const Unknowns plus = Moved(x, c, kStep, columns), minus = Moved(x, c, -kStep, columns);
    for (std::size_t i = 0; i < n; ++i) {
      f_H_x[i].col(c) = (problem.Corrected(plus.theta, i).first -
                         problem.Corrected(minus.theta, i).first) / (2 * kStep);
    }
  }
  // The rates' Jacobians as the motion residual takes them (implicit, stored).
  const auto p = problem.Pointers(x.theta);
  const CorrectedRates rates = correction.Correct(p.data(), problem.s, problem.s.gyr,
                                                  RateCorrection::Options{false, true});
  strapdown::Propagation propagation(problem.OmegaB0(x.attitude),
                                     kR_n_b0.transpose() * so3::Skew(kOmegaN), P + 3, P, true);
  auto add_rate_H_x = [&](const Mat3& K, std::size_t i, Sensitivity& out) {
    correction.AddRateJacobian(rates, K, i, out);
  };
  auto force_H_x = [&](std::size_t i, Sensitivity& out) { out = f_H_x[i]; };
  propagation.Start(problem.Corrected(x.theta, 0).first, force_H_x);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    propagation.Advance(i, problem.s.dt_s[i + 1] - problem.s.dt_s[i], rates.w_b[i],
                        rates.w_b[i + 1], problem.Corrected(x.theta, i + 1).first, add_rate_H_x,
                        force_H_x);
  }

  const auto [dR, dv] = problem.Value(x);
  EXPECT_LT((propagation.dR() - dR).norm(), 1e-12);
  EXPECT_LT((propagation.dv() - dv).norm(), 1e-12);
  Eigen::MatrixXd dR_numeric(3, P + 3), dv_numeric(3, P + 3);
  for (int c = 0; c < P + 3; ++c) {
    const auto plus = problem.Value(Moved(x, c, kStep, columns));
    const auto minus = problem.Value(Moved(x, c, -kStep, columns));
    dR_numeric.col(c) =
        (so3::Log(dR.transpose() * plus.first) - so3::Log(dR.transpose() * minus.first)) /
        (2 * kStep);
    dv_numeric.col(c) = (plus.second - minus.second) / (2 * kStep);
  }
  const Sensitivity& dR_H_x = propagation.dR_H_x();
  const Sensitivity& dv_H_x = propagation.dv_H_x();
  return {RelativeError(dR_H_x.leftCols(P), dR_numeric.leftCols(P)),
          RelativeError(dR_H_x.rightCols<3>(), dR_numeric.rightCols<3>()),
          RelativeError(dv_H_x.leftCols(P), dv_numeric.leftCols(P)),
          RelativeError(dv_H_x.rightCols<3>(), dv_numeric.rightCols<3>())};
}

void ExpectCoreJacobiansMatch(const std::string& spec) {
  SCOPED_TRACE(spec);
  const Errors e = CoreJacobianErrors(spec);
  EXPECT_LT(e.dR_theta, 1e-6);
  EXPECT_LT(e.dR_attitude, 1e-6);
  EXPECT_LT(e.dv_theta, 1e-6);
  EXPECT_LT(e.dv_attitude, 1e-6);
}

TEST(Strapdown, JacobiansMatchNumericForTheBaseModel) { ExpectCoreJacobiansMatch("base"); }

// Every catalogue effect alone, and with one that reads the linear stage's E
// (gyro_scale_nonlinearity) and one that couples the sensors (gyro_g_sensitivity): the
// three ways the model's inverse hands the rates' Jacobians to the core.
TEST(Strapdown, JacobiansMatchNumericForEveryCatalogueEffect) {
  for (const std::string& name : model::Registry::Global().CatalogueNames()) {
    ExpectCoreJacobiansMatch("base+" + name);
    if (name != "gyro_scale_nonlinearity" && name != "gyro_g_sensitivity") {
      ExpectCoreJacobiansMatch("base+gyro_scale_nonlinearity+gyro_g_sensitivity+" + name);
    }
  }
}

// Without Earth rate the sensitivity may be carried in the start frame: the same dR and
// dR_H_x as the body frame's propagation.
TEST(Strapdown, TheStartFrameFormIsTheBodyFrameForm) {
  const Problem problem("base+gyro_g_sensitivity+gyro_scale_nonlinearity");
  const RateCorrection correction(problem.model);
  const int P = correction.columns().parameters;
  const model::ParameterBlocks theta = Values(problem.model);
  const auto p = problem.Pointers(theta);
  const CorrectedRates rates = correction.Correct(p.data(), problem.s, problem.s.gyr,
                                                  RateCorrection::Options{false, true});
  auto add_rate_H_x = [&](const Mat3& K, std::size_t i, Sensitivity& out) {
    correction.AddRateJacobian(rates, K, i, out);
  };
  strapdown::Propagation body(Vec3::Zero(), Mat3::Zero(), P, -1, false);
  for (std::size_t i = 0; i + 1 < problem.s.size(); ++i) {
    body.Advance(i, problem.s.dt_s[i + 1] - problem.s.dt_s[i], rates.w_b[i], rates.w_b[i + 1],
                 Vec3::Zero(), add_rate_H_x, [](std::size_t, Sensitivity&) {});
  }
  Sensitivity summed = Sensitivity::Zero(3, P);
  const Mat3 dR = strapdown::PropagateInStartFrame(
      problem.s.dt_s, rates.w_b, [&](const Mat3& G, std::size_t i) { add_rate_H_x(G, i, summed); });
  EXPECT_LT((dR - body.dR()).norm(), 1e-13);
  EXPECT_LT((dR.transpose() * summed - body.dR_H_x()).norm(), 1e-12 * body.dR_H_x().norm());
  EXPECT_LT((strapdown::IntegratedRotation(problem.s.dt_s, rates.w_b, Vec3::Zero()) - dR).norm(),
            1e-13);
}

}  // namespace
}  // namespace plumb::residuals
