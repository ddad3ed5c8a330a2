// plumb/residuals/velocity_residual.cc — see velocity_residual.h.
#include "plumb/residuals/velocity_residual.h"

#include <ceres/dynamic_numeric_diff_cost_function.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <memory>
#include <utility>

#include "plumb/core/so3.h"
#include "plumb/model/effects/accel_linear.h"
#include "plumb/model/effects/gyro_linear.h"
#include "plumb/residuals/motion_residual.h"

namespace plumb::residuals {

VelocityResidual::VelocityResidual(const model::Model& model, SharedMotionSamples samples,
                                   const Vec3& g_n, const Vec3& omega_ie_n,
                                   const Vec3& sqrt_info, int accel_wander, int gyro_wander)
    : model_(&model), samples_(std::move(samples)), s_(*samples_), g_n_(g_n), omega_ie_n_(omega_ie_n),
      sqrt_info_(sqrt_info), accel_wander_(accel_wander), gyro_wander_(gyro_wander) {}

namespace {

/// The velocity residual's cost function: analytic where the model acts as its linear stage,
/// central differences elsewhere (file comment).
class VelocityCost final : public ceres::CostFunction {
 public:
  explicit VelocityCost(std::unique_ptr<VelocityResidual> functor) : functor_(functor.get()) {
    auto numeric = std::make_unique<
        ceres::DynamicNumericDiffCostFunction<VelocityResidual, ceres::CENTRAL>>(functor.release());
    numeric->SetNumResiduals(3);
    numeric_ = std::move(numeric);
    set_num_residuals(3);
  }
  void AddParameterBlock(int size) {
    mutable_parameter_block_sizes()->push_back(size);
    static_cast<ceres::DynamicNumericDiffCostFunction<VelocityResidual, ceres::CENTRAL>*>(
        numeric_.get())->AddParameterBlock(size);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (jacobians == nullptr) return (*functor_)(parameters, residuals);
    if (!functor_->model().AtLinearStage(parameters + 1)) {
      return numeric_->Evaluate(parameters, residuals, jacobians);
    }
    // The other effects at zero: analytic columns for the rest, central differences for
    // theirs when they are asked for (diagnose's probe columns).
    const std::size_t blocks = parameter_block_sizes().size();
    std::vector<double*> linear(jacobians, jacobians + blocks);
    std::vector<double*> other(blocks, nullptr);
    bool any_other = false;
    for (std::size_t b = 0; b < blocks; ++b) {
      if (linear[b] != nullptr && !functor_->IsLinearBlock(b)) {
        std::swap(linear[b], other[b]);
        any_other = true;
      }
    }
    functor_->EvaluateLinear(parameters, residuals, linear.data());
    double unused[3];
    return !any_other || numeric_->Evaluate(parameters, unused, other.data());
  }

