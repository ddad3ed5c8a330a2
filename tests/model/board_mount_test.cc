// The board_mount block (model/board_mount.h): its layout, its rotation and the left
// perturbation its rotation vector makes.
#include "plumb/model/board_mount.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>

namespace plumb::model {
namespace {

TEST(BoardMount, DescribesItsSevenValuesInSi) {
  const EffectInfo info = board_mount::Describe();
  ASSERT_EQ(info.size(), board_mount::kSize);
  EXPECT_EQ(info.parameters[board_mount::kRotation].name, "rotation.x");
  EXPECT_EQ(info.parameters[board_mount::kLeverArm + 2].name, "lever_arm.z");
  EXPECT_EQ(info.parameters[board_mount::kTimeOffset].name, "time_offset");
  EXPECT_EQ(info.parameters[board_mount::kRotation + 1].unit, "rad");
  EXPECT_EQ(info.parameters[board_mount::kLeverArm].unit, "m");
  EXPECT_EQ(info.parameters[board_mount::kTimeOffset].unit, "s");
  std::set<std::string> names;
  for (const ParameterInfo& p : info.parameters) {
    names.insert(p.name);
    EXPECT_GT(p.typical, 0.0) << p.name;
    EXPECT_EQ(p.nominal, 0.0) << p.name;  // all zero: where IMU 0 is
  }
  EXPECT_EQ(names.size(), info.parameters.size());
  EXPECT_TRUE(info.input_side);  // SI whatever the outputs' unit
}

TEST(BoardMount, ZeroIsIdentityAndTheRotationIsItsVectorsExp) {
  const double zero[board_mount::kSize] = {};
  EXPECT_EQ(board_mount::Rotation(zero).coeffs(), Quat::Identity().coeffs());
  const double block[board_mount::kSize] = {0.01, -0.02, 0.03, 0.05, 0.0, 0.0, 1e-3};
  const Eigen::AngleAxisd aa(board_mount::Rotation(block));
  EXPECT_NEAR((aa.angle() * aa.axis() - Vec3(0.01, -0.02, 0.03)).norm(), 0.0, 1e-15);
}

// Exp(rho + d) = Exp(J_l(rho) d) Exp(rho): against a central difference of Log.
TEST(BoardMount, TheLeftPerturbationOfItsRotationVector) {
  double block[board_mount::kSize] = {0.3, -0.2, 0.5, 0, 0, 0, 0};
  const Mat3 J = board_mount::LeftPerturbation_H_rotation(block);
  const Quat R = board_mount::Rotation(block);
  constexpr double kStep = 1e-6;
  for (int j = 0; j < 3; ++j) {
    double plus[board_mount::kSize], minus[board_mount::kSize];
    std::copy(block, block + board_mount::kSize, plus);
    std::copy(block, block + board_mount::kSize, minus);
    plus[j] += kStep;
    minus[j] -= kStep;
    const Eigen::AngleAxisd up(board_mount::Rotation(plus) * R.inverse());
    const Eigen::AngleAxisd down(board_mount::Rotation(minus) * R.inverse());
    const Vec3 column = (up.angle() * up.axis() - down.angle() * down.axis()) / (2 * kStep);
    EXPECT_LT((column - J.col(j)).norm(), 1e-8) << j;
  }
}

}  // namespace
}  // namespace plumb::model
