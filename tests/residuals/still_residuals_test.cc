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
/// `weights`: the wander processes' bridge-mean weights (none: a constant bias); `mounted`: the
/// residual of another IMU of the board, at a rotation R_b_i of a few degrees.
double StillJacobianError(const std::string& spec, model::Sensor sensor,
                          std::vector<double> weights = {}, bool mounted = false) {
  model::Model m = model::Model::Parse(spec);
  const auto theta = SmallParameters(m, 7);
  StillMeasurement meas;
  meas.mean = sensor == model::Sensor::kAccel ? Vec3(0.3, -0.2, -9.7) : Vec3(0.01, -0.02, 0.005);
  meas.sqrt_info = Vec3(100, 120, 90);
  meas.dt_s = 40.0;
  meas.dtemp_c = 3.0;
  const Vec3 g_n(0, 0, 9.81), omega_ie_n(4.5e-5, 0, -5.7e-5);
  std::unique_ptr<ceres::CostFunction> cost(
      mounted ? StillResidual::CreateMounted(m, sensor, meas, g_n, omega_ie_n, Vec3::Zero(), weights)
              : StillResidual::Create(m, sensor, meas, g_n, omega_ie_n, Vec3::Zero(), weights));
  const Quat q = Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized())).normalized();
  const double q_block[4] = {q.x(), q.y(), q.z(), q.w()};
  // The board_mount block: a rotation of 0.03 rad, a lever arm and a time offset (which a still
  // pose does not see: their columns are zero).
  const Vec3 rho = 0.03 * Vec3(-2, 1, 0.5).normalized();
  const double mount_block[7] = {rho.x(), rho.y(), rho.z(), 0.02, -0.01, 0.03, 1e-3};
  std::vector<const double*> params = {q_block};
  if (mounted) params.push_back(mount_block);
  for (int t : StillResidual::TermsOf(m, sensor)) params.push_back(theta[static_cast<std::size_t>(t)].data());
  // Wander states: start and end of each process.
  const double states[2][2][3] = {{{0.01, -0.02, 0.005}, {0.015, -0.01, 0.0}},
                                  {{-0.003, 0.004, 0.002}, {0.001, 0.006, -0.002}}};
  for (std::size_t p = 0; p < weights.size(); ++p) {
    params.insert(params.end(), {states[p][0], states[p][1]});
  }
  const auto manifold = AttitudeManifold();
  std::vector<const ceres::Manifold*> manifolds(params.size(), nullptr);
  manifolds[0] = manifold.get();
  return testing::JacobianError(*cost, params, manifolds);
}

TEST(StillResidual, AccelJacobianMatchesNumericBase) {
  EXPECT_LT(StillJacobianError("base", model::Sensor::kAccel), 1e-8);
}

TEST(StillResidual, JacobianMatchesNumericWithABiasWalk) {
  EXPECT_LT(StillJacobianError("base", model::Sensor::kAccel, {0.5}), 1e-8);
  EXPECT_LT(StillJacobianError("base+gyro_g_sensitivity", model::Sensor::kGyro, {0.5}), 1e-8);
}

TEST(StillResidual, JacobianMatchesNumericWithAWalkAndAnInstability) {
  EXPECT_LT(StillJacobianError("base", model::Sensor::kAccel, {0.5, 0.31}), 1e-8);
  EXPECT_LT(StillJacobianError("base+gyro_g_sensitivity", model::Sensor::kGyro, {0.5, 0.42}),
            1e-8);
}

TEST(StillResidual, TheWanderEntersAsItsWeightedEnds) {
  // r(weights) - r(none) = -W sum_p w_p (s_p + e_p), exactly.
  model::Model m = model::Model::Parse("base");
  const auto theta = m.ZeroParameters();
  StillMeasurement meas;
  meas.mean = Vec3(0.3, -0.2, -9.7);
  meas.sqrt_info = Vec3(100, 120, 90);
  const double q[4] = {0, 0, 0, 1};
  const double s0[3] = {0.01, -0.02, 0.005}, e0[3] = {0.015, -0.01, 0.0};
  const double s1[3] = {-0.003, 0.004, 0.002}, e1[3] = {0.001, 0.006, -0.002};
  std::vector<const double*> p = {q, theta[0].data()};
  std::unique_ptr<ceres::CostFunction> plain(StillResidual::Create(
      m, model::Sensor::kAccel, meas, Vec3(0, 0, 9.81), Vec3::Zero()));
  double r0[3], r1[3];
  plain->Evaluate(p.data(), r0, nullptr);
  p.insert(p.end(), {s0, e0, s1, e1});
  std::unique_ptr<ceres::CostFunction> wandered(StillResidual::Create(
      m, model::Sensor::kAccel, meas, Vec3(0, 0, 9.81), Vec3::Zero(), Vec3::Zero(), {0.5, 0.3}));
  wandered->Evaluate(p.data(), r1, nullptr);
  for (int i = 0; i < 3; ++i) {
    const double shift = 0.5 * (s0[i] + e0[i]) + 0.3 * (s1[i] + e1[i]);
    EXPECT_NEAR(r1[i], r0[i] - meas.sqrt_info[i] * shift, 1e-12);
  }
}

