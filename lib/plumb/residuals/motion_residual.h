// plumb/residuals/motion_residual.h — the gyroscope integrated between two still segments.
//
// Between still segment k (attitude R_k) and k+1 (attitude R_k+1) the corrected rate
//
//   w_i = model inverse of y_g,i (E^-1 (y_g - b_g - effects) for the base model),  rad/s
//   e_i = dR_i^T R_k^T omega_ie_n           (Earth rate seen in the body frame at sample i)
//
// is integrated on SO(3) as a product of exponentials of the two-sample coning-corrected
// increments (third order in the step, like RK4 on a rate linear between samples):
//
//   phi_i = (h/2) (u_i + u_i+1) + (h^2/12) u_i x u_i+1,   u_i = w_i - e_i,   h = t_i+1 - t_i
//   dR = prod_i Exp(phi_i)
//
// and the residual is r = W Log(dR^T R_k^T R_k+1) (3 values, rad), whitened by
// W = diag(sqrt_info), the propagated white gyroscope noise of the interval.
//
// Propagation: the strapdown core (residuals/strapdown.h) carries the right-perturbation
// sensitivity of dR through the samples, with Earth rate in the body frame; without it in the
// interval's start frame, where each sample's rate Jacobian enters once and, in closed form,
// only the sums of gyro_linear::SubtractSummedRateJacobian are kept (their product with E^-1
// taken once). A value alone without Earth rate is integrated on unit quaternions.
//
// The rates and their Jacobians come from the model's inverse (residuals/corrected_rates.h):
// closed-form for the base model (and wherever every other effect is at zero and not
// differentiated), implicit otherwise. The cost is one pass over the samples per evaluation.
//
// With a gyroscope bias random walk (residuals/bias_walk_residual.h), the output carries the
// walk too: it is b_from at the first sample (the walk at the last sample of segment k) and
// b_to at the last (the walk at the first sample of k+1), linear in time between them (the
// Brownian bridge about that line is in sqrt_info), and is taken off the output before the
// model is inverted: y_g,i - ((1 - a_i) b_from + a_i b_to), a_i = (t_i - t_0) / (t_n - t_0).
// It enters like the gyroscope bias, so d w_i / d b_from = (1 - a_i) d w_i / d b_g. When the
// bias wanders as a sum of processes (walk, instability), b_from and b_to are the sums of
// their states, which all have the same Jacobian.
//
// Parameter blocks, in order: q_k (4), q_k+1 (4) (Eigen order x y z w, R_n_b, manifolds of
// plumb/residuals/manifolds.h: left perturbation in NED), then every block of the model in
// model order, then, per wander process (`wander_processes` of them), its b_from (3) and b_to
// (3) in sensor units.
#pragma once

#include <memory>
#include <utility>
#include <vector>

#include "plumb/model/model.h"
#include "plumb/residuals/cached_cost_function.h"
#include "plumb/residuals/corrected_rates.h"
#include "plumb/residuals/measurements.h"
#include "plumb/residuals/strapdown.h"

namespace plumb::residuals {

/// The residual of the file comment. A CachedCostFunction: its evaluations may be made ahead
/// of Ceres's call, all intervals at once (estimation/parallel_evaluation.h); it keeps no
/// other state, so distinct objects may be evaluated on distinct threads.
class MotionResidual final : public CachedCostFunction {
 public:
  /// `omega_ie_n`: Earth rate in NED, rad/s (zero without a site). The model must outlive
  /// the cost function.
  MotionResidual(const model::Model& model, SharedMotionSamples samples, const Vec3& omega_ie_n,
                 int wander_processes = 0);
  MotionResidual(const model::Model& model, MotionSamples samples, const Vec3& omega_ie_n,
                 int wander_processes = 0)
      : MotionResidual(model, std::make_shared<const MotionSamples>(std::move(samples)),
                       omega_ie_n, wander_processes) {}

