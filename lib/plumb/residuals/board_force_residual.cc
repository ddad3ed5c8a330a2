// plumb/residuals/board_force_residual.cc — see board_force_residual.h.
#include "plumb/residuals/board_force_residual.h"

#include <ceres/dynamic_numeric_diff_cost_function.h>

#include <Eigen/LU>
#include <algorithm>
#include <tuple>
#include <utility>

#include "plumb/core/so3.h"
#include "plumb/model/board_mount.h"

namespace plumb::residuals {
namespace {

/// Newton steps of the correction (model::Model::Correct) where the model does not act as its
/// linear stage: model::Model::Correct's default.
constexpr int kCorrectionSteps = 3;

/// Whether some term of `model` reads the angular acceleration (its correction then needs it).
bool ReadsAngularAcceleration(const model::Model& model) {
  for (const auto& term : model.terms()) {
    if (term.effect->info().excitation.angular_acceleration) return true;
  }
  return false;
}

/// Cells on each side of an edge whose means give its value: a quartic primitive, exact for
/// a cubic motion (the cell-average reconstruction of finite-volume schemes).
constexpr std::size_t kCellsPerEdge = 4;

}  // namespace

BoardForceResidual::EdgeStencils BoardForceResidual::Stencils(
    const std::vector<BoardWindow>& windows) {
  // The value at edge e_k is the derivative there of the polynomial through the primitive
  // P(e_j) = sum over the windows before e_j of their mean times their width, at kCellsPerEdge
  // + 1 edges around it: sum_j L_j'(e_k) P(e_j), L_j the Lagrange basis of node j; as weights on
  // the windows' means, P(e_j) = sum_{m < j} width_m x_m. The windows before j0 enter every
  // P(e_j) alike, and the L_j' sum to zero: only windows j0 .. j0 + cells - 1 have weights.
  const std::size_t n = windows.size();
  EdgeStencils out;
  if (n == 0) return out;
  const std::size_t cells = std::min(kCellsPerEdge, n);
  out.first.assign(n + 1, 0);
  out.weights.assign(n + 1, std::vector<double>(cells, 0.0));
  std::vector<double> e(n + 1);
  for (std::size_t w = 0; w < n; ++w) {
    e[w] = windows[w].t_begin_s;
    e[w + 1] = windows[w].t_end_s;
  }
  for (std::size_t k = 0; k <= n; ++k) {
    const std::size_t j0 = std::min(k > cells / 2 ? k - cells / 2 : 0, n - cells);
    out.first[k] = j0;
    for (std::size_t j = j0; j <= j0 + cells; ++j) {
      double weight = 0.0;
      if (j == k) {
        for (std::size_t m = j0; m <= j0 + cells; ++m) {
          if (m != k) weight += 1.0 / (e[k] - e[m]);
        }
      } else {
        double num = 1.0, den = 1.0;
        for (std::size_t m = j0; m <= j0 + cells; ++m) {
          if (m == j) continue;
          den *= e[j] - e[m];
          if (m != k) num *= e[k] - e[m];
        }
        weight = num / den;
      }
      for (std::size_t m = j0; m < j; ++m) out.weights[k][m - j0] += weight * (e[m + 1] - e[m]);
    }
  }
  return out;
}

std::vector<Vec3> BoardForceResidual::MeanRate(const std::vector<Vec3>& x) const {
  const std::vector<BoardWindow>& windows = *windows_;
  const std::size_t n = windows.size();
  std::vector<Vec3> edge(n + 1, Vec3::Zero());
  for (std::size_t k = 0; k <= n && n > 0; ++k) {
    const std::vector<double>& weights = stencils_.weights[k];
    for (std::size_t c = 0; c < weights.size(); ++c) edge[k] += weights[c] * x[stencils_.first[k] + c];
  }
  std::vector<Vec3> out(n);
  for (std::size_t w = 0; w < n; ++w) {
    out[w] = (edge[w + 1] - edge[w]) / (windows[w].t_end_s - windows[w].t_begin_s);
  }
  return out;
}

namespace {

/// The Jacobian columns of `blocks` that central differences need not compute: IMU i's
/// gyroscope terms where both models act as their linear stage (its corrected force reads only
/// its accelerometer's terms then).
class BoardForceCost final : public ceres::CostFunction {
 public:
  using Numeric = ceres::DynamicNumericDiffCostFunction<BoardForceResidual, ceres::CENTRAL>;
  BoardForceCost(BoardForceResidual* functor, const model::Model& model,
                 const model::Model& model0, int accel_wander, int accel_wander0, int rows)
      : functor_(functor), model_(&model), model0_(&model0),
        numeric_(std::make_unique<Numeric>(functor)) {
    auto add = [&](int size) {
      mutable_parameter_block_sizes()->push_back(size);
      numeric_->AddParameterBlock(size);
    };
    add(model::board_mount::kSize);
    for (const auto& term : model.terms()) {
      add(term.effect->info().size());
      gyro_only_.push_back(term.effect->info().sensor == model::Sensor::kGyro);
    }
    for (const auto& term : model0.terms()) add(term.effect->info().size());
    for (int p = 0; p < 2 * (accel_wander + accel_wander0); ++p) add(3);
    numeric_->SetNumResiduals(rows);
    set_num_residuals(rows);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (jacobians == nullptr) return (*functor_)(parameters, residuals);
    const int terms = model_->num_terms();
    const bool linear = model_->AtLinearStage(parameters + 1) &&
                        model0_->AtLinearStage(parameters + 1 + terms);
    std::vector<double*> asked(jacobians, jacobians + parameter_block_sizes().size());
    for (int t = 0; linear && t < terms; ++t) {
      double*& J = asked[static_cast<std::size_t>(1 + t)];
      if (J == nullptr || !gyro_only_[static_cast<std::size_t>(t)]) continue;
      std::fill_n(J, num_residuals() * parameter_block_sizes()[static_cast<std::size_t>(1 + t)], 0.0);
      J = nullptr;
    }
    return numeric_->Evaluate(parameters, residuals, asked.data());
  }