 private:
  const VelocityResidual* functor_;             // owned by numeric_
  std::unique_ptr<ceres::CostFunction> numeric_;
};

}  // namespace

ceres::CostFunction* VelocityResidual::Create(const model::Model& model, SharedMotionSamples samples,
                                              const Vec3& g_n, const Vec3& omega_ie_n,
                                              const Vec3& sqrt_info, int accel_wander,
                                              int gyro_wander) {
  auto cost = std::make_unique<VelocityCost>(std::make_unique<VelocityResidual>(
      model, std::move(samples), g_n, omega_ie_n, sqrt_info, accel_wander, gyro_wander));
  cost->AddParameterBlock(4);
  for (const auto& t : model.terms()) cost->AddParameterBlock(t.effect->info().size());
  for (int p = 0; p < 2 * (accel_wander + gyro_wander); ++p) cost->AddParameterBlock(3);
  return cost.release();
}

namespace {

/// What both evaluations read from the parameters: the attitude of segment k (q_k, its
/// R_b_n), the model's outputs at zero input (F, E and the biases) and F^-1, E^-1.
struct LinearStage {
  LinearStage(const model::Model& model, double const* const* parameters)
      : q_k(Quat(parameters[0][3], parameters[0][0], parameters[0][1], parameters[0][2]).normalized()),
        R_b_n(q_k.toRotationMatrix().transpose()),
        linear(model.Predict(parameters + 1, model::SensorInput<double>())),
        F_inv(linear.F.inverse()),
        E_inv(linear.E.inverse()) {}
  Quat q_k;
  Mat3 R_b_n;
  model::SensorOutput<double> linear;
  Mat3 F_inv, E_inv;
};

/// A sensor's bias wander over the motion: the line from its value at the motion's start to
/// its value at the end (the file comment), in output units.
struct WanderLine {
  Vec3 from = Vec3::Zero(), to = Vec3::Zero();
  /// The wander at fraction `u` of the motion, u in [0, 1].
  Vec3 At(double u) const { return from + u * (to - from); }
};

/// The sum over `count` processes of the (b_from, b_to) block pairs starting at `blocks`.
WanderLine WanderEnds(double const* const* blocks, int count) {
  WanderLine line;
  for (int p = 0; p < count; ++p) {
    line.from += Eigen::Map<const Vec3>(blocks[2 * p]);
    line.to += Eigen::Map<const Vec3>(blocks[2 * p + 1]);
  }
  return line;
}

}  // namespace

Vec3 VelocityResidual::VelocityChange(double const* const* parameters) const {
  const LinearStage stage(*model_, parameters);
  const Mat3& R_b_n = stage.R_b_n;
  double const* const* theta = parameters + 1;
  const model::SensorOutput<double>& linear = stage.linear;
  const Mat3& F_inv = stage.F_inv;
  const Mat3& E_inv = stage.E_inv;
  const std::size_t n = s_.size();
  // Every effect other than the linear stage at zero (the base model, or diagnose's probes
  // away from the one being differentiated): the closed-form inverse.
  const bool closed_form = model_->AtLinearStage(theta);
  const Vec3 b_a = linear.acc, b_g = linear.gyr;  // the outputs at zero input: the biases
  if (n < 2) return Vec3::Zero();  // no step: no velocity change
  // The wander along its line over the motion (file comment), per sensor.
  double const* const* wander = theta + model_->num_terms();
  const WanderLine acc_wander = WanderEnds(wander, accel_wander_);
  const WanderLine gyr_wander = WanderEnds(wander + 2 * accel_wander_, gyro_wander_);
  const double t0 = s_.dt_s[0], span = std::max(s_.dt_s[n - 1] - t0, 1e-12);
  // Corrected specific force and rate of sample i.
  auto correct = [&](std::size_t i) -> std::pair<Vec3, Vec3> {
    const double u = (s_.dt_s[i] - t0) / span;
    const Vec3 y_a = s_.acc[i] - acc_wander.At(u);
    const Vec3 y_g = s_.gyr[i] - gyr_wander.At(u);
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

bool VelocityResidual::IsLinearBlock(std::size_t block) const {
  const auto t = static_cast<int>(block) - 1;  // q_k, then the model's terms, then the wander
  return t < 0 || t >= model_->num_terms() ||
         model_->terms()[static_cast<std::size_t>(t)].effect->info().linear_stage;
}

void VelocityResidual::EvaluateLinear(double const* const* parameters, double* residuals,
                                      double** jacobians) const {
  const LinearStage stage(*model_, parameters);
  const Quat& q_k = stage.q_k;
  const Mat3& R_b_n = stage.R_b_n;
  double const* const* theta = parameters + 1;
  const Mat3& F_inv = stage.F_inv;
  const Mat3& E_inv = stage.E_inv;
  const Vec3 b_a = stage.linear.acc, b_g = stage.linear.gyr;
  const std::size_t n = s_.size();
  // Columns of the unknowns: the model's P parameters (block by block), the left perturbation
  // of R_k, then the wander's ends: accelerometer from, to, gyroscope from, to (every process
  // of a sensor has the same columns).
  std::vector<int> offset;
  int P = 0;
  for (const auto& t : model_->terms()) {
    offset.push_back(P);
    P += t.effect->info().size();
  }
  const int att = P, acc_from = P + 3, acc_to = P + 6, gyr_from = P + 9, gyr_to = P + 12;
  const int U = P + 15;
  const int a_term = model_->BaseTerm(model::Sensor::kAccel);
  const int g_term = model_->BaseTerm(model::Sensor::kGyro);
  double const* const* wander = theta + model_->num_terms();
  const WanderLine acc_wander = WanderEnds(wander, accel_wander_);
  const WanderLine gyr_wander = WanderEnds(wander + 2 * accel_wander_, gyro_wander_);
  const double t0 = n > 0 ? s_.dt_s[0] : 0.0;
  const double span = n > 0 ? std::max(s_.dt_s[n - 1] - t0, 1e-12) : 1.0;
  struct Sample {
    Vec3 f, w;
    double u;
  };
  auto correct = [&](std::size_t i) {
    const double u = (s_.dt_s[i] - t0) / span;
    return Sample{F_inv * (s_.acc[i] - acc_wander.At(u) - b_a),
                  E_inv * (s_.gyr[i] - gyr_wander.At(u) - b_g), u};
  };
  using Cols = Eigen::Matrix<double, 3, Eigen::Dynamic>;
  // Adds K d w / dx (rate) or K d f / dx (force) of sample `x` to `out`.
  auto add_rate = [&](const Mat3& K, const Sample& x, Cols& out) {
    if (g_term < 0) return;
    const Mat3 KE_inv = K * E_inv;
    model::gyro_linear::SubtractRateJacobian(
        KE_inv, x.w, out.middleCols(offset[static_cast<std::size_t>(g_term)], model::gyro_linear::kSize));
    out.middleCols<3>(gyr_from).noalias() -= (1.0 - x.u) * KE_inv;
    out.middleCols<3>(gyr_to).noalias() -= x.u * KE_inv;
  };
  // Writes K d f / dx of sample `x` to `out` (3 x U, preallocated: no allocation per sample).
  auto force_jacobian = [&](const Sample& x, Cols& out) {
    out.setZero();
    if (a_term >= 0) {
      const int size = model_->terms()[static_cast<std::size_t>(a_term)].effect->info().size();
      model::accel_linear::SubtractForceJacobian(
          F_inv, x.f, size == model::accel_linear::kSizeFull,
          out.middleCols(offset[static_cast<std::size_t>(a_term)], size));
    }
    out.middleCols<3>(acc_from) -= (1.0 - x.u) * F_inv;
    out.middleCols<3>(acc_to) -= x.u * F_inv;
  };

  const Vec3 omega_k = R_b_n * omega_ie_n_;
  const Mat3 d_omega_k = R_b_n * so3::Skew(omega_ie_n_);  // d omega_k / d delta_k
  Mat3 dR = Mat3::Identity();
  Vec3 dv = Vec3::Zero();
  // A: d(right perturbation of dR_i)/dx; D: d(dR_i f_i)/dx; B: d(dv)/dx (file comment).
  Cols A = Cols::Zero(3, U), A_next(3, U), B = Cols::Zero(3, U);
  Sample x0 = n > 0 ? correct(0) : Sample{Vec3::Zero(), Vec3::Zero(), 0.0};
  Cols D0 = Cols::Zero(3, U), D1(3, U), dR_D1(3, U);
  if (n > 0) force_jacobian(x0, D0);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const double h = s_.dt_s[i + 1] - s_.dt_s[i];
    const Sample x1 = correct(i + 1);
    const Vec3 e = dR.transpose() * omega_k;
    const Vec3 u0 = x0.w - e, u1 = x1.w - e;
    const Vec3 phi = so3::ConingIncrement(u0, u1, h);
    const Mat3 Ex = so3::Exp(phi);
    const Mat3 dR_next = dR * Ex;
    dv += 0.5 * h * (dR * x0.f + dR_next * x1.f);
    const Mat3 Jr = so3::RightJacobian(phi);
    const Mat3 K0 = Jr * (0.5 * h * Mat3::Identity() - (h * h / 12.0) * so3::Skew(u1));
    const Mat3 K1 = Jr * (0.5 * h * Mat3::Identity() + (h * h / 12.0) * so3::Skew(u0));
    const Mat3 K = K0 + K1;
    A_next.noalias() = (Ex.transpose() - K * so3::Skew(e)) * A;
    add_rate(K0, x0, A_next);
    add_rate(K1, x1, A_next);
    A_next.middleCols<3>(att).noalias() -= K * (dR.transpose() * d_omega_k);
    force_jacobian(x1, D1);
    D1.noalias() -= so3::Skew(x1.f) * A_next;
    dR_D1.noalias() = dR_next * D1;
    B += 0.5 * h * (D0 + dR_D1);
    D0.swap(dR_D1);
    A.swap(A_next);
    dR = dR_next;
    x0 = x1;
  }
  const double T = n > 0 ? s_.dt_s[n - 1] - s_.dt_s[0] : 0.0;
  const Vec3 r = n < 2 ? Vec3::Zero() : Vec3(dv + R_b_n * g_n_ * T);
  if (n >= 2) B.middleCols<3>(att) += R_b_n * so3::Skew(g_n_) * T;
  else B.setZero();
  const Eigen::DiagonalMatrix<double, 3> W(sqrt_info_);
  for (int k = 0; k < 3; ++k) residuals[k] = sqrt_info_[k] * r[k];
  const Cols J = W * B;
  using RowMajor = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>;
  if (jacobians[0] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> out(jacobians[0]);
    out = J.middleCols<3>(att) * 4.0 * LeftPlusJacobian(q_k).transpose();
  }
  for (int t = 0; t < model_->num_terms(); ++t) {
    if (jacobians[1 + t] == nullptr) continue;
    const int size = model_->terms()[static_cast<std::size_t>(t)].effect->info().size();
    Eigen::Map<RowMajor>(jacobians[1 + t], 3, size) = J.middleCols(offset[static_cast<std::size_t>(t)], size);
  }
  const int first_wander = 1 + model_->num_terms();
  for (int b = 0; b < 2 * (accel_wander_ + gyro_wander_); ++b) {
    double* out = jacobians[first_wander + b];
    if (out == nullptr) continue;
    const bool accel = b < 2 * accel_wander_;
    const bool to = b % 2 == 1;
    const int col = accel ? (to ? acc_to : acc_from) : (to ? gyr_to : gyr_from);
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> J_out(out);
    J_out = J.middleCols<3>(col);
  }
}

bool VelocityResidual::operator()(double const* const* parameters, double* residuals) const {
  const Vec3 dv = VelocityChange(parameters);
  for (int i = 0; i < 3; ++i) residuals[i] = sqrt_info_[i] * dv[i];
  return true;
}

}  // namespace plumb::residuals
