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
// Propagation. Jacobians are analytic, as in IMU preintegration: the right-perturbation
// sensitivity of dR, A (3 x unknowns), follows A_i+1 = Exp(phi_i)^T A_i + J_r(phi_i)
// d(phi_i)/d(unknowns). With C0 = h/2 I - h^2/12 [u1]x, C1 = h/2 I + h^2/12 [u0]x and W_i =
// d w_i / d(unknowns):
//   d phi = C0 dU0 + C1 dU1,  dU = W - d e,  d e = [e]x A + [0 | dR^T d omega_k],
//   A' = (Exp(phi)^T - J_r (C0 + C1) [e]x) A + J_r C0 W_i + J_r C1 W_i+1
//        - [0 | J_r (C0 + C1) dR^T d omega_k].
// Without Earth rate A is carried in the interval's start frame, A~_i = dR_i A_i:
// A~_i+1 = A~_i + dR_i+1 (J_r C0 W_i + J_r C1 W_i+1), A = dR^T A~ at the end; each W_i then
// enters once, with G_i = dR_i+1 J_r C0 (step i) + dR_i J_r C1 (step i-1), and in closed form
// only the sums of gyro_linear::SubtractSummedRateJacobian are kept (their product with E^-1
// taken once). A value alone without Earth rate is integrated on unit quaternions.
//
// d(w_i)/d(theta) is closed-form for the base model; with other effects it is implicit, the
// linear stage's share closed-form and the other terms' from Jets (one pass per 8 parameters
// through the term that owns them). The cost is one pass over the samples per evaluation.
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
#include "plumb/residuals/measurements.h"

namespace plumb::residuals {

/// d w_i / d theta of every sample of an interval, 3 x P each. Stored either whole (columns
/// [0, P), side by side in one allocation) or, when the linear stage's share has its closed
/// form, as the columns [first, P) of the other terms plus, per sample, d w / d p (3 x 6, the
/// rate rows of -D_x^-1: how w moves when p is added to the predicted outputs y_a, y_g at a
/// fixed measurement, -d w / d y) and the corrected force f: the linear stage's columns are
/// then d w / d p times d p / d theta (e_r f_c and I for F and b_a, e_r w_c and I for E and
/// b_g), applied by the caller with the linear residuals' own column functions.
class RateJacobians {
 public:
  void Reset(std::size_t samples, int first, int columns) {
    first_ = first;
    P_ = columns;
    columns_.setZero(3, static_cast<Eigen::Index>(samples) * P_);
    dw_dp_.clear();
    f_.clear();
  }
  /// The stored columns of sample i (those from first()).
  auto operator[](std::size_t i) { return columns_.middleCols(static_cast<Eigen::Index>(i) * P_, P_); }
  auto operator[](std::size_t i) const {
    return columns_.middleCols(static_cast<Eigen::Index>(i) * P_, P_);
  }
  int first() const { return static_cast<int>(first_); }
  int columns() const { return static_cast<int>(P_); }
  /// Gives the linear stage's share by d w / d p per sample (see above).
  void SetLinearStage(std::vector<Eigen::Matrix<double, 3, 6>> dw_dp, std::vector<Vec3> f,
                      bool coupled) {
    dw_dp_ = std::move(dw_dp);
    f_ = std::move(f);
    coupled_ = coupled;
  }
  bool linear_stage_closed() const { return !dw_dp_.empty(); }
  const Eigen::Matrix<double, 3, 6>& dw_dp(std::size_t i) const { return dw_dp_[i]; }
  const Vec3& f(std::size_t i) const { return f_[i]; }
  /// Some rate depends on the accelerometer's input (its columns are then not zero).
  bool coupled() const { return coupled_; }

