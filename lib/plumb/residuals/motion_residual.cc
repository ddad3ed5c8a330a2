#include "plumb/residuals/motion_residual.h"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>
#include <utility>

#include "plumb/core/so3.h"
#include "plumb/model/effects/gyro_linear.h"
#include "plumb/residuals/strapdown.h"

namespace plumb::residuals {
using so3::Skew;
namespace {

/// The closed form's share of the propagated sensitivities without Earth rate: the sums over
/// samples of G_i w_i,c, G_i and a_i G_i, multiplied by E^-1 once at the end (E^-1 is the
/// same for every sample).
struct GyroStageSums {
  std::array<Mat3, 3> by_rate = {Mat3::Zero(), Mat3::Zero(), Mat3::Zero()};
  Mat3 total = Mat3::Zero();  ///< sum_i G_i
  Mat3 to = Mat3::Zero();     ///< sum_i a_i G_i (the walk's b_to weight)

  void Add(const Mat3& G, const Vec3& w, double a) {
    for (int c = 0; c < 3; ++c) by_rate[static_cast<std::size_t>(c)] += w[c] * G;
    total += G;
    if (a != 0.0) to += a * G;  // without a walk (a = 0) nothing to add
  }
  /// Subtracts the sums times E^-1 from the gyroscope's 12 leading columns of A and, when
  /// `walk_from` >= 0, from the walk's b_from and b_to columns there.
  void SubtractFrom(const Mat3& E_inv, int walk_from,
                    Eigen::Matrix<double, 3, Eigen::Dynamic>& A) const {
    model::gyro_linear::SubtractSummedRateJacobian(E_inv, by_rate, total,
                                                   A.leftCols(model::gyro_linear::kSize));
    if (walk_from < 0) return;
    A.middleCols<3>(walk_from).noalias() -= (total - to) * E_inv;
    A.middleCols<3>(walk_from + 3).noalias() -= to * E_inv;
  }
};

}  // namespace

Eigen::Matrix<double, 4, 3> LeftPlusJacobian(const Quat& q) {
  // (0, a) (x) (w, v) = (-a.v, w a + a x v); Exp(delta) ~ (1, delta / 2).
  Eigen::Matrix<double, 4, 3> P;
  const Vec3 v = q.vec();
  for (int j = 0; j < 3; ++j) {
    const Vec3 a = Vec3::Unit(j);
    P.block<3, 1>(0, j) = 0.5 * (q.w() * a + a.cross(v));
    P(3, j) = -0.5 * v[j];
  }
  return P;
}

MotionResidual::MotionResidual(const model::Model& model, SharedMotionSamples samples,
                               const Vec3& omega_ie_n, int wander_processes)
    : model_(&model), samples_(std::move(samples)), s_(*samples_), omega_ie_n_(omega_ie_n),
      correction_(model), wander_(wander_processes) {
  set_num_residuals(3);
  mutable_parameter_block_sizes()->push_back(4);
  mutable_parameter_block_sizes()->push_back(4);
  for (const auto& t : model.terms()) mutable_parameter_block_sizes()->push_back(t.effect->info().size());
  if (wander_ > 0) {
    for (int b = 0; b < 2 * wander_; ++b) mutable_parameter_block_sizes()->push_back(3);
    const double span = s_.dt_s.back() - s_.dt_s.front();
    for (std::size_t i = 0; i < s_.size(); ++i) {
      walk_weight_.push_back(span > 0 ? (s_.dt_s[i] - s_.dt_s.front()) / span : 0.0);
    }
  }
}

/// The strapdown core's add_rate_H_x for this residual (residuals/strapdown.h): adds K w_i_H_x
/// to the propagated sensitivity, whose columns Layout gives, from the closed form of the
/// linear stage or from the rates' stored Jacobians (residuals/corrected_rates.h).
class MotionResidual::RateColumns {
 public:
  /// Every argument must outlive the object.
  RateColumns(const MotionResidual& residual, double const* const* theta,
              const CorrectedRates& rates, bool closed_form)
      : r_(residual), rates_(rates), closed_form_(closed_form) {
    if (closed_form_) std::tie(E_inv_, gyro_offset_) = residual.ClosedFormGyro(theta);
    const int P = residual.columns().parameters;
    // The model parameters that move the rates: all P in general; in closed form the
    // gyroscope's linear block only (the others' columns are zero).
    layout_.rate_columns = !closed_form_ ? P : gyro_offset_ >= 0 ? model::gyro_linear::kSize : 0;
    layout_.rate_first = closed_form_ ? std::max(gyro_offset_, 0) : 0;
    layout_.start_attitude = layout_.rate_columns;
    layout_.walk_from = layout_.rate_columns + 3;
    layout_.columns = layout_.rate_columns + 3 + (residual.wander_ > 0 ? 6 : 0);
  }

