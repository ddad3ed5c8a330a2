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
#include "plumb/residuals/strapdown.h"

namespace plumb::residuals {

VelocityResidual::VelocityResidual(const model::Model& model, SharedMotionSamples samples,
                                   const Vec3& g_n, const Vec3& omega_ie_n,
                                   const Vec3& sqrt_info, int accel_wander, int gyro_wander)
    : model_(&model), samples_(std::move(samples)), s_(*samples_), g_n_(g_n), omega_ie_n_(omega_ie_n),
      sqrt_info_(sqrt_info), accel_wander_(accel_wander), gyro_wander_(gyro_wander),
      columns_(model) {}

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
    return model_->Correct(theta, y_a, y_g, in, F_inv, E_inv, 3);
  };
  const Vec3 dv = strapdown::IntegratedChange(s_.dt_s, R_b_n * omega_ie_n_, correct).second;
  const double T = s_.dt_s[n - 1] - s_.dt_s[0];
  return dv + R_b_n * g_n_ * T;
}

bool VelocityResidual::IsLinearBlock(std::size_t block) const {
  const auto t = static_cast<int>(block) - 1;  // q_k, then the model's terms, then the wander
  return t < 0 || t >= model_->num_terms() ||
         model_->terms()[static_cast<std::size_t>(t)].effect->info().linear_stage;
}

namespace {

/// Columns of the unknowns in EvaluateLinear: the model's P parameters (block by block), the
/// left perturbation of R_k, then the wander's ends: accelerometer from, to, gyroscope from, to
/// (every process of a sensor has the same columns).
struct VelocityColumns {
  explicit VelocityColumns(int P) : model(P) {}
  int model;
  int start_attitude = model, acc_from = model + 3, acc_to = model + 6;
  int gyr_from = model + 9, gyr_to = model + 12, count = model + 15;
};

/// The samples corrected by the linear stage, f = F^-1 (y_a - wander - b_a) and w = E^-1 (y_g -
/// wander - b_g), with their Jacobians in VelocityColumns: the strapdown core's add_rate_H_x
/// and force_H_x (residuals/strapdown.h).
class LinearlyCorrected {
 public:
  struct Sample {
    Vec3 f, w;  ///< m/s^2 and rad/s, body frame
    double u;   ///< fraction of the motion, the wander line's weight
  };
  /// `layout`: the model's columns (VelocityResidual's, made once).
  LinearlyCorrected(const model::Model& model, const ModelColumns& layout, const MotionSamples& s,
                    const LinearStage& stage, const WanderLine& acc_wander,
                    const WanderLine& gyr_wander)
      : model_(model), stage_(stage), layout_(layout), columns_(layout_.parameters),
        a_term_(model.BaseTerm(model::Sensor::kAccel)),
        g_term_(model.BaseTerm(model::Sensor::kGyro)) {
    const std::size_t n = s.size();
    const double t0 = n > 0 ? s.dt_s[0] : 0.0;
    const double span = n > 0 ? std::max(s.dt_s[n - 1] - t0, 1e-12) : 1.0;
    samples_.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double u = (s.dt_s[i] - t0) / span;
      samples_.push_back({stage.F_inv * (s.acc[i] - acc_wander.At(u) - stage.linear.acc),
                          stage.E_inv * (s.gyr[i] - gyr_wander.At(u) - stage.linear.gyr), u});
    }
  }
  const Sample& operator[](std::size_t i) const { return samples_[i]; }
  const VelocityColumns& columns() const { return columns_; }
  const ModelColumns& layout() const { return layout_; }

  /// out += K d w_i / d x.
  void AddRate(const Mat3& K, std::size_t i, strapdown::Sensitivity& out) const {
    if (g_term_ < 0) return;
    const Sample& x = samples_[i];
    const Mat3 KE_inv = K * stage_.E_inv;
    model::gyro_linear::SubtractRateJacobian(
        KE_inv, x.w, out.middleCols(layout_.Offset(g_term_), model::gyro_linear::kSize));
    out.middleCols<3>(columns_.gyr_from).noalias() -= (1.0 - x.u) * KE_inv;
    out.middleCols<3>(columns_.gyr_to).noalias() -= x.u * KE_inv;
  }
  /// out = d f_i / d x (3 x count, preallocated: no allocation per sample).
  void Force(std::size_t i, strapdown::Sensitivity& out) const {
    const Sample& x = samples_[i];
    out.setZero();
    if (a_term_ >= 0) {
      const int size = model_.terms()[static_cast<std::size_t>(a_term_)].effect->info().size();
      model::accel_linear::SubtractForceJacobian(stage_.F_inv, x.f,
                                                 size == model::accel_linear::kSizeFull,
                                                 out.middleCols(layout_.Offset(a_term_), size));
    }
    out.middleCols<3>(columns_.acc_from) -= (1.0 - x.u) * stage_.F_inv;
    out.middleCols<3>(columns_.acc_to) -= x.u * stage_.F_inv;
  }

