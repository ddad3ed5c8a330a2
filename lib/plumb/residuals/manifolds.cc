#include "plumb/residuals/manifolds.h"

#include <ceres/autodiff_manifold.h>
#include <ceres/rotation.h>

namespace plumb::residuals {
namespace {

/// Left perturbation by a rotation vector whose components [kFirst, kFirst + kTangent) are
/// free (0 north, 1 east, 2 down). Quaternions in Eigen order (x y z w); ceres::rotation uses
/// (w x y z).
template <int kFirst, int kTangent>
struct LeftRotationPlus {
  template <typename T>
  bool Plus(const T* x, const T* delta, T* x_plus_delta) const {
    T rv[3] = {T(0), T(0), T(0)};
    for (int i = 0; i < kTangent; ++i) rv[kFirst + i] = delta[i];
    T dq[4];
    ceres::AngleAxisToQuaternion(rv, dq);
    const T q[4] = {x[3], x[0], x[1], x[2]};
    T out[4];
    ceres::QuaternionProduct(dq, q, out);
    x_plus_delta[0] = out[1];
    x_plus_delta[1] = out[2];
    x_plus_delta[2] = out[3];
    x_plus_delta[3] = out[0];
    return true;
  }

  template <typename T>
  bool Minus(const T* y, const T* x, T* y_minus_x) const {
    // Log(y (x) x^-1)
    const T qy[4] = {y[3], y[0], y[1], y[2]};
    const T qx_inv[4] = {x[3], -x[0], -x[1], -x[2]};
    T d[4];
    ceres::QuaternionProduct(qy, qx_inv, d);
    if (d[0] < T(0)) {
      for (T& v : d) v = -v;
    }
    T rv[3];
    ceres::QuaternionToAngleAxis(d, rv);
    for (int i = 0; i < kTangent; ++i) y_minus_x[i] = rv[kFirst + i];
    return true;
  }
};

}  // namespace

std::unique_ptr<ceres::Manifold> AttitudeManifold() {
  return std::make_unique<ceres::AutoDiffManifold<LeftRotationPlus<0, 3>, 4, 3>>();
}

std::unique_ptr<ceres::Manifold> TiltManifold() {
  return std::make_unique<ceres::AutoDiffManifold<LeftRotationPlus<0, 2>, 4, 2>>();
}

std::unique_ptr<ceres::Manifold> HeadingManifold() {
  return std::make_unique<ceres::AutoDiffManifold<LeftRotationPlus<2, 1>, 4, 1>>();
}

}  // namespace plumb::residuals
