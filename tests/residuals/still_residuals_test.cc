// Jacobian checks of the still residuals against central numeric differences
// (ceres::GradientChecker), for the base model and a model with catalogue effects.
#include "plumb/residuals/still_residuals.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "plumb/residuals/manifolds.h"
#include "support/jacobian_check.h"

namespace plumb::residuals {
namespace {

/// Fills every block with small deterministic values (matrix deltas, biases, effects).
model::ParameterBlocks SmallParameters(const model::Model& m, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto theta = m.ZeroParameters();
  for (int t = 0; t < m.num_terms(); ++t) {
    const auto& info = m.terms()[static_cast<std::size_t>(t)].effect->info();
    for (int i = 0; i < info.size(); ++i) {
      theta[static_cast<std::size_t>(t)][static_cast<std::size_t>(i)] =
          0.5 * info.parameters[static_cast<std::size_t>(i)].typical * u(rng);
    }
  }
  return theta;
}

/// Runs the gradient checker on a still residual of `sensor` and returns its max error.
double StillJacobianError(const std::string& spec, model::Sensor sensor, bool walk = false) {
  model::Model m = model::Model::Parse(spec);
  const auto theta = SmallParameters(m, 7);
  StillMeasurement meas;
  meas.mean = sensor == model::Sensor::kAccel ? Vec3(0.3, -0.2, -9.7) : Vec3(0.01, -0.02, 0.005);
  meas.sqrt_info = Vec3(100, 120, 90);
  meas.dt_s = 40.0;
  meas.dtemp_c = 3.0;
  std::unique_ptr<ceres::CostFunction> cost(StillResidual::Create(
      m, sensor, meas, Vec3(0, 0, 9.81), Vec3(4.5e-5, 0, -5.7e-5), Vec3::Zero(), walk));
  const Quat q = Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized())).normalized();
  const double q_block[4] = {q.x(), q.y(), q.z(), q.w()};
  std::vector<const double*> params = {q_block};
  for (int t : StillResidual::TermsOf(m, sensor)) params.push_back(theta[static_cast<std::size_t>(t)].data());
  const double s_k[3] = {0.01, -0.02, 0.005}, e_k[3] = {0.015, -0.01, 0.0};  // bias walk
  if (walk) params.insert(params.end(), {s_k, e_k});
  const auto manifold = AttitudeManifold();
  std::vector<const ceres::Manifold*> manifolds(params.size(), nullptr);
  manifolds[0] = manifold.get();
  return testing::JacobianError(*cost, params, manifolds);
}

TEST(StillResidual, AccelJacobianMatchesNumericBase) {
  EXPECT_LT(StillJacobianError("base", model::Sensor::kAccel), 1e-8);
}

TEST(StillResidual, JacobianMatchesNumericWithABiasWalk) {
  EXPECT_LT(StillJacobianError("base", model::Sensor::kAccel, true), 1e-8);
  EXPECT_LT(StillJacobianError("base+gyro_g_sensitivity", model::Sensor::kGyro, true), 1e-8);
}

TEST(StillResidual, GyroJacobianMatchesNumericBase) {
  EXPECT_LT(StillJacobianError("base", model::Sensor::kGyro), 1e-8);
}

TEST(StillResidual, AccelJacobianMatchesNumericWithEffects) {
  EXPECT_LT(StillJacobianError("base+accel_bias_drift", model::Sensor::kAccel), 1e-8);
}

TEST(StillResidual, ZeroResidualAtTruth) {
  // A level pose measured exactly as predicted by the identity model.
  model::Model m = model::Model::Parse("base");
  const auto theta = m.ZeroParameters();
  StillMeasurement meas;
  meas.mean = Vec3(0, 0, -9.81);
  StillResidual r(m, model::Sensor::kAccel, StillResidual::TermsOf(m, model::Sensor::kAccel), meas,
                  Vec3(0, 0, 9.81), Vec3::Zero());
  const double q[4] = {0, 0, 0, 1};
  EXPECT_LT((r.Predict(q, theta) - meas.mean).norm(), 1e-12);
}

}  // namespace
}  // namespace plumb::residuals
