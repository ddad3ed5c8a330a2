// plumb/residuals/strapdown.h — the strapdown propagation of attitude and velocity over one
// interval of samples, with its Jacobians: the core the motion and velocity residuals use (and
// the flight residuals will).
//
// Inputs, per sample i of the interval: the time t_i (s), the corrected angular rate w_i (rad/s,
// body frame) and, for the velocity, the corrected specific force f_i (m/s^2, body frame), both
// from the error model's inverse (model::Model::Correct); and the Earth rate in the body frame of
// the interval's start, omega_b0 = R_n_b0^T omega_ie_n (rad/s; zero without a site). Outputs:
//
//   e_i     = dR_i^T omega_b0                    Earth rate at step i's start, held over the step
//   phi_i   = (h/2) (u_i + u_i+1) + (h^2/12) u_i x u_i+1,   u = w - e_i,   h = t_i+1 - t_i
//   dR_i+1  = dR_i Exp(phi_i),  dR_0 = I          attitude change R_b0_bi (coning-corrected,
//                                                 third order in h like RK4 on SO(3))
//   dv      = sum_i (h/2) (dR_i f_i + dR_i+1 f_i+1)   velocity change from the specific force,
//                                                 m/s, body frame of the start (no gravity)
//
// Jacobians. The unknowns x have a layout the caller owns (the model's parameters, the bias
// wander's ends, the start attitude's left perturbation in NED): `columns` of them, the start
// attitude's three from `start_attitude` (-1: not an unknown). The caller gives each sample's
// input Jacobians through two functors, so that a closed form (the linear stage) or stored
// columns (implicit differentiation of a general model) serve alike:
//
//   add_rate_H_x(K, i, out)   out += K w_i_H_x   (K 3 x 3, out 3 x columns)
//   force_H_x(i, out)         out  = f_i_H_x
//
// dR_H_x is the right perturbation of dR with respect to x (dR(x + dx) = dR Exp(dR_H_x dx)), as
// in IMU preintegration: with C_0 = h/2 I - h^2/12 [u_i+1]x, C_1 = h/2 I + h^2/12 [u_i]x and
// phi_H_u = J_r(phi) C (K_0 = J_r C_0, K_1 = J_r C_1, K = K_0 + K_1):
//
//   dR_H_x' = (Exp(phi)^T - K [e]x) dR_H_x + K_0 w_i_H_x + K_1 w_i+1_H_x
//             - K dR_i^T omega_b0_H_startAttitude           (start attitude's columns)
//   dRf_H_x_i = dR_i (f_i_H_x - [f_i]x dR_H_x_i)           d(dR_i f_i)/dx
//   dv_H_x  = sum_i (h/2) (dRf_H_x_i + dRf_H_x_i+1)
//
// Without Earth rate dR_H_x may instead be carried in the start frame (PropagateInStartFrame):
// dR dR_H_x = sum_i G_i w_i_H_x with G_i = dR_i+1 K_0 (step i) + dR_i K_1 (step i-1), so each
// sample's rate Jacobian enters once, and a closed form may sum G_i alone.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "plumb/core/so3.h"
#include "plumb/core/types.h"

namespace plumb::residuals::strapdown {

/// Sensitivities of a 3-vector to the unknowns: 3 x columns.
using Sensitivity = Eigen::Matrix<double, 3, Eigen::Dynamic>;

/// One step's rotation vector phi, Exp(phi) and J_r(phi), and phi's Jacobians with respect to
/// the rates at the step's two ends: phi_H_u = J_r(phi) C (the file comment's K_0 and K_1).
struct Step {
  Step(double h, const Vec3& u0, const Vec3& u1)
      : u0(u0), u1(u1), c0(0.5 * h), c1(h * h / 12.0), phi(so3::ConingIncrement(u0, u1, h)) {
    so3::ExpAndRightJacobian(phi, &Exp_phi, &Jr);
  }
  /// D C_0 and D C_1 for a 3 x 3 D (D = J_r: K_0 and K_1; D = dR_i+1 J_r: the start frame's
  /// weights), by columns.
  Mat3 TimesC0(const Mat3& D) const { return c0 * D - c1 * so3::TimesSkew(D, u1); }
  Mat3 TimesC1(const Mat3& D) const { return c0 * D + c1 * so3::TimesSkew(D, u0); }

