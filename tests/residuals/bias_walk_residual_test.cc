// The bias random-walk factor: its value, its Jacobian, and that its whitened square has the
// expected chi^2 for a simulated random walk.
#include "plumb/residuals/bias_walk_residual.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "support/jacobian_check.h"

namespace plumb::residuals {
namespace {

TEST(BiasWalkResidual, IsTheStepOverItsSigma) {
  const Vec3 inv_sigma(2.0, 4.0, 8.0);
  std::unique_ptr<ceres::CostFunction> cost(BiasWalkResidual::Create(inv_sigma));
  const double from[3] = {1.0, 2.0, 3.0}, to[3] = {1.5, 1.0, 3.25};
  const double* p[2] = {from, to};
  double r[3];
  ASSERT_TRUE(cost->Evaluate(p, r, nullptr));
  EXPECT_DOUBLE_EQ(r[0], 1.0);
  EXPECT_DOUBLE_EQ(r[1], -4.0);
  EXPECT_DOUBLE_EQ(r[2], 2.0);
  std::unique_ptr<ceres::CostFunction> anchor(BiasWalkResidual::CreateAnchor(inv_sigma));
  ASSERT_TRUE(anchor->Evaluate(&p[1], r, nullptr));
  EXPECT_DOUBLE_EQ(r[1], 4.0);
}

TEST(BiasWalkResidual, JacobianMatchesNumeric) {
  std::unique_ptr<ceres::CostFunction> cost(BiasWalkResidual::Create(Vec3(3.0, 5.0, 7.0)));
  const double from[3] = {0.1, -0.2, 0.3}, to[3] = {0.2, 0.1, -0.3};
  EXPECT_LT(testing::JacobianError(*cost, {from, to}, {nullptr, nullptr}), 1e-8);
}

TEST(BiasWalkResidual, GaussMarkovFactorCarriesPhi) {
  // r = (to - phi from) inv_sigma, and its Jacobian.
  std::unique_ptr<ceres::CostFunction> cost(BiasWalkResidual::Create(Vec3(2.0, 4.0, 8.0), 0.5));
  const double from[3] = {1.0, 2.0, 3.0}, to[3] = {1.5, 1.0, 3.25};
  const double* p[2] = {from, to};
  double r[3];
  ASSERT_TRUE(cost->Evaluate(p, r, nullptr));
  EXPECT_DOUBLE_EQ(r[0], 2.0);
  EXPECT_DOUBLE_EQ(r[1], 0.0);
  EXPECT_DOUBLE_EQ(r[2], 14.0);
  EXPECT_LT(testing::JacobianError(*cost, {from, to}, {nullptr, nullptr}), 1e-8);
}

TEST(BiasWalkResidual, WhitensASimulatedWalk) {
  // A walk of density K sampled every dt: the factor over each step is N(0, 1) per axis, so
  // the mean square over many steps is 1 within its spread (sqrt(2 / n)).
  const double K = 2e-4, dt = 0.7;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  std::unique_ptr<ceres::CostFunction> cost(
      BiasWalkResidual::Create(Vec3::Constant(1.0 / (K * std::sqrt(dt)))));
  Vec3 b = Vec3::Zero();
  double sum = 0;
  const int steps = 20000;
  for (int k = 0; k < steps; ++k) {
    const Vec3 next = b + K * std::sqrt(dt) * Vec3(n(rng), n(rng), n(rng));
    const double* p[2] = {b.data(), next.data()};
    double r[3];
    cost->Evaluate(p, r, nullptr);
    sum += r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    b = next;
  }
  EXPECT_NEAR(sum / (3.0 * steps), 1.0, 3.0 * std::sqrt(2.0 / (3.0 * steps)));
}

}  // namespace
}  // namespace plumb::residuals