  static ceres::CostFunction* Create(const model::Model& model, SharedMotionSamples samples,
                                     const Vec3& omega_ie_n, int wander_processes = 0) {
    return new MotionResidual(model, std::move(samples), omega_ie_n, wander_processes);
  }
  static ceres::CostFunction* Create(const model::Model& model, MotionSamples samples,
                                     const Vec3& omega_ie_n, int wander_processes = 0) {
    return new MotionResidual(model, std::move(samples), omega_ie_n, wander_processes);
  }

  /// ceres::CostFunction::Evaluate's contract (CachedCostFunction::Evaluate hands out a
  /// precomputed one when it can).
  bool EvaluateUncached(double const* const* parameters, double* residuals,
                        double** jacobians) const override;

  /// The integrated rotation dR = R_k^T R(t_end) (body frame) at given values (with a walk:
  /// the walk at zero).
  Quat Integrate(const double* q_k, const model::ParameterBlocks& theta) const;

 private:
  /// Columns of the propagated sensitivity: the model parameters that move the rates (from
  /// `rate_first` among the P, `rate_columns` of them), the left perturbation of R_k, then
  /// (walk) b_from and b_to.
  struct Layout {
    int rate_first = 0, rate_columns = 0;
    int start_attitude = 0;  ///< first of R_k's three columns
    int walk_from = 0;       ///< first of b_from's three columns (b_to's follow)
    int columns = 0;
  };
  class RateColumns;
  /// dR and its right-perturbation sensitivity (columns of Layout).
  struct Propagated {
    Mat3 dR;
    strapdown::Sensitivity dR_H_x;
  };

  const ModelColumns& columns() const { return correction_.columns(); }
  /// True when the model acts as its linear stage at `theta`: every other effect is at zero
  /// and its Jacobian is not requested (`jacobians` may be null).
  bool LinearAt(double const* const* theta, double** jacobians) const;
  /// With Earth rate: propagated in the body frame (omega_b0 = R_k^T omega_ie_n).
  Propagated PropagateInBodyFrame(const RateColumns& columns, const std::vector<Vec3>& w,
                                  const Vec3& omega_b0, const Mat3& R_k) const;
  /// Without Earth rate: propagated in the start frame (closed form: by its sums).
  Propagated PropagateInStartFrame(const RateColumns& columns, const std::vector<Vec3>& w) const;
  /// E^-1 at `theta` and the offset of the gyroscope's linear block among the P parameters
  /// (identity and -1 without a gyroscope term).
  std::pair<Mat3, int> ClosedFormGyro(double const* const* theta) const;
  /// The gyroscope's outputs with the bias walk taken off: y_g,i - ((1 - a_i) b_from + a_i b_to),
  /// the walk's blocks summed over its processes.
  std::vector<Vec3> WalkedOutputs(double const* const* parameters) const;
  /// Ceres's Jacobians of the residual r = W Log(M R_k+1), M = dR^T R_k^T, from the propagated
  /// sensitivity A of dR (columns of `layout`).
  void WriteJacobians(const Vec3& r, const Mat3& M, const strapdown::Sensitivity& A,
                      const Layout& layout, const Quat& q_k, const Quat& q_k1,
                      double** jacobians) const;

  const model::Model* model_;
  SharedMotionSamples samples_;  // shared with the other problems built on the same samples
  const MotionSamples& s_;
  Vec3 omega_ie_n_;
  RateCorrection correction_;      // the model's inverse on the samples, and its layout
  int wander_ = 0;                 // wander processes; their block pairs follow the model's
  std::vector<double> walk_weight_;  // per sample, with a walk: a_i, the weight of b_to
};

/// d(Exp(delta) (x) q)/d(delta) at delta = 0 for q in Eigen order (x y z w): 4 x 3.
Eigen::Matrix<double, 4, 3> LeftPlusJacobian(const Quat& q);

}  // namespace plumb::residuals
