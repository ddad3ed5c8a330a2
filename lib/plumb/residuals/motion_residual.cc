#include "plumb/residuals/motion_residual.h"

#include <ceres/dynamic_autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/LU>

namespace plumb::residuals {
namespace {

/// dq/dt = 0.5 q (x) (0, w)
template <typename T>
Eigen::Quaternion<T> Derivative(const Eigen::Quaternion<T>& q, const Vec3T<T>& w) {
  const Eigen::Quaternion<T> wq(T(0), w.x(), w.y(), w.z());
  Eigen::Quaternion<T> d = q * wq;
  d.coeffs() *= T(0.5);
  return d;
}

template <typename T>
Eigen::Quaternion<T> AddScaled(const Eigen::Quaternion<T>& q, const Eigen::Quaternion<T>& d,
                               double h) {
  Eigen::Quaternion<T> out;
  out.coeffs() = q.coeffs() + d.coeffs() * T(h);
  return out;
}

}  // namespace

MotionResidual::MotionResidual(const model::Model& model, MotionSamples samples,
                               const Vec3& omega_ie_n)
    : model_(&model), s_(std::move(samples)), omega_ie_n_(omega_ie_n) {
  bool linear_only = true;
  for (const auto& t : model.terms()) linear_only = linear_only && t.effect->info().linear_stage;
  newton_iterations_ = linear_only ? 1 : 3;
}

template <typename T>
Eigen::Quaternion<T> MotionResidual::IntegrateT(T const* const* parameters) const {
  const Eigen::Map<const Eigen::Quaternion<T>> q_k(parameters[0]);
  T const* const* theta = parameters + 2;
  // The linear part, for the Newton steps of the inverse model.
  const model::SensorOutput<T> at_zero = model_->Predict(theta, model::SensorInput<T>());
  const Mat3T<T> F_inv = at_zero.F.inverse();
  const Mat3T<T> E_inv = at_zero.E.inverse();
  const Vec3T<T> omega_ie_k = q_k.conjugate() * omega_ie_n_.cast<T>();  // Earth rate in b_k

  auto corrected_rate = [&](std::size_t i) {
    model::SensorInput<T> in;
    in.alpha_b = s_.alpha_b[i].cast<T>();
    in.dt_s = T(s_.dt_s[i]);
    in.dtemp_c = T(s_.dtemp_c[i]);
    const Vec3T<T> y_a = s_.acc[i].cast<T>();
    const Vec3T<T> y_g = s_.gyr[i].cast<T>();
    for (int it = 0; it < newton_iterations_; ++it) {
      const model::SensorOutput<T> out = model_->Predict(theta, in);
      in.f_b += F_inv * (y_a - out.acc);
      in.omega_b += E_inv * (y_g - out.gyr);
    }
    return Vec3T<T>(in.omega_b);
  };

  Eigen::Quaternion<T> dq(T(1), T(0), T(0), T(0));
  Vec3T<T> w0 = corrected_rate(0);
  for (std::size_t i = 0; i + 1 < s_.size(); ++i) {
    const double h = s_.dt_s[i + 1] - s_.dt_s[i];
    const Vec3T<T> w1 = corrected_rate(i + 1);
    // Earth rate seen in the current body frame, removed from the measured rate.
    const Vec3T<T> earth_b = dq.conjugate() * omega_ie_k;
    const Vec3T<T> a = w0 - earth_b;
    const Vec3T<T> b = w1 - earth_b;
    const Vec3T<T> m = (a + b) * T(0.5);
    const auto k1 = Derivative(dq, a);
    const auto k2 = Derivative(AddScaled(dq, k1, 0.5 * h), m);
    const auto k3 = Derivative(AddScaled(dq, k2, 0.5 * h), m);
    const auto k4 = Derivative(AddScaled(dq, k3, h), b);
    dq.coeffs() += (k1.coeffs() + T(2) * k2.coeffs() + T(2) * k3.coeffs() + k4.coeffs()) *
                   T(h / 6.0);
    dq.normalize();
    w0 = w1;
  }
  return dq;
}

template <typename T>
bool MotionResidual::operator()(T const* const* parameters, T* residuals) const {
  const Eigen::Map<const Eigen::Quaternion<T>> q_k(parameters[0]);
  const Eigen::Map<const Eigen::Quaternion<T>> q_k1(parameters[1]);
  const Eigen::Quaternion<T> dq = IntegrateT(parameters);
  Eigen::Quaternion<T> err = (q_k * dq).conjugate() * q_k1;
  if (err.w() < T(0)) err.coeffs() = -err.coeffs();
  const T wxyz[4] = {err.w(), err.x(), err.y(), err.z()};
  T angle_axis[3];
  ceres::QuaternionToAngleAxis(wxyz, angle_axis);
  for (int i = 0; i < 3; ++i) residuals[i] = angle_axis[i] * T(s_.sqrt_info[i]);
  return true;
}

Quat MotionResidual::Integrate(const double* q_k, const model::ParameterBlocks& theta) const {
  std::vector<const double*> p = {q_k, q_k};
  for (const auto& b : theta) p.push_back(b.data());
  return IntegrateT<double>(p.data());
}

ceres::CostFunction* MotionResidual::Create(const model::Model& model, MotionSamples samples,
                                            const Vec3& omega_ie_n) {
  auto* cost = new ceres::DynamicAutoDiffCostFunction<MotionResidual, model::kJetStride>(
      new MotionResidual(model, std::move(samples), omega_ie_n));
  cost->AddParameterBlock(4);
  cost->AddParameterBlock(4);
  for (const auto& t : model.terms()) cost->AddParameterBlock(t.effect->info().size());
  cost->SetNumResiduals(3);
  return cost;
}

template bool MotionResidual::operator()<double>(double const* const*, double*) const;
template bool MotionResidual::operator()<model::Jet>(model::Jet const* const*,
                                                      model::Jet*) const;

}  // namespace plumb::residuals
