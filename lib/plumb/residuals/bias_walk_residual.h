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
// The bias instability (a first-order Gauss-Markov process of steady-state sigma s and
// correlation time tau per axis) is Markov too; its factor between two instants is
//
//   r = (b_to - phi b_from) ./ (s sqrt(1 - phi^2)),     phi = exp(-(t_to - t_from) / tau),
//
// and its anchor (the process is zero at t_ref, like the walk) is the same with b_from = 0.
// Both are this functor: phi = 1 for the walk.
//
// Parameter blocks: b_from (3) then b_to (3); or b_to (3) only for the anchor.
#pragma once

#include <ceres/cost_function.h>

#include "plumb/core/types.h"

namespace plumb::residuals {

class BiasWalkResidual {
 public:
  /// `inv_sigma`: 1 / the sigma of the step per axis (walk: K sqrt(dt); instability:
  /// s sqrt(1 - phi^2)), 1 / sensor units (> 0, finite); `phi`: the factor carried over
  /// (1 for the walk, exp(-dt / tau) for the instability).
  explicit BiasWalkResidual(const Vec3& inv_sigma, double phi = 1.0)
      : inv_sigma_(inv_sigma), phi_(phi) {}

  template <typename T>
  bool operator()(const T* from, const T* to, T* residuals) const {
    for (int i = 0; i < 3; ++i) residuals[i] = (to[i] - phi_ * from[i]) * inv_sigma_[i];
    return true;
  }
  template <typename T>
  bool operator()(const T* to, T* residuals) const {
    for (int i = 0; i < 3; ++i) residuals[i] = to[i] * inv_sigma_[i];
    return true;
  }

  /// The factor between two states (blocks b_from, b_to).
  static ceres::CostFunction* Create(const Vec3& inv_sigma, double phi = 1.0);
  /// The anchor: the walk starts at zero at t_ref (block b_to).
  static ceres::CostFunction* CreateAnchor(const Vec3& inv_sigma);

 private:
  Vec3 inv_sigma_;
  double phi_ = 1.0;
};

}  // namespace plumb::residuals