 private:
  BoardForceResidual* functor_;  // owned by numeric_
  const model::Model* model_;
  const model::Model* model0_;
  std::unique_ptr<Numeric> numeric_;
  std::vector<bool> gyro_only_;  // per term of IMU i's model
};

}  // namespace

BoardForceResidual::BoardForceResidual(const model::Model& model, const model::Model& model0,
                                       SharedBoardWindows windows, int accel_wander,
                                       int accel_wander0)
    : model_(&model), model0_(&model0), windows_(std::move(windows)),
      stencils_(Stencils(*windows_)), accel_wander_(accel_wander), accel_wander0_(accel_wander0),
      reads_alpha_(ReadsAngularAcceleration(model)),
      reads_alpha0_(ReadsAngularAcceleration(model0)) {}

ceres::CostFunction* BoardForceResidual::Create(const model::Model& model,
                                                const model::Model& model0,
                                                SharedBoardWindows windows, int accel_wander,
                                                int accel_wander0) {
  const int rows = 3 * static_cast<int>(std::count_if(
                             windows->begin(), windows->end(),
                             [](const BoardWindow& w) { return w.imu.count > 0; }));
  auto* functor =
      new BoardForceResidual(model, model0, std::move(windows), accel_wander, accel_wander0);
  return new BoardForceCost(functor, model, model0, accel_wander, accel_wander0, rows);
}

void BoardForceResidual::Correct(const model::Model& model, double const* const* theta,
                                 double const* const* wander, int processes, bool imu0,
                                 const std::vector<Vec3>& alpha, std::vector<Vec3>& f,
                                 std::vector<Vec3>& w) const {
  const auto linear = model.Predict(theta, model::SensorInput<double>());
  const Mat3 F_inv = linear.F.inverse(), E_inv = linear.E.inverse();
  // The linear stage's inverse in closed form: its outputs at zero input are the biases.
  const bool closed_form = model.AtLinearStage(theta);
  const std::vector<BoardWindow>& windows = *windows_;
  f.resize(windows.size());
  w.resize(windows.size());
  for (std::size_t k = 0; k < windows.size(); ++k) {
    const WindowMeans& m = imu0 ? windows[k].imu0 : windows[k].imu;
    if (m.count == 0) {
      f[k] = w[k] = Vec3::Zero();
      continue;
    }
    Vec3 y_a = m.acc;
    for (int p = 0; p < processes; ++p) {
      const Eigen::Map<const Vec3> from(wander[2 * p]), to(wander[2 * p + 1]);
      y_a -= from + m.line * (to - from);
    }
    if (closed_form) {
      f[k] = F_inv * (y_a - linear.acc);
      w[k] = E_inv * (m.gyr - linear.gyr);
      continue;
    }
    model::SensorInput<double> in;
    in.dt_s = m.dt_s;
    in.dtemp_c = m.dtemp_c;
    in.alpha_b = alpha[k];
    std::tie(f[k], w[k]) = model.Correct(theta, y_a, m.gyr, in, F_inv, E_inv, kCorrectionSteps);
  }
}

bool BoardForceResidual::operator()(double const* const* parameters, double* residuals) const {
  const std::vector<BoardWindow>& windows = *windows_;
  const std::size_t n = windows.size();
  const double* mount = parameters[0];
  double const* const* theta = parameters + 1;
  double const* const* theta0 = theta + model_->num_terms();
  double const* const* wander = theta0 + model0_->num_terms();
  double const* const* wander0 = wander + 2 * accel_wander_;
  // IMU 0: its rates (twice where its model reads their derivative) and their mean derivative
  // alpha_b.
  const std::vector<Vec3> none(n, Vec3::Zero());
  std::vector<Vec3> f0, w0;
  Correct(*model0_, theta0, wander0, accel_wander0_, true, none, f0, w0);
  std::vector<Vec3> alpha_b = MeanRate(w0);
  if (reads_alpha0_) {
    Correct(*model0_, theta0, wander0, accel_wander0_, true, alpha_b, f0, w0);
    alpha_b = MeanRate(w0);
  }
  // The specific force at IMU i's place, in the body: f_0 + A r, and its mean rate of change.
  const Mat3 E0_inv = model0_->Predict(theta0, model::SensorInput<double>()).E.inverse();
  const Eigen::Map<const Vec3> r(mount + model::board_mount::kLeverArm);
  std::vector<Vec3> at_imu(n);
  for (std::size_t k = 0; k < n; ++k) {
    const Mat3 C = E0_inv * windows[k].gyr0_spread * E0_inv.transpose();
    const Vec3& omega = w0[k];
    const Mat3 A = so3::Skew(alpha_b[k]) + omega * omega.transpose() + C -
                   (omega.squaredNorm() + C.trace()) * Mat3::Identity();
    at_imu[k] = f0[k] + A * r;
  }
  const std::vector<Vec3> rate = MeanRate(at_imu);
  // IMU i, in its own frame.
  const Mat3 R_b_i = so3::Exp(model::board_mount::RotationVector(mount));
  std::vector<Vec3> alpha_i = none;
  if (reads_alpha_) {
    for (std::size_t k = 0; k < n; ++k) alpha_i[k] = R_b_i.transpose() * alpha_b[k];
  }
  std::vector<Vec3> f, w;
  Correct(*model_, theta, wander, accel_wander_, false, alpha_i, f, w);
  const double dt = mount[model::board_mount::kTimeOffset];
  double* row = residuals;
  for (std::size_t k = 0; k < n; ++k) {
    if (windows[k].imu.count == 0) continue;
    const Vec3 e = R_b_i * f[k] - at_imu[k] - (dt + windows[k].stamp_lag_s) * rate[k];
    Eigen::Map<Vec3> whitened(row);
    whitened = windows[k].sqrt_info * e;
    row += 3;
  }
  return true;
}

}  // namespace plumb::residuals
