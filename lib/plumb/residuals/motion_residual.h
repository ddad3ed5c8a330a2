// plumb/residuals/motion_residual.h — the gyroscope integrated between two still segments.
//
// Between still segment k (attitude R_k) and k+1 (attitude R_k+1) the corrected rate
//
//   omega_b(t) = model inverse of y_g(t) (E^-1 (y_g - b_g - effects) for the base model),
//   omega_nb_b(t) = omega_b(t) - R_b_n(t) omega_ie_n       (Earth rate removed)
//
// is integrated on SO(3) with fourth-order Runge-Kutta on the unit quaternion, the rate
// linear between samples, giving dR = R_k^T R(t_end). The residual is
//
//   r = W Log(dR^T R_k^T R_k+1)   (3 values, rad)
//
// whitened by W = diag(sqrt_info), the propagated white gyroscope noise of the interval.
//
// Parameter blocks, in order: q_k (4), q_k+1 (4) (Eigen order x y z w, R_n_b), then every
// block of the model in model order. Samples and time in plumb::residuals::MotionSamples.
#pragma once

#include <ceres/cost_function.h>

#include "plumb/model/model.h"
#include "plumb/residuals/measurements.h"

namespace plumb::residuals {

class MotionResidual {
 public:
  /// `omega_ie_n`: Earth rate in NED, rad/s (zero without a site). The model must outlive
  /// the functor.
  MotionResidual(const model::Model& model, MotionSamples samples, const Vec3& omega_ie_n);

  template <typename T>
  bool operator()(T const* const* parameters, T* residuals) const;

  static ceres::CostFunction* Create(const model::Model& model, MotionSamples samples,
                                     const Vec3& omega_ie_n);

  /// The integrated rotation dR (as a quaternion x y z w) at given values, for reports and
  /// initialisation.
  Quat Integrate(const double* q_k, const model::ParameterBlocks& theta) const;

 private:
  template <typename T>
  Eigen::Quaternion<T> IntegrateT(T const* const* parameters) const;

  const model::Model* model_;
  MotionSamples s_;
  Vec3 omega_ie_n_;
  int newton_iterations_;
};

}  // namespace plumb::residuals
