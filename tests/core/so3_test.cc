// SO(3) helpers: invariants (Exp/Log inverse, orthogonality) and Jacobians against central
// differences, on both sides of the series threshold.
#include "plumb/core/so3.h"

#include <gtest/gtest.h>

namespace plumb::so3 {
namespace {

const Vec3 kAngles[] = {Vec3(1e-9, 0, 0), Vec3(0.01, -0.02, 0.015), Vec3(0.03, 0.02, -0.025),
                        Vec3(0.04, 0.03, 0.0), Vec3(0.3, -1.1, 0.7), Vec3(2.0, 1.0, -0.5)};

TEST(So3, ExpIsARotationAndLogInvertsIt) {
  for (const Vec3& phi : kAngles) {
    const Mat3 R = Exp(phi);
    EXPECT_LT((R.transpose() * R - Mat3::Identity()).norm(), 1e-15);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-15);
    EXPECT_LT((Log(R) - phi).norm(), 1e-12 * std::max(1.0, phi.norm()));
  }
}

TEST(So3, ExpMatchesAngleAxisAndQuaternion) {
  for (const Vec3& phi : kAngles) {
    const Mat3 ref = Eigen::AngleAxisd(phi.norm(), phi.normalized()).toRotationMatrix();
    EXPECT_LT((Exp(phi) - ref).norm(), 1e-15);
    EXPECT_LT((ExpQuat(phi).toRotationMatrix() - ref).norm(), 1e-15);
  }
}

TEST(So3, RightJacobianMatchesCentralDifferences) {
  // Exp(phi + d) = Exp(phi) Exp(J_r d): column j is Log(Exp(phi)^T Exp(phi + h e_j)) / h.
  for (const Vec3& phi : kAngles) {
    Mat3 numeric;
    const double h = 1e-6;
    for (int j = 0; j < 3; ++j) {
      const Vec3 d = h * Vec3::Unit(j);
      numeric.col(j) = (Log(Exp(phi).transpose() * Exp(phi + d)) -
                        Log(Exp(phi).transpose() * Exp(phi - d))) / (2 * h);
    }
    EXPECT_LT((RightJacobian(phi) - numeric).norm(), 1e-8);
  }
}

TEST(So3, LeftJacobianInverseMatchesCentralDifferences) {
  // Log(Exp(d) R) = Log(R) + J_l^-1(Log R) d.
  for (const Vec3& phi : kAngles) {
    const Mat3 R = Exp(phi);
    Mat3 numeric;
    const double h = 1e-6;
    for (int j = 0; j < 3; ++j) {
      const Vec3 d = h * Vec3::Unit(j);
      numeric.col(j) = (Log(Exp(d) * R) - Log(Exp(-d) * R)) / (2 * h);
    }
    EXPECT_LT((LeftJacobianInverse(phi) - numeric).norm(), 1e-8);
  }
}

}  // namespace
}  // namespace plumb::so3
