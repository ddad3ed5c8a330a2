// plumb/residuals/still_residuals.h — residuals of still segments (SPEC section 3).
//
// Still accelerometer, segment k, attitude R_k = R_n_b during the segment:
//
//   r_a = W_a (mean(y_a)_k - h_a(theta, f_b = R_k^T (-g_n), omega_b = R_k^T omega_ie_n))
//
// Still gyroscope (the Earth-rate constraint), with a known turntable rate if stated:
//
//   r_g = W_g (mean(y_g)_k - h_g(theta, f_b, omega_b = R_k^T omega_ie_n + omega_eb_b))
//
// h is the model's forward prediction (plumb/model/model.h) evaluated only with the terms of
// the residual's sensor. W = diag(sqrt_info) whitens by the standard deviation of the segment
// mean (sqrt(N_k) / sigma_k, corrected for sample correlation), so the cost does not grow with
// the number of samples.
//
// With a bias random walk (residuals/bias_walk_residual.h) the segment's mean output also
// carries the mean of the walk over the segment, (s_k + e_k) / 2 given the walk at its first
// and last sample (the rest, a Brownian bridge of variance K^2 T / 12, is in sqrt_info):
//
//   r = W (mean(y)_k - h(theta, ...) - (s_k + e_k) / 2)
//
// More generally the bias wanders as a sum of independent Markov processes (the walk, the
// instability's Gauss-Markov process), each with its states at both ends; the segment mean
// carries sum_p w_p (s_p + e_p), w_p the weight of process p (1/2 for the walk; for a
// Gauss-Markov process the mean of its bridge), and sqrt_info the variance of every
// process's bridge about it (estimation/noise_model.h, BridgeMeanVariance; set in
// estimation/calibration_problem.cc).
//
// Another IMU of the same board (SPEC 6, "Several IMUs of one board") sits in the body at a
// rotation R_b_i (its frame into the body frame, which IMU 0's accelerometer defines;
// model/board_mount.h): it
// sees the inputs in its own frame, f_i = R_b_i^T f_b and omega_i = R_b_i^T omega_b, as an IMU
// at attitude R_n_i = R_n_b R_b_i. A still pose has no angular rate or acceleration, so its
// lever arm and time offset do not enter. CreateMounted makes that residual, with the pose's
// attitude shared by every IMU of the board.
//
// Parameter blocks, in order: q_k (4, Eigen order x y z w, unit quaternion of R_n_b), then
// (CreateMounted only) IMU i's board_mount block (7: R_b_i's rotation vector, its lever arm and
// time offset, model/board_mount.h; only the rotation enters), then the blocks of the model terms
// listed in `terms` (their sizes in info().size()), then, per entry of `wander_weights`, s_p (3)
// and e_p (3) in sensor units.
// Units: g_n in m/s^2 (NED, down positive), omega in rad/s, outputs in sensor units.
#pragma once

#include <ceres/dynamic_autodiff_cost_function.h>

#include <memory>
#include <vector>

#include "plumb/autodiff/differentiable_effect.h"
#include "plumb/model/model.h"
#include "plumb/residuals/measurements.h"

namespace plumb::residuals {

class StillResidual {
 public:
  /// `sensor` selects accelerometer or gyroscope; `terms` are the model's term indices for
  /// that sensor (see TermsOf); `g_n` gravity in NED, m/s^2; `omega_ie_n` Earth rate in NED,
  /// rad/s (zero without a site); `omega_eb_b` a known rate relative to the Earth, rad/s.
  StillResidual(const model::Model& model, model::Sensor sensor, std::vector<int> terms,
                StillMeasurement measurement, const Vec3& g_n, const Vec3& omega_ie_n,
                const Vec3& omega_eb_b = Vec3::Zero(), std::vector<double> wander_weights = {},
                bool mounted = false);

  template <typename T>
  bool operator()(T const* const* parameters, T* residuals) const;

  /// The cost function; parameter blocks as documented above.
  static ceres::CostFunction* Create(const model::Model& model, model::Sensor sensor,
                                     StillMeasurement measurement, const Vec3& g_n,
                                     const Vec3& omega_ie_n,
                                     const Vec3& omega_eb_b = Vec3::Zero(), std::vector<double> wander_weights = {});

  /// The same for an IMU mounted at R_b_i in the body (file comment): its board_mount block
  /// follows q_k.
  static ceres::CostFunction* CreateMounted(const model::Model& model, model::Sensor sensor,
                                            StillMeasurement measurement, const Vec3& g_n,
                                            const Vec3& omega_ie_n, const Vec3& omega_eb_b,
                                            std::vector<double> wander_weights);

  /// Indices of the model terms that act on `sensor`.
  static std::vector<int> TermsOf(const model::Model& model, model::Sensor sensor);

  /// The prediction (unwhitened) at given values, for reports: q_k, the model blocks, and for a
  /// mounted residual the IMU's rotation R_b_i into the body (an unmounted one is IMU 0's, whose
  /// frame is the body's: it has no such block).
  Vec3 Predict(const double* q_k, const model::ParameterBlocks& theta,
               const Quat& R_b_i = Quat::Identity()) const;

 private:
  template <typename T>
  Vec3T<T> PredictT(T const* const* parameters) const;

  const model::Model* model_;
  model::Sensor sensor_;
  std::vector<int> terms_;
  std::vector<autodiff::DifferentiableEffect> effects_;  // the effects of terms_, on both scalars
  StillMeasurement m_;
  Vec3 g_n_, omega_ie_n_, omega_eb_b_;
  std::vector<double> wander_weights_;  // per wander process: w_p
  int first_term_block_ = 1;            // 2 when the board_mount block follows q_k (mounted)
};

}  // namespace plumb::residuals