 private:
  Eigen::Index first_ = 0, P_ = 0;
  Eigen::Matrix<double, 3, Eigen::Dynamic> columns_;
  std::vector<Eigen::Matrix<double, 3, 6>> dw_dp_;
  std::vector<Vec3> f_;
  bool coupled_ = false;
};

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
  /// True when the model acts as its linear stage at `theta`: every other effect is at zero
  /// and its Jacobian is not requested (`jacobians` may be null).
  bool LinearAt(double const* const* theta, double** jacobians) const;
  /// Corrected rates w_i of the outputs `gyr` and, if `W` is non-null, their Jacobians
  /// d w_i / d theta (3 x P, P = all model parameters in block order); `linear` selects the
  /// closed form of LinearAt.
  void CorrectedRates(double const* const* theta, const std::vector<Vec3>& gyr, bool linear,
                      std::vector<Vec3>* w, RateJacobians* W) const;
  /// E^-1 at `theta` and the offset of the gyroscope's linear block among the P parameters
  /// (identity and -1 without a gyroscope term).
  std::pair<Mat3, int> ClosedFormGyro(double const* const* theta) const;
  /// The gyroscope's outputs with the bias walk taken off: y_g,i - ((1 - a_i) b_from + a_i b_to),
  /// the walk's blocks summed over its processes.
  std::vector<Vec3> WalkedOutputs(double const* const* parameters) const;
  /// dR without Earth rate, from the corrected rates `w`: the same product of exponentials
  /// on unit quaternions (a value alone needs no 3 x 3 matrix per step; the same rotation to
  /// rounding).
  Mat3 IntegratedRotation(const std::vector<Vec3>& w) const;
  /// Ceres's Jacobians of the residual r = W Log(M R_k+1), M = dR^T R_k^T, from the propagated
  /// sensitivities A of dR (columns: `rate_cols` model parameters from `rate_first`, the
  /// attitude R_k, then each walk's b_from and b_to).
  void WriteJacobians(const Vec3& r, const Mat3& M, const Eigen::Matrix<double, 3, Eigen::Dynamic>& A,
                      int rate_first, int rate_cols, const Quat& q_k, const Quat& q_k1,
                      double** jacobians) const;
  /// The general model's d w_i / d theta (3 x P) at the corrected inputs (f_i, w_i), given the
  /// model's output at zero input (its F and E).
  void ImplicitRateJacobians(double const* const* theta,
                             const model::SensorOutput<double>& at_zero,
                             const std::vector<Vec3>& f, const std::vector<Vec3>& w,
                             RateJacobians& W) const;
  /// The Jet passes of ImplicitRateJacobians: (parameters seeded, at most model::kJetStride of
  /// the P; the terms applied), one per kJetStride parameters of a term that can move the
  /// rates (`coupled`: the sensors' inputs are coupled somewhere, so accelerometer terms can),
  /// through that term alone when the terms are split, and the linear stage's with the terms
  /// that read it unless it is closed-form (`linear_closed`).
  std::vector<std::pair<std::vector<int>, std::vector<int>>> JetPasses(bool coupled,
                                                                       bool linear_closed) const;

  const model::Model* model_;
  SharedMotionSamples samples_;  // shared with the other problems built on the same samples
  const MotionSamples& s_;
  Vec3 omega_ie_n_;
  int num_model_parameters_ = 0;
  std::vector<int> block_offset_;  // offset of each model block in the P parameters
  std::vector<std::pair<int, int>> parameter_of_;  // per parameter of the P: (term, index)
  int wander_ = 0;                 // wander processes; their block pairs follow the model's
  int bias_offset_ = -1;           // offset of b_g among the P parameters (-1: no gyroscope)
  std::vector<double> walk_weight_;  // per sample, with a walk: a_i, the weight of b_to
  // The model's terms: all, the linear stage's, the catalogue's; the linear stage's followed
  // by the catalogue terms that read its F or E (empty when none does); false when some
  // catalogue term reads the outputs summed before it (every Jet pass then runs every term).
  std::vector<int> all_terms_, linear_terms_, catalogue_terms_, stage_readers_;
  bool terms_split_ = true;
};

/// d(Exp(delta) (x) q)/d(delta) at delta = 0 for q in Eigen order (x y z w): 4 x 3.
Eigen::Matrix<double, 4, 3> LeftPlusJacobian(const Quat& q);

}  // namespace plumb::residuals
