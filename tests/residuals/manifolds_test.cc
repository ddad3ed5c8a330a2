// Invariants of the attitude manifolds (Ceres' own manifold test battery).
#include "plumb/residuals/manifolds.h"

#include <ceres/manifold_test_utils.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

// The Ceres macro names its helpers unqualified, so the tests live in namespace ceres.
namespace ceres {
namespace {

using plumb::residuals::AttitudeManifold;
using plumb::residuals::HeadingManifold;
using plumb::residuals::TiltManifold;

Eigen::Vector4d SomeQuaternion() {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, -2, 0.5).normalized()));
  return Eigen::Vector4d(q.x(), q.y(), q.z(), q.w());
}

TEST(Manifolds, AttitudeManifoldInvariants) {
  const auto owned = AttitudeManifold();
  const Manifold& m = *owned;
  const Eigen::Vector4d x = SomeQuaternion();
  const Eigen::Vector3d delta(0.01, -0.02, 0.03);
  const Eigen::Quaterniond qy(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()));
  const Eigen::Quaterniond qx(x[3], x[0], x[1], x[2]);
  const Eigen::Quaterniond q = qy * qx;
  const Eigen::Vector4d y(q.x(), q.y(), q.z(), q.w());
  EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(m, x, delta, y, 1e-9);
}

TEST(Manifolds, TiltManifoldInvariantsAndHeadingHeld) {
  const auto owned = TiltManifold();
  const Manifold& m = *owned;
  const Eigen::Vector4d x = SomeQuaternion();
  const Eigen::Vector2d delta(0.01, -0.02);
  const Eigen::Quaterniond qn(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()));
  const Eigen::Quaterniond qx(x[3], x[0], x[1], x[2]);
  const Eigen::Quaterniond q = qn * qx;
  const Eigen::Vector4d y(q.x(), q.y(), q.z(), q.w());
  EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(m, x, delta, y, 1e-9);
  EXPECT_EQ(m.TangentSize(), 2);
}

TEST(Manifolds, HeadingManifoldInvariantsAndTiltHeld) {
  const auto owned = HeadingManifold();
  const Manifold& m = *owned;
  const Eigen::Vector4d x = SomeQuaternion();
  const Eigen::Matrix<double, 1, 1> delta(0.03);
  const Eigen::Quaterniond qd(Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond qx(x[3], x[0], x[1], x[2]);
  const Eigen::Quaterniond q = qd * qx;
  const Eigen::Vector4d y(q.x(), q.y(), q.z(), q.w());
  EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(m, x, delta, y, 1e-9);
  EXPECT_EQ(m.TangentSize(), 1);
  // Moving along the tangent keeps the body's gravity direction R^T e_down.
  Eigen::Vector4d moved;
  m.Plus(x.data(), delta.data(), moved.data());
  const Eigen::Quaterniond qm(moved[3], moved[0], moved[1], moved[2]);
  EXPECT_LT((qm.conjugate() * Eigen::Vector3d::UnitZ() - qx.conjugate() * Eigen::Vector3d::UnitZ())
                .norm(),
            1e-12);
}

}  // namespace
}  // namespace ceres