 private:
  const model::Model& model_;
  const LinearStage& stage_;
  const ModelColumns& layout_;
  VelocityColumns columns_;
  int a_term_, g_term_;
  std::vector<Sample> samples_;
};

}  // namespace

void VelocityResidual::EvaluateLinear(double const* const* parameters, double* residuals,
                                      double** jacobians) const {
  const LinearStage stage(*model_, parameters);
  double const* const* wander = parameters + 1 + model_->num_terms();
  const LinearlyCorrected x(*model_, columns_, s_, stage, WanderEnds(wander, accel_wander_),
                            WanderEnds(wander + 2 * accel_wander_, gyro_wander_));
  const VelocityColumns& cols = x.columns();
  const std::size_t n = s_.size();
  strapdown::Propagation propagation(stage.R_b_n * omega_ie_n_,
                                     stage.R_b_n * so3::Skew(omega_ie_n_), cols.count,
                                     cols.start_attitude, true);
  auto add_rate_H_x = [&](const Mat3& K, std::size_t i, strapdown::Sensitivity& out) {
    x.AddRate(K, i, out);
  };
  auto force_H_x = [&](std::size_t i, strapdown::Sensitivity& out) { x.Force(i, out); };
  if (n > 0) propagation.Start(x[0].f, force_H_x);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    propagation.Advance(i, s_.dt_s[i + 1] - s_.dt_s[i], x[i].w, x[i + 1].w, x[i + 1].f,
                        add_rate_H_x, force_H_x);
  }
  // r = dv + R_k^T g_n T; d(R_k^T g_n T) / d delta_k = R_k^T [g_n]x T.
  const double T = n > 0 ? s_.dt_s[n - 1] - s_.dt_s[0] : 0.0;
  const Vec3 r = n < 2 ? Vec3::Zero() : Vec3(propagation.dv() + stage.R_b_n * g_n_ * T);
  strapdown::Sensitivity r_H_x = propagation.dv_H_x();
  if (n >= 2) r_H_x.middleCols<3>(cols.start_attitude) += stage.R_b_n * so3::Skew(g_n_) * T;
  else r_H_x.setZero();
  for (int k = 0; k < 3; ++k) residuals[k] = sqrt_info_[k] * r[k];
  const strapdown::Sensitivity J = Eigen::DiagonalMatrix<double, 3>(sqrt_info_) * r_H_x;
  if (jacobians[0] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> out(jacobians[0]);
    out = J.middleCols<3>(cols.start_attitude) * 4.0 * LeftPlusJacobian(stage.q_k).transpose();
  }
  using RowMajor = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>;
  for (int t = 0; t < model_->num_terms(); ++t) {
    if (jacobians[1 + t] == nullptr) continue;
    const int size = model_->terms()[static_cast<std::size_t>(t)].effect->info().size();
    Eigen::Map<RowMajor>(jacobians[1 + t], 3, size) = J.middleCols(x.layout().Offset(t), size);
  }
  double** wander_jacobians = jacobians + 1 + model_->num_terms();
  for (int b = 0; b < 2 * (accel_wander_ + gyro_wander_); ++b) {
    if (wander_jacobians[b] == nullptr) continue;
    const bool accel = b < 2 * accel_wander_;
    const bool to = b % 2 == 1;
    const int col = accel ? (to ? cols.acc_to : cols.acc_from) : (to ? cols.gyr_to : cols.gyr_from);
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> out(wander_jacobians[b]);
    out = J.middleCols<3>(col);
  }
}

bool VelocityResidual::operator()(double const* const* parameters, double* residuals) const {
  const Vec3 dv = VelocityChange(parameters);
  for (int i = 0; i < 3; ++i) residuals[i] = sqrt_info_[i] * dv[i];
  return true;
}

}  // namespace plumb::residuals