  /// out += K d w_i / d x, and with a walk K d w_i / d b_from and K d w_i / d b_to.
  void operator()(const Mat3& K, std::size_t i, strapdown::Sensitivity& out) const {
    if (closed_form_) {
      if (gyro_offset_ >= 0) AddGyroStage(K * E_inv_, i, 0, out);
      return;
    }
    // Columns that enter like the gyroscope's bias: the walk's b_from and b_to, weighted.
    const Mat3 K_dw_db = r_.correction_.AddRateJacobian(rates_, K, i, out);
    if (r_.wander_ > 0) {
      const double a = r_.walk_weight_[i];
      out.middleCols<3>(layout_.walk_from).noalias() += (1.0 - a) * K_dw_db;
      out.middleCols<3>(layout_.walk_from + 3).noalias() += a * K_dw_db;
    }
  }

  const Layout& layout() const { return layout_; }
  bool closed_form() const { return closed_form_; }
  /// E^-1 at theta (closed form).
  const Mat3& E_inv() const { return E_inv_; }

 private:
  /// The linear gyroscope stage's share of K d w_i / d theta, given KE = -K d w_i / d p_g (K E^-1
  /// for the base model, w = E^-1 (y_g - b_g)): the 12 columns of E and b_g from `g_col` and,
  /// with a walk, those of b_from and b_to (d w_i / d b_g weighted by 1 - a_i and a_i).
  void AddGyroStage(const Mat3& KE, std::size_t i, int g_col, strapdown::Sensitivity& out) const {
    model::gyro_linear::SubtractRateJacobian(KE, rates_.w_b[i],
                                             out.middleCols(g_col, model::gyro_linear::kSize));
    if (r_.wander_ > 0) {
      const double a = r_.walk_weight_[i];
      out.middleCols<3>(layout_.walk_from).noalias() -= (1.0 - a) * KE;
      out.middleCols<3>(layout_.walk_from + 3).noalias() -= a * KE;
    }
  }