  Vec3 u0, u1;     ///< the rates less the Earth rate at the step's ends, rad/s
  double c0, c1;   ///< h / 2 and h^2 / 12
  Vec3 phi;        ///< rotation vector of the step, rad
  Mat3 Exp_phi;    ///< Exp(phi)
  Mat3 Jr;         ///< J_r(phi)
};

/// The attitude change of an interval without Jacobians: the product of exponentials on unit
/// quaternions without Earth rate (no 3 x 3 matrix per step), on rotation matrices with it.
/// `t_s` and `w_b` have one entry per sample.
Mat3 IntegratedRotation(const std::vector<double>& t_s, const std::vector<Vec3>& w_b,
                        const Vec3& omega_b0);

/// The attitude and velocity change (dR, dv) of an interval without Jacobians, the corrected
/// force and rate of sample i from `sample(i)` -> std::pair(f_i, w_i), called once per sample.
template <class CorrectedSample>
std::pair<Mat3, Vec3> IntegratedChange(const std::vector<double>& t_s, const Vec3& omega_b0,
                                       CorrectedSample&& sample) {
  Mat3 dR = Mat3::Identity();
  Vec3 dv = Vec3::Zero();
  if (t_s.empty()) return {dR, dv};
  auto [f0, w0] = sample(std::size_t{0});
  for (std::size_t i = 0; i + 1 < t_s.size(); ++i) {
    const double h = t_s[i + 1] - t_s[i];
    const auto [f1, w1] = sample(i + 1);
    const Vec3 e = dR.transpose() * omega_b0;
    const Mat3 dR_next = dR * so3::Exp(so3::ConingIncrement(w0 - e, w1 - e, h));
    dv += 0.5 * h * (dR * f0 + dR_next * f1);
    dR = dR_next;
    f0 = f1;
    w0 = w1;
  }
  return {dR, dv};
}

/// The propagation in the body frame, step by step, with dR_H_x and, when `velocity`, dv and
/// dv_H_x (file comment).
class Propagation {
 public:
  /// `columns` unknowns, the start attitude's three from `start_attitude` (-1: none), whose
  /// Earth rate moves by omega_b0_H_startAttitude (R_n_b0^T [omega_ie_n]x).
  Propagation(const Vec3& omega_b0, const Mat3& omega_b0_H_startAttitude, int columns,
              int start_attitude, bool velocity)
      : omega_b0_(omega_b0), omega_b0_H_startAttitude_(omega_b0_H_startAttitude),
        start_attitude_(start_attitude), velocity_(velocity),
        dR_H_x_(Sensitivity::Zero(3, columns)), next_(3, columns) {
    if (velocity_) {
      dv_H_x_ = Sensitivity::Zero(3, columns);
      dRf_H_x_ = Sensitivity::Zero(3, columns);
      f_H_x_.resize(3, columns);
      dRf_H_x_next_.resize(3, columns);
    }
  }

  /// Sets f_0 and its Jacobian (velocity only; before the first step).
  template <class ForceH>
  void Start(const Vec3& f0, ForceH&& force_H_x) {
    f_ = f0;
    force_H_x(std::size_t{0}, dRf_H_x_);
  }

  /// Advances from sample i (rate w_i, corrected force f_i given before) to i + 1 over h s.
  template <class AddRateH, class ForceH>
  void Advance(std::size_t i, double h, const Vec3& w_i, const Vec3& w_next, const Vec3& f_next,
               AddRateH&& add_rate_H_x, ForceH&& force_H_x) {
    const Vec3 e = dR_.transpose() * omega_b0_;
    const Step step(h, w_i - e, w_next - e);
    const Mat3 dR_next = dR_ * step.Exp_phi;
    const Mat3 phi_H_u0 = step.TimesC0(step.Jr), phi_H_u1 = step.TimesC1(step.Jr);
    const Mat3 K = phi_H_u0 + phi_H_u1;
    next_.noalias() = (step.Exp_phi.transpose() - K * so3::Skew(e)) * dR_H_x_;
    if (start_attitude_ >= 0) {
      next_.middleCols<3>(start_attitude_).noalias() -=
          K * (dR_.transpose() * omega_b0_H_startAttitude_);
    }
    add_rate_H_x(phi_H_u0, i, next_);
    add_rate_H_x(phi_H_u1, i + 1, next_);
    dR_H_x_.swap(next_);
    if (velocity_) {
      dv_ += 0.5 * h * (dR_ * f_ + dR_next * f_next);
      force_H_x(i + 1, f_H_x_);
      f_H_x_.noalias() -= so3::Skew(f_next) * dR_H_x_;
      dRf_H_x_next_.noalias() = dR_next * f_H_x_;
      dv_H_x_ += 0.5 * h * (dRf_H_x_ + dRf_H_x_next_);
      dRf_H_x_.swap(dRf_H_x_next_);
      f_ = f_next;
    }
    dR_ = dR_next;
  }

  const Mat3& dR() const { return dR_; }                ///< R_b0_bi after the last step
  const Sensitivity& dR_H_x() const { return dR_H_x_; }  ///< right perturbation of dR
  const Vec3& dv() const { return dv_; }                ///< m/s, body frame of the start
  const Sensitivity& dv_H_x() const { return dv_H_x_; }

 private:
  Vec3 omega_b0_;
  Mat3 omega_b0_H_startAttitude_;
  int start_attitude_;
  bool velocity_;
  Mat3 dR_ = Mat3::Identity();
  Vec3 dv_ = Vec3::Zero();
  Vec3 f_ = Vec3::Zero();  // f_i of the step to come
  Sensitivity dR_H_x_, next_;
  // Velocity: dv_H_x, d(dR_i f_i)/dx of the step's start and end, f_i+1_H_x (preallocated:
  // no allocation per sample).
  Sensitivity dv_H_x_, dRf_H_x_, dRf_H_x_next_, f_H_x_;
};

/// dR without Earth rate, its sensitivity carried in the start frame (file comment): hands
/// each sample's weight to `add_weight(G_i, i)` once, for the caller to sum G_i w_i_H_x (then
/// dR_H_x = dR^T times that sum). Returns dR.
template <class AddWeight>
Mat3 PropagateInStartFrame(const std::vector<double>& t_s, const std::vector<Vec3>& w_b,
                           AddWeight&& add_weight) {
  Mat3 dR = Mat3::Identity();
  Mat3 G_next = Mat3::Zero();  // the share of sample i + 1 from step i
  for (std::size_t i = 0; i + 1 < t_s.size(); ++i) {
    const Step step(t_s[i + 1] - t_s[i], w_b[i], w_b[i + 1]);
    const Mat3 dR_next = dR * step.Exp_phi;
    const Mat3 D = dR_next * step.Jr;
    add_weight(Mat3(G_next + step.c0 * D - step.c1 * so3::TimesSkew(D, step.u1)), i);
    G_next = step.TimesC1(D);
    dR = dR_next;
  }
  if (t_s.size() >= 2) add_weight(G_next, t_s.size() - 1);
  return dR;
}

}  // namespace plumb::residuals::strapdown
