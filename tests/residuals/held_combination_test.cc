// The held combination: its value, its Jacobian (a term's coefficient over the width, terms of
// one value summed), and that a combination over two blocks holds just that combination.
#include "plumb/residuals/held_combination.h"

#include <gtest/gtest.h>

#include "support/jacobian_check.h"

namespace plumb::residuals {
namespace {

// Blocks of sizes 3 and 2; the combination 2 a[0] - 0.5 a[2] + 4 b[1], started at
// a = (1, 0, 2), b = (0, -1).
HeldCombination Example() {
  return HeldCombination({3, 2},
                         {{0, 0, 2.0, 1.0}, {0, 2, -0.5, 2.0}, {1, 1, 4.0, -1.0}}, 0.25);
}

TEST(HeldCombination, IsTheCombinationsMoveOverItsWidth) {
  const HeldCombination cost = Example();
  const double a[3] = {1.5, 7.0, 1.0}, b[2] = {3.0, -0.75};
  const double* p[2] = {a, b};
  double r = 0.0;
  ASSERT_TRUE(cost.Evaluate(p, &r, nullptr));
  // 2 * 0.5 - 0.5 * (-1) + 4 * 0.25 = 2.5, over 0.25.
  EXPECT_DOUBLE_EQ(r, 10.0);
  // A move that keeps the combination (a[1] and b[0] are not in it; a[0] up, b[1] down).
  const double a2[3] = {1.0 + 0.2, -3.0, 2.0}, b2[2] = {9.0, -1.0 - 0.1};
  const double* p2[2] = {a2, b2};
  ASSERT_TRUE(cost.Evaluate(p2, &r, nullptr));
  EXPECT_NEAR(r, 0.0, 1e-12);
}

TEST(HeldCombination, JacobianMatchesNumeric) {
  const HeldCombination cost = Example();
  const double a[3] = {0.3, -0.2, 0.9}, b[2] = {0.4, 0.1};
  EXPECT_LT(testing::JacobianError(cost, {a, b}, {nullptr, nullptr}), 1e-8);
}

TEST(HeldCombination, TermsOfOneValueAddUp) {
  const HeldCombination cost({2}, {{0, 1, 1.0, 0.0}, {0, 1, 2.0, 0.0}}, 1.0);
  const double a[2] = {5.0, 1.0};
  const double* p[1] = {a};
  double r = 0.0, J[2] = {0.0, 0.0};
  double* jacobians[1] = {J};
  ASSERT_TRUE(cost.Evaluate(p, &r, jacobians));
  EXPECT_DOUBLE_EQ(r, 3.0);
  EXPECT_DOUBLE_EQ(J[0], 0.0);
  EXPECT_DOUBLE_EQ(J[1], 3.0);
}

}  // namespace
}  // namespace plumb::residuals
