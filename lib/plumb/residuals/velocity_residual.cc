// plumb/residuals/velocity_residual.cc — see velocity_residual.h.
#include "plumb/residuals/velocity_residual.h"

#include <ceres/dynamic_numeric_diff_cost_function.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <utility>

#include "plumb/core/so3.h"

namespace plumb::residuals {

VelocityResidual::VelocityResidual(const model::Model& model, MotionSamples samples,
                                   const Vec3& g_n, const Vec3& omega_ie_n,
                                   const Vec3& sqrt_info, int accel_wander, int gyro_wander)
    : model_(&model), s_(std::move(samples)), g_n_(g_n), omega_ie_n_(omega_ie_n),
      sqrt_info_(sqrt_info), accel_wander_(accel_wander), gyro_wander_(gyro_wander) {}

ceres::CostFunction* VelocityResidual::Create(const model::Model& model, MotionSamples samples,
                                              const Vec3& g_n, const Vec3& omega_ie_n,
                                              const Vec3& sqrt_info, int accel_wander,
                                              int gyro_wander) {
  auto* functor = new VelocityResidual(model, std::move(samples), g_n, omega_ie_n, sqrt_info,
                                       accel_wander, gyro_wander);
  auto* cost = new ceres::DynamicNumericDiffCostFunction<VelocityResidual, ceres::CENTRAL>(functor);
  cost->AddParameterBlock(4);
  for (const auto& t : model.terms()) cost->AddParameterBlock(t.effect->info().size());
  for (int p = 0; p < 2 * (accel_wander + gyro_wander); ++p) cost->AddParameterBlock(3);
  cost->SetNumResiduals(3);
  return cost;
}

namespace {

/// The sum over `count` processes of the (b_from, b_to) block pairs starting at `blocks`.
std::pair<Vec3, Vec3> WanderEnds(double const* const* blocks, int count) {
  Vec3 from = Vec3::Zero(), to = Vec3::Zero();
  for (int p = 0; p < count; ++p) {
    from += Eigen::Map<const Vec3>(blocks[2 * p]);
    to += Eigen::Map<const Vec3>(blocks[2 * p + 1]);
  }
  return {from, to};
}

}  // namespace

Vec3 VelocityResidual::VelocityChange(double const* const* parameters) const {
  const Quat q_k(parameters[0][3], parameters[0][0], parameters[0][1], parameters[0][2]);
  const Mat3 R_b_n = q_k.normalized().toRotationMatrix().transpose();
  double const* const* theta = parameters + 1;
  const model::SensorOutput<double> linear = model_->Predict(theta, model::SensorInput<double>());
  const Mat3 F_inv = linear.F.inverse();
  const Mat3 E_inv = linear.E.inverse();
  const std::size_t n = s_.size();
  // Every effect other than the linear stage at zero (the base model, or diagnose's probes
  // away from the one being differentiated): the closed-form inverse.
  bool closed_form = true;
  for (int t = 0; t < model_->num_terms() && closed_form; ++t) {
    const auto& info = model_->terms()[static_cast<std::size_t>(t)].effect->info();
    if (info.linear_stage) continue;
    for (int j = 0; j < info.size(); ++j) closed_form = closed_form && theta[t][j] == 0.0;
  }
  const Vec3 b_a = linear.acc, b_g = linear.gyr;  // the outputs at zero input: the biases
  if (n < 2) return Vec3::Zero();  // no step: no velocity change
  // The wander along its line over the motion (file comment), per sensor.
  double const* const* wander = theta + model_->num_terms();
  const auto [acc_from, acc_to] = WanderEnds(wander, accel_wander_);
  const auto [gyr_from, gyr_to] = WanderEnds(wander + 2 * accel_wander_, gyro_wander_);
  const double t0 = s_.dt_s[0], span = std::max(s_.dt_s[n - 1] - t0, 1e-12);
  // Corrected specific force and rate of sample i.
  auto correct = [&](std::size_t i) -> std::pair<Vec3, Vec3> {
    const double u = (s_.dt_s[i] - t0) / span;
    const Vec3 y_a = s_.acc[i] - (acc_from + u * (acc_to - acc_from));
    const Vec3 y_g = s_.gyr[i] - (gyr_from + u * (gyr_to - gyr_from));
    if (closed_form) return {F_inv * (y_a - b_a), E_inv * (y_g - b_g)};
    model::SensorInput<double> in;
    in.alpha_b = s_.alpha_b[i];
    in.dt_s = s_.dt_s[i];
    in.dtemp_c = s_.dtemp_c[i];
    return model_->Correct<double>(theta, y_a, y_g, in, F_inv, E_inv, 3);
  };
  const Vec3 omega_k = R_b_n * omega_ie_n_;
  Mat3 dR = Mat3::Identity();
  Vec3 dv = Vec3::Zero();
  auto [f0, w0] = correct(0);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const double h = s_.dt_s[i + 1] - s_.dt_s[i];
    const auto [f1, w1] = correct(i + 1);
    const Vec3 e = dR.transpose() * omega_k;
    const Mat3 dR_next = dR * so3::Exp(so3::ConingIncrement(w0 - e, w1 - e, h));
    dv += 0.5 * h * (dR * f0 + dR_next * f1);
    dR = dR_next;
    f0 = f1;
    w0 = w1;
  }
  const double T = s_.dt_s[n - 1] - s_.dt_s[0];
  return dv + R_b_n * g_n_ * T;
}

bool VelocityResidual::operator()(double const* const* parameters, double* residuals) const {
  const Vec3 dv = VelocityChange(parameters);
  for (int i = 0; i < 3; ++i) residuals[i] = sqrt_info_[i] * dv[i];
  return true;
}

}  // namespace plumb::residuals