TEST(StillResidual, GyroJacobianMatchesNumericBase) {
  EXPECT_LT(StillJacobianError("base", model::Sensor::kGyro), 1e-8);
}

TEST(StillResidual, AccelJacobianMatchesNumericWithEffects) {
  EXPECT_LT(StillJacobianError("base+accel_bias_drift", model::Sensor::kAccel), 1e-8);
}

TEST(StillResidual, MountedJacobianMatchesNumeric) {
  EXPECT_LT(StillJacobianError("base", model::Sensor::kAccel, {}, true), 1e-8);
  // A still gyroscope sees its mount through Earth rate only (5e-5 rad/s): that block's
  // Jacobian is 2e4 times smaller than the residual, and the central difference's rounding
  // (eps |r| / step) is 4e-8 of it.
  EXPECT_LT(StillJacobianError("base", model::Sensor::kGyro, {0.5}, true), 2e-7);
  EXPECT_LT(StillJacobianError("base+gyro_g_sensitivity", model::Sensor::kGyro, {0.5, 0.42}, true),
            2e-7);
}

/// The residual of a still accelerometer pose, `mounted` or not, at attitude q_n_b (and mount
/// R_b_i with a lever arm and time offset), for a base model with a few parameters set.
Vec3 AccelResidual(bool mounted, const Quat& R_n_b, const Quat& R_b_i = Quat::Identity(),
                   const Vec3& lever_arm_m = Vec3::Zero(), double time_offset_s = 0.0) {
  model::Model m = model::Model::Parse("base");
  const auto theta = SmallParameters(m, 11);
  StillMeasurement meas;
  meas.mean = Vec3(0.3, -0.2, -9.7);
  meas.sqrt_info = Vec3(100, 120, 90);
  const Vec3 g_n(0, 0, 9.81);
  std::unique_ptr<ceres::CostFunction> cost(
      mounted ? StillResidual::CreateMounted(m, model::Sensor::kAccel, meas, g_n, Vec3::Zero(),
                                             Vec3::Zero(), {})
              : StillResidual::Create(m, model::Sensor::kAccel, meas, g_n, Vec3::Zero()));
  const double q[4] = {R_n_b.x(), R_n_b.y(), R_n_b.z(), R_n_b.w()};
  const Eigen::AngleAxisd aa(R_b_i);
  const Vec3 rho = aa.angle() * aa.axis();
  const double mount[7] = {rho.x(),         rho.y(),         rho.z(),      lever_arm_m.x(),
                           lever_arm_m.y(), lever_arm_m.z(), time_offset_s};
  std::vector<const double*> p = {q};
  if (mounted) p.push_back(mount);
  p.push_back(theta[static_cast<std::size_t>(m.BaseTerm(model::Sensor::kAccel))].data());
  Vec3 r;
  cost->Evaluate(p.data(), r.data(), nullptr);
  return r;
}

TEST(StillResidual, AMountedImuSeesThePoseThroughItsMount) {
  // R_n_i = R_n_b R_b_i: the mounted residual at (R_n_b, R_b_i) is the plain one at R_n_b R_b_i,
  // and a mount at the identity changes nothing.
  const Quat R_n_b = Quat(Eigen::AngleAxisd(0.9, Vec3(0.3, -1, 2).normalized()));
  const Quat R_b_i = Quat(Eigen::AngleAxisd(0.02, Vec3(1, 1, -0.4).normalized()));
  EXPECT_LT((AccelResidual(true, R_n_b, R_b_i) - AccelResidual(false, R_n_b * R_b_i)).norm(), 1e-9);
  EXPECT_LT((AccelResidual(true, R_n_b, Quat::Identity()) - AccelResidual(false, R_n_b)).norm(),
            1e-12);
  // The mount matters: 0.02 rad of tilt moves 9.8 m/s^2 by about 0.2 m/s^2, 20 sigma here.
  EXPECT_GT((AccelResidual(true, R_n_b, R_b_i) - AccelResidual(false, R_n_b)).norm(), 5.0);
  // Still, the lever arm and the time offset do not enter (no rate, no angular acceleration).
  EXPECT_EQ(AccelResidual(true, R_n_b, R_b_i, Vec3(0.03, -0.02, 0.01), 2e-3),
            AccelResidual(true, R_n_b, R_b_i));
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
