// plumb/residuals/velocity_residual.h — the accelerometer during the motion between two still
// segments: the IMU is at rest at both ends, so its velocity does not change.
//
// With the corrected gyroscope integrated as in MotionResidual (the strapdown core, residuals/
// strapdown.h: coning-corrected product of exponentials of u_i = w_i - dR_i^T R_k^T omega_ie_n,
// dR_0 = I) and the corrected specific force f_i (both from model::Model::Correct on the
// sample's outputs, with its angular acceleration):
//
//   r = W_v ( sum_i (h_i / 2) (dR_i f_i + dR_i+1 f_i+1) + R_k^T g_n T ),   m/s, body frame of k
//
// (the velocity change expressed in the body frame of segment k; transport and Coriolis terms
// over a few seconds are far below the noise). It is what makes the accelerometer's lever arms
// (accel_size_effect) and the time offset between the triads (time_offset) visible: both
// change f_i or dR_i only while the IMU turns.
//
// Whitening W_v = diag(1 / sigma_v), per axis, from the white noises: the accelerometer's
// (carried through F^-1) summed over the steps, and the gyroscope's (through E^-1) integrated
// into an attitude random walk that tilts gravity:
//   sigma_v^2 = sigma_f^2 h^2 N tau_a + g^2 sigma_w^2 h^4 N^3 tau_g / 3.
// Its correlation with the rotation residual of the same interval is neglected.
//
// The wandering bias (estimation/noise_model.h) over the motion: as in MotionResidual, each
// process of each sensor runs along the line from its value at the end of segment k (b_from)
// to its value at the start of k+1 (b_to), and the sum of a sensor's processes is taken off its
// outputs before the correction: y(t) - (b_from + (b_to - b_from) (t - t_0) / T). (The bridge
// about that line is in sqrt_info.)
//
// Jacobians: analytic where the model acts as its linear stage (every other effect at zero:
// the base model, and diagnose's probe fits, whose probe columns alone are then
// differentiated numerically), in the same pass:
// by the strapdown core (residuals/strapdown.h), with A_i the right-perturbation sensitivity
// of dR_i and
// df_i/dx closed-form (f = F^-1 (y_a - b_a): d f / d F_rc = -F^-1 e_r f_c, d f / d b_a = -F^-1),
//   d(dR_i f_i) = dR_i (d f_i - [f_i]x A_i dx),   d(R_k^T g_n T) / d delta_k = R_k^T [g_n]x T.
// Otherwise central differences (ceres::DynamicNumericDiffCostFunction), one pass over the
// samples per parameter. The backend adds these residuals only when the model has an effect
// that needs them (EffectInfo::excitation.angular_acceleration).
//
// Parameter blocks, in order: q_k (4, R_n_b in Eigen order x y z w), then every block of the
// model in model order, then per accelerometer wander process (`accel_wander` of them) its
// b_from (3) and b_to (3), then the same per gyroscope process (`gyro_wander`), sensor units.
#pragma once

#include <ceres/cost_function.h>

#include <memory>

#include "plumb/model/model.h"
#include "plumb/residuals/corrected_rates.h"
#include "plumb/residuals/measurements.h"

namespace plumb::residuals {

class VelocityResidual {
 public:
  /// `g_n` gravity in NED, m/s^2; `omega_ie_n` Earth rate in NED, rad/s; `sqrt_info` 1 / sigma_v
  /// per axis, s/m. The model must outlive the cost function.
  VelocityResidual(const model::Model& model, SharedMotionSamples samples, const Vec3& g_n,
                   const Vec3& omega_ie_n, const Vec3& sqrt_info, int accel_wander = 0,
                   int gyro_wander = 0);
  VelocityResidual(const model::Model& model, MotionSamples samples, const Vec3& g_n,
                   const Vec3& omega_ie_n, const Vec3& sqrt_info, int accel_wander = 0,
                   int gyro_wander = 0)
      : VelocityResidual(model, std::make_shared<const MotionSamples>(std::move(samples)), g_n,
                         omega_ie_n, sqrt_info, accel_wander, gyro_wander) {}

  /// The cost function (analytic Jacobians at the linear stage, else numeric differentiation
  /// over q_k, every model block and the wander blocks).
  static ceres::CostFunction* Create(const model::Model& model, SharedMotionSamples samples,
                                     const Vec3& g_n, const Vec3& omega_ie_n,
                                     const Vec3& sqrt_info, int accel_wander = 0,
                                     int gyro_wander = 0);
  static ceres::CostFunction* Create(const model::Model& model, MotionSamples samples,
                                     const Vec3& g_n, const Vec3& omega_ie_n,
                                     const Vec3& sqrt_info, int accel_wander = 0,
                                     int gyro_wander = 0) {
    return Create(model, std::make_shared<const MotionSamples>(std::move(samples)), g_n,
                  omega_ie_n, sqrt_info, accel_wander, gyro_wander);
  }

  /// r (3 values, whitened) at the given blocks.
  bool operator()(double const* const* parameters, double* residuals) const;

  /// The velocity change sum (unwhitened, m/s, body frame of k).
  Vec3 VelocityChange(double const* const* parameters) const;

  /// The model the residual corrects the samples with.
  const model::Model& model() const { return *model_; }
  /// Whether parameter block `block` is q_k, a linear-stage term's or a wander block: the
  /// blocks EvaluateLinear differentiates.
  bool IsLinearBlock(std::size_t block) const;
  /// r and its analytic Jacobians (Ceres's layout: row-major, ambient for q_k; null blocks
  /// skipped) where the model is at its linear stage (model::Model::AtLinearStage; the other
  /// terms' blocks must be null).
  void EvaluateLinear(double const* const* parameters, double* residuals,
                      double** jacobians) const;

 private:
  const model::Model* model_;
  SharedMotionSamples samples_;  // shared with the other problems built on the same samples
  const MotionSamples& s_;
  Vec3 g_n_, omega_ie_n_, sqrt_info_;
  int accel_wander_ = 0, gyro_wander_ = 0;  // wander processes; their block pairs follow the model's
  ModelColumns columns_;  // where each model block sits among the P parameters
};

}  // namespace plumb::residuals