  const MotionResidual& r_;
  const CorrectedRates& rates_;
  bool closed_form_;
  Mat3 E_inv_ = Mat3::Identity();
  int gyro_offset_ = -1;  // the gyroscope's linear block among the P (closed form)
  Layout layout_;
};

bool MotionResidual::LinearAt(double const* const* theta, double** jacobians) const {
  if (!model_->AtLinearStage(theta)) return false;
  for (int t = 0; jacobians != nullptr && t < model_->num_terms(); ++t) {
    const auto& info = model_->terms()[static_cast<std::size_t>(t)].effect->info();
    if (!info.linear_stage && jacobians[2 + t] != nullptr) return false;
  }
  return true;
}

bool MotionResidual::EvaluateUncached(double const* const* parameters, double* residuals,
                                      double** jacobians) const {
  const Quat q_k(parameters[0][3], parameters[0][0], parameters[0][1], parameters[0][2]);
  const Quat q_k1(parameters[1][3], parameters[1][0], parameters[1][1], parameters[1][2]);
  const Mat3 R_k = q_k.normalized().toRotationMatrix();
  const Mat3 R_k1 = q_k1.normalized().toRotationMatrix();
  double const* const* theta = parameters + 2;
  const bool want_jacobians = jacobians != nullptr;

  // The outputs with the bias walk taken off (the samples themselves without a walk).
  std::vector<Vec3> walked;
  if (wander_ > 0) walked = WalkedOutputs(parameters);
  const std::vector<Vec3>& gyr = wander_ > 0 ? walked : s_.gyr;
  // For the base model d w / d theta has a closed form used on the fly (no per-sample
  // storage). It also holds when every other effect is at zero and its Jacobian is not asked
  // for (e.g. diagnose's probes).
  const bool closed_form = LinearAt(theta, jacobians);
  const CorrectedRates rates =
      correction_.Correct(theta, s_, gyr, {closed_form, want_jacobians && !closed_form});
  const bool earth = omega_ie_n_.squaredNorm() > 0.0;  // without a site: e = 0
  const Vec3 omega_b0 = earth ? Vec3(R_k.transpose() * omega_ie_n_) : Vec3::Zero();
  if (!want_jacobians) {
    const Mat3 M = strapdown::IntegratedRotation(s_.dt_s, rates.w_b, omega_b0).transpose() *
                   R_k.transpose();
    const Vec3 r = so3::Log(M * R_k1);
    for (int k = 0; k < 3; ++k) residuals[k] = s_.sqrt_info[k] * r[k];
    return true;
  }
  const RateColumns columns(*this, theta, rates, closed_form);
  Propagated p = earth ? PropagateInBodyFrame(columns, rates.w_b, omega_b0, R_k)
                       : PropagateInStartFrame(columns, rates.w_b);
  const Mat3 M = p.dR.transpose() * R_k.transpose();
  const Vec3 r = so3::Log(M * R_k1);
  for (int k = 0; k < 3; ++k) residuals[k] = s_.sqrt_info[k] * r[k];
  WriteJacobians(r, M, p.dR_H_x, columns.layout(), q_k, q_k1, jacobians);
  return true;
}

MotionResidual::Propagated MotionResidual::PropagateInBodyFrame(const RateColumns& columns,
                                                                const std::vector<Vec3>& w,
                                                                const Vec3& omega_b0,
                                                                const Mat3& R_k) const {
  const Layout& layout = columns.layout();
  strapdown::Propagation propagation(omega_b0, R_k.transpose() * so3::Skew(omega_ie_n_),
                                     layout.columns, layout.start_attitude, false);
  auto no_force = [](std::size_t, strapdown::Sensitivity&) {};
  for (std::size_t i = 0; i + 1 < s_.size(); ++i) {
    propagation.Advance(i, s_.dt_s[i + 1] - s_.dt_s[i], w[i], w[i + 1], Vec3::Zero(), columns,
                        no_force);
  }
  return {propagation.dR(), propagation.dR_H_x()};
}

MotionResidual::Propagated MotionResidual::PropagateInStartFrame(const RateColumns& columns,
                                                                 const std::vector<Vec3>& w) const {
  const Layout& layout = columns.layout();
  strapdown::Sensitivity A = strapdown::Sensitivity::Zero(3, layout.columns);
  if (!columns.closed_form()) {
    const Mat3 dR = strapdown::PropagateInStartFrame(
        s_.dt_s, w, [&](const Mat3& G, std::size_t i) { columns(G, i, A); });
    return {dR, dR.transpose() * A};
  }
  // The closed form: the sums of G_i alone, times E^-1 once.
  GyroStageSums sums;
  const bool walk = wander_ > 0;
  const Mat3 dR = strapdown::PropagateInStartFrame(s_.dt_s, w, [&](const Mat3& G, std::size_t i) {
    sums.Add(G, w[i], walk ? walk_weight_[i] : 0.0);
  });
  if (layout.rate_columns > 0) sums.SubtractFrom(columns.E_inv(), walk ? layout.walk_from : -1, A);
  return {dR, dR.transpose() * A};
}

std::pair<Mat3, int> MotionResidual::ClosedFormGyro(double const* const* theta) const {
  const int g = model_->BaseTerm(model::Sensor::kGyro);
  if (g < 0) return {Mat3::Identity(), -1};
  return {model_->Predict(theta, model::SensorInput<double>()).E.inverse(),
          columns().Offset(g)};
}

std::vector<Vec3> MotionResidual::WalkedOutputs(double const* const* parameters) const {
  Vec3 b_from = Vec3::Zero(), b_to = Vec3::Zero();
  for (int p = 0; p < wander_; ++p) {
    b_from += Eigen::Map<const Vec3>(parameters[2 + model_->num_terms() + 2 * p]);
    b_to += Eigen::Map<const Vec3>(parameters[3 + model_->num_terms() + 2 * p]);
  }
  std::vector<Vec3> walked(s_.size());
  for (std::size_t i = 0; i < s_.size(); ++i) {
    const double a = walk_weight_[i];
    walked[i] = s_.gyr[i] - ((1.0 - a) * b_from + a * b_to);
  }
  return walked;
}

void MotionResidual::WriteJacobians(const Vec3& r, const Mat3& M, const strapdown::Sensitivity& A,
                                    const Layout& layout, const Quat& q_k, const Quat& q_k1,
                                    double** jacobians) const {
  const int P = columns().parameters;
  const int att = layout.start_attitude;
  const int from = layout.walk_from;
  const Mat3 Jli = so3::LeftJacobianInverse(r);
  const Eigen::DiagonalMatrix<double, 3> Wsi(s_.sqrt_info);
  // Tangent Jacobians (left perturbations in NED for the attitudes), then ambient ones
  // J_amb = J_tan 4 P^T, which satisfy J_amb P = J_tan since P^T P = I / 4.
  const Mat3 J_k = Wsi * (-Jli * (M + A.middleCols<3>(att)));
  const Mat3 J_k1 = Wsi * (Jli * M);
  auto ambient = [](const Mat3& J_tan, const Quat& q, double* out) {
    const Eigen::Matrix<double, 3, 4> J = J_tan * 4.0 * LeftPlusJacobian(q).transpose();
    Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> J_out(out);
    J_out = J;
  };
  if (jacobians[0]) ambient(J_k, q_k, jacobians[0]);
  if (jacobians[1]) ambient(J_k1, q_k1, jacobians[1]);
  Eigen::Matrix<double, 3, Eigen::Dynamic> J_theta = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, P);
  J_theta.middleCols(layout.rate_first, layout.rate_columns) =
      Wsi * (-Jli * A.leftCols(layout.rate_columns));
  for (int t = 0; t < model_->num_terms(); ++t) {
    double* out = jacobians[t + 2];
    if (!out) continue;
    const int size = model_->terms()[static_cast<std::size_t>(t)].effect->info().size();
    Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> J_out(out, 3, size);
    J_out = J_theta.middleCols(columns().Offset(t), size);
  }
  for (int b = 0; b < 2 * wander_; ++b) {
    double* out = jacobians[2 + model_->num_terms() + b];
    if (!out) continue;
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> J_out(out);
    J_out = Wsi * (-Jli * A.middleCols<3>(from + 3 * (b % 2)));
  }
}

Quat MotionResidual::Integrate(const double* q_k, const model::ParameterBlocks& theta) const {
  // Residual with R_k+1 = R_k: r = Log(dR^T), so dR = Exp(-r).
  std::vector<const double*> p = {q_k, q_k};
  for (const auto& b : theta) p.push_back(b.data());
  const double zero[3] = {0.0, 0.0, 0.0};
  for (int b = 0; b < 2 * wander_; ++b) p.push_back(zero);
  double r[3];
  Evaluate(p.data(), r, nullptr);
  const Vec3 rv = Vec3(r[0], r[1], r[2]).cwiseQuotient(s_.sqrt_info);
  return Quat(so3::Exp(-rv));
}

}  // namespace plumb::residuals
