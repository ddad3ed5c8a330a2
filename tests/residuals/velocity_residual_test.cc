// The velocity residual: zero on an exactly measured turn at rest at both ends, sensitive to
// the lever arms and the time offset, Jacobian against numeric differences (the analytic one
// at the linear stage, the central differences elsewhere), and the analytic one against the
// central differences where both apply.
#include "plumb/residuals/velocity_residual.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include <ceres/dynamic_numeric_diff_cost_function.h>

#include "plumb/residuals/manifolds.h"
#include "support/jacobian_check.h"

namespace plumb::residuals {
namespace {

constexpr double kG = 9.81;

/// A 90-degree turn about body x over 2 s at 200 Hz (raised-cosine rate), starting level
/// (R_n_b = I), measured by the identity sensor at the body origin: gravity rotates in the
/// body frame, so the specific force is f_b = R(t)^T (0, 0, -g).
MotionSamples TurnAboutX() {
  MotionSamples s;
  const double T = 2.0, A = M_PI / 2;
  const int n = 401;
  for (int i = 0; i < n; ++i) {
    const double t = T * i / (n - 1);
    const double rate = A / T * (1 - std::cos(2 * M_PI * t / T));
    const double angle = A / T * (t - T / (2 * M_PI) * std::sin(2 * M_PI * t / T));
    const Mat3 R = Eigen::AngleAxisd(angle, Vec3::UnitX()).toRotationMatrix();
    s.dt_s.push_back(t);
    s.gyr.push_back(Vec3(rate, 0, 0));
    s.acc.push_back(R.transpose() * Vec3(0, 0, -kG));
    s.alpha_b.push_back(Vec3(A / T * 2 * M_PI / T * std::sin(2 * M_PI * t / T), 0, 0));
    s.dtemp_c.push_back(0.0);
  }
  return s;
}

Vec3 Change(const model::Model& m, const model::ParameterBlocks& theta, const MotionSamples& s) {
  const VelocityResidual r(m, s, Vec3(0, 0, kG), Vec3::Zero(), Vec3::Ones());
  const double q[4] = {0, 0, 0, 1};
  std::vector<const double*> p = {q};
  for (const auto& b : theta) p.push_back(b.data());
  return r.VelocityChange(p.data());
}

TEST(VelocityResidual, ZeroForAnExactTurnBetweenRests) {
  const model::Model m = model::Model::Parse("base");
  const Vec3 dv = Change(m, m.ZeroParameters(), TurnAboutX());
  // g T = 19.6 m/s of gravity cancelled to the integration error of the trapezoid rule.
  EXPECT_LT(dv.norm(), 1e-4) << dv.transpose();
}

TEST(VelocityResidual, SeesALeverArmAndATimeOffset) {
  const MotionSamples s = TurnAboutX();
  // A lever arm along z of the y accelerometer: it reads alpha x r + omega x (omega x r) on y
  // while the IMU turns, which the base model takes for velocity.
  model::Model lever = model::Model::Parse("base+accel_size_effect");
  auto theta = lever.ZeroParameters();
  const Vec3 zero = Change(lever, theta, s);
  theta[2][2] = 0.02;  // r_y.z, m
  EXPECT_GT((Change(lever, theta, s) - zero).norm(), 1e-3);
  // A gyroscope 3 ms late against the accelerometer tilts gravity during the turn.
  model::Model offset = model::Model::Parse("base+time_offset");
  auto theta_t = offset.ZeroParameters();
  theta_t[2][0] = 3e-3;
  EXPECT_GT((Change(offset, theta_t, s) - Change(offset, offset.ZeroParameters(), s)).norm(), 1e-2);
}

TEST(VelocityResidual, JacobianMatchesNumeric) {
  const MotionSamples s = TurnAboutX();
  const model::Model m = model::Model::Parse("base+accel_size_effect+time_offset");
  auto theta = m.ZeroParameters();
  theta[0][6] = 0.05;
  theta[1][0] = 0.01;
  theta[2][2] = 0.01;
  theta[3][0] = 1e-3;
  std::unique_ptr<ceres::CostFunction> cost(
      VelocityResidual::Create(m, s, Vec3(0, 0, kG), Vec3(4e-5, 0, -5e-5), Vec3::Constant(100.0)));
  const Quat q(Eigen::AngleAxisd(0.02, Vec3(1, 1, 0).normalized()));
  const double a[4] = {q.x(), q.y(), q.z(), q.w()};
  std::vector<const double*> params = {a};
  for (const auto& block : theta) params.push_back(block.data());
  const auto manifold = AttitudeManifold();
  std::vector<const ceres::Manifold*> manifolds(params.size(), nullptr);
  manifolds[0] = manifold.get();
  // Central differences on both sides: agreement to the numeric step's truncation error.
  EXPECT_LT(testing::JacobianError(*cost, params, manifolds), 1e-4);
}

TEST(VelocityResidual, TakesTheWanderAlongItsLineOffTheOutputs) {
  // Outputs carrying an accelerometer wander from a to b and a gyroscope wander from c to d
  // (linear over the turn), with those as the wander blocks: the velocity change of the clean
  // turn. Without the blocks the wander shows as velocity.
  const MotionSamples clean = TurnAboutX();
  MotionSamples s = clean;
  const Vec3 a(0.02, -0.01, 0.03), b(0.05, 0.0, -0.02), c(1e-3, -2e-3, 5e-4), d(-1e-3, 0.0, 2e-3);
  const double T = s.dt_s.back();
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double u = s.dt_s[i] / T;
    s.acc[i] += a + u * (b - a);
    s.gyr[i] += c + u * (d - c);
  }
  const model::Model m = model::Model::Parse("base");
  const auto theta = m.ZeroParameters();
  const double q[4] = {0, 0, 0, 1};
  // Two accelerometer processes (a split in two) and one gyroscope process.
  const Vec3 a1 = 0.25 * a, a2 = 0.75 * a, b1 = 0.5 * b, b2 = 0.5 * b;
  std::vector<const double*> p = {q, theta[0].data(), theta[1].data(), a1.data(), b1.data(),
                                  a2.data(), b2.data(), c.data(), d.data()};
  const VelocityResidual with(m, s, Vec3(0, 0, kG), Vec3::Zero(), Vec3::Ones(), 2, 1);
  EXPECT_LT((with.VelocityChange(p.data()) - Change(m, theta, clean)).norm(), 1e-9);
  EXPECT_GT(Change(m, theta, s).norm(), 0.05);
}

TEST(VelocityResidual, JacobianMatchesNumericWithWander) {
  const MotionSamples s = TurnAboutX();
  const model::Model m = model::Model::Parse("base+time_offset");
  auto theta = m.ZeroParameters();
  theta[2][0] = 1e-3;
  std::unique_ptr<ceres::CostFunction> cost(VelocityResidual::Create(
      m, s, Vec3(0, 0, kG), Vec3(4e-5, 0, -5e-5), Vec3::Constant(100.0), 1, 1));
  const Quat q(Eigen::AngleAxisd(0.02, Vec3(1, 1, 0).normalized()));
  const double a[4] = {q.x(), q.y(), q.z(), q.w()};
  const Vec3 w0(0.01, 0.02, -0.01), w1(0.03, 0.0, 0.01), g0(1e-4, 0, -1e-4), g1(0, 2e-4, 0);
  std::vector<const double*> params = {a};
  for (const auto& block : theta) params.push_back(block.data());
  for (const Vec3* w : {&w0, &w1, &g0, &g1}) params.push_back(w->data());
  const auto manifold = AttitudeManifold();
  std::vector<const ceres::Manifold*> manifolds(params.size(), nullptr);
  manifolds[0] = manifold.get();
  EXPECT_LT(testing::JacobianError(*cost, params, manifolds), 1e-4);
}

/// The parameters of TurnAboutX at a tilted attitude, the given model blocks and wander ends.
struct Point {
  double q[4];
  std::vector<std::vector<double>> blocks;
  std::vector<const double*> params;
  std::vector<const ceres::Manifold*> manifolds;
  std::unique_ptr<ceres::Manifold> attitude = AttitudeManifold();
  Point(const model::ParameterBlocks& theta, const std::vector<Vec3>& wander) {
    const Quat r(Eigen::AngleAxisd(0.02, Vec3(1, 1, 0).normalized()));
    q[0] = r.x(), q[1] = r.y(), q[2] = r.z(), q[3] = r.w();
    params.push_back(q);
    blocks.assign(theta.begin(), theta.end());
    for (const Vec3& w : wander) blocks.emplace_back(w.data(), w.data() + 3);
    for (const auto& b : blocks) params.push_back(b.data());
    manifolds.assign(params.size(), nullptr);
    manifolds[0] = attitude.get();
  }
};

/// The base model away from identity: F, E and the biases all non-trivial.
model::ParameterBlocks TiltedBase(const model::Model& m) {
  auto theta = m.ZeroParameters();
  for (std::size_t j = 0; j < theta[0].size(); ++j) theta[0][j] = 0.01 * (1.0 + static_cast<double>(j % 3));
  for (std::size_t j = 0; j < theta[1].size(); ++j) theta[1][j] = -0.004 * (1.0 + static_cast<double>(j % 4));
  return theta;
}

TEST(VelocityResidual, AnalyticJacobianOfTheBaseModelMatchesNumeric) {
  for (const char* spec : {"base", "accel_linear:full+gyro_linear"}) {
    SCOPED_TRACE(spec);
    const model::Model full = model::Model::Parse(spec);
    const MotionSamples s = TurnAboutX();
    const Point p(TiltedBase(full), {Vec3(0.01, 0.02, -0.01), Vec3(0.03, 0.0, 0.01),
                                     Vec3(1e-4, 0, -1e-4), Vec3(0, 2e-4, 0)});
    std::unique_ptr<ceres::CostFunction> cost(VelocityResidual::Create(
        full, s, Vec3(0, 0, kG), Vec3(4e-5, 0, -5e-5), Vec3::Constant(100.0), 1, 1));
    EXPECT_LT(testing::JacobianError(*cost, p.params, p.manifolds), 1e-6);
  }
}

TEST(VelocityResidual, AnalyticAndCentralDifferencesAgreeOnAProbeFit) {
  // A probe at zero (diagnose's probe fits): analytic columns for every block but the probe's,
  // whose columns come from central differences; against central differences everywhere.
  const model::Model m = model::Model::Parse("base+accel_size_effect");
  const MotionSamples s = TurnAboutX();
  const Point p(TiltedBase(m), {Vec3(0.01, 0.02, -0.01), Vec3(0.03, 0.0, 0.01)});
  const Vec3 g(0, 0, kG), omega(4e-5, 0, -5e-5), info = Vec3::Constant(100.0);
  std::unique_ptr<ceres::CostFunction> cost(VelocityResidual::Create(m, s, g, omega, info, 1, 0));
  ceres::DynamicNumericDiffCostFunction<VelocityResidual, ceres::CENTRAL> central(
      new VelocityResidual(m, s, g, omega, info, 1, 0));
  for (int size : cost->parameter_block_sizes()) central.AddParameterBlock(size);
  central.SetNumResiduals(3);
  const auto& sizes = cost->parameter_block_sizes();
  using RowMajor = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>;
  std::vector<RowMajor> analytic, numeric;
  std::vector<double*> ja, jn;
  for (int size : sizes) {
    analytic.emplace_back(RowMajor::Zero(3, size));
    numeric.emplace_back(RowMajor::Zero(3, size));
  }
  for (std::size_t b = 0; b < sizes.size(); ++b) {
    ja.push_back(analytic[b].data());
    jn.push_back(numeric[b].data());
  }
  Vec3 ra, rn;
  ASSERT_TRUE(cost->Evaluate(p.params.data(), ra.data(), ja.data()));
  ASSERT_TRUE(central.Evaluate(p.params.data(), rn.data(), jn.data()));
  EXPECT_LT((ra - rn).norm(), 1e-12 * std::max(1.0, rn.norm()));
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> plus;
  p.attitude->PlusJacobian(p.params[0], plus.data());
  for (std::size_t b = 0; b < sizes.size(); ++b) {
    // Ambient q_k columns differ by design (any J_amb with J_amb P = J_tan): compare tangents.
    const Eigen::MatrixXd a = b == 0 ? Eigen::MatrixXd(analytic[b] * plus) : Eigen::MatrixXd(analytic[b]);
    const Eigen::MatrixXd n = b == 0 ? Eigen::MatrixXd(numeric[b] * plus) : Eigen::MatrixXd(numeric[b]);
    EXPECT_GT(n.norm(), 0.0) << "block " << b;
    EXPECT_LT((a - n).norm(), 1e-5 * std::max(1.0, n.norm())) << "block " << b;
  }
}

}  // namespace
}  // namespace plumb::residuals
