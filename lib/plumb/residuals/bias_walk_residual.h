// plumb/residuals/bias_walk_residual.h — the bias random walk between two instants.
//
// A MEMS bias is not constant: it walks, b(t2) - b(t1) ~ N(0, K^2 (t2 - t1)) per axis for a
// random walk of density K (sensor units / s / sqrt(Hz), i.e. units / sqrt(s); IEEE Std 952's
// rate or acceleration random walk). The backend (estimation/calibration_problem.h) gives every
// still segment k and sensor two bias-walk states, the walk at the segment's first and last
// sample, s_k and e_k (sensor units, relative to the model's constant bias, which is the bias
// at the model's reference time t_ref). The walk is Markov, so the factors
//
//   r = (b_to - b_from) ./ (K sqrt(t_to - t_from))          (3 values, dimensionless)
//
// between consecutive instants (s_0 from t_ref, s_k to e_k within a segment, e_k to s_k+1
// across a gap) are independent and exact. The anchor at t_ref, where the walk is zero by
// definition, is the same factor with b_from = 0 (one parameter block).
//
// Parameter blocks: b_from (3) then b_to (3); or b_to (3) only for the anchor.
#pragma once

#include <ceres/cost_function.h>

#include "plumb/core/types.h"

namespace plumb::residuals {

class BiasWalkResidual {
 public:
  /// `inv_sigma`: 1 / (K sqrt(dt)) per axis, 1 / sensor units (> 0, finite).
  explicit BiasWalkResidual(const Vec3& inv_sigma) : inv_sigma_(inv_sigma) {}

  template <typename T>
  bool operator()(const T* from, const T* to, T* residuals) const {
    for (int i = 0; i < 3; ++i) residuals[i] = (to[i] - from[i]) * inv_sigma_[i];
    return true;
  }
  template <typename T>
  bool operator()(const T* to, T* residuals) const {
    for (int i = 0; i < 3; ++i) residuals[i] = to[i] * inv_sigma_[i];
    return true;
  }

  /// The factor between two states (blocks b_from, b_to).
  static ceres::CostFunction* Create(const Vec3& inv_sigma);
  /// The anchor: the walk starts at zero at t_ref (block b_to).
  static ceres::CostFunction* CreateAnchor(const Vec3& inv_sigma);

 private:
  Vec3 inv_sigma_;
};

}  // namespace plumb::residuals
