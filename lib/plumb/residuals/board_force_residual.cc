// plumb/residuals/board_force_residual.cc — see board_force_residual.h.
#include "plumb/residuals/board_force_residual.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
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

/// The residuals of `windows`: 3 per window with samples of IMU i.
int Rows(const std::vector<BoardWindow>& windows) {
  return 3 * static_cast<int>(std::count_if(windows.begin(), windows.end(),
                                            [](const BoardWindow& w) { return w.imu.count > 0; }));
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
  // The value at edge k from its stencil; each edge's is taken as the windows on both sides
  // of it need it, the earlier one kept.
  auto edge = [&](std::size_t k) {
    Vec3 value = Vec3::Zero();
    const std::vector<double>& weights = stencils_.weights[k];
    const Vec3* cells = x.data() + stencils_.first[k];
    for (std::size_t c = 0; c < weights.size(); ++c) value += weights[c] * cells[c];
    return value;
  };
  std::vector<Vec3> out(n);
  if (n == 0) return out;
  Vec3 before = edge(0);
  for (std::size_t w = 0; w < n; ++w) {
    const Vec3 after = edge(w + 1);
    out[w] = (after - before) / (windows[w].t_end_s - windows[w].t_begin_s);
    before = after;
  }
  return out;
}

namespace {

/// The cost function: the functor's own central differences (BoardForceResidual::
/// Differentiate), not over IMU i's gyroscope terms where both models act as their linear
/// stage (its corrected force reads only its accelerometer's terms then: those columns are
/// zero).
class BoardForceCost final : public ceres::CostFunction {
 public:
  BoardForceCost(std::unique_ptr<BoardForceResidual> functor, const model::Model& model,
                 const model::Model& model0, int accel_wander, int accel_wander0, int rows)
      : functor_(std::move(functor)), model_(&model), model0_(&model0) {
    auto add = [&](int size) { mutable_parameter_block_sizes()->push_back(size); };
    add(model::board_mount::kSize);
    for (const auto& term : model.terms()) {
      add(term.effect->info().size());
      gyro_only_.push_back(term.effect->info().sensor == model::Sensor::kGyro);
    }
    for (const auto& term : model0.terms()) add(term.effect->info().size());
    for (int p = 0; p < 2 * (accel_wander + accel_wander0); ++p) add(3);
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
    functor_->Differentiate(parameters, parameter_block_sizes(), residuals, asked.data());
    return true;
  }

 private:
  std::unique_ptr<BoardForceResidual> functor_;
  const model::Model* model_;
  const model::Model* model0_;
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
  const int rows = Rows(*windows);
  auto functor = std::make_unique<BoardForceResidual>(model, model0, std::move(windows),
                                                      accel_wander, accel_wander0);
  return new BoardForceCost(std::move(functor), model, model0, accel_wander, accel_wander0, rows);
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

BoardForceResidual::Blocks BoardForceResidual::Split(double const* const* parameters) const {
  Blocks b;
  b.mount = parameters[0];
  b.theta = parameters + 1;
  b.theta0 = b.theta + model_->num_terms();
  b.wander = b.theta0 + model0_->num_terms();
  b.wander0 = b.wander + 2 * accel_wander_;
  return b;
}

BoardForceResidual::Imu0Turn BoardForceResidual::TurnOfImu0(const Blocks& b) const {
  const std::vector<BoardWindow>& windows = *windows_;
  const std::size_t n = windows.size();
  // IMU 0: its rates (twice where its model reads their derivative) and their mean derivative
  // alpha_b.
  Imu0Turn out;
  const std::vector<Vec3> none(n, Vec3::Zero());
  std::vector<Vec3> w0;
  Correct(*model0_, b.theta0, b.wander0, accel_wander0_, true, none, out.f0, w0);
  out.alpha_b = MeanRate(w0);
  if (reads_alpha0_) {
    Correct(*model0_, b.theta0, b.wander0, accel_wander0_, true, out.alpha_b, out.f0, w0);
    out.alpha_b = MeanRate(w0);
  }
  // The turn's A_w (file comment), in the body.
  const Mat3 E0_inv = model0_->Predict(b.theta0, model::SensorInput<double>()).E.inverse();
  out.A.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const Mat3 C = E0_inv * windows[k].gyr0_spread * E0_inv.transpose();
    const Vec3& omega = w0[k];
    out.A[k] = so3::Skew(out.alpha_b[k]) + omega * omega.transpose() + C -
               (omega.squaredNorm() + C.trace()) * Mat3::Identity();
  }
  return out;
}

BoardForceResidual::ForceAtImu BoardForceResidual::AtImu(const Imu0Turn& turn,
                                                         const Blocks& b) const {
  // The specific force at IMU i's place, in the body: f_0 + A r, and its mean rate of change.
  const Eigen::Map<const Vec3> r(b.mount + model::board_mount::kLeverArm);
  ForceAtImu out;
  out.g.resize(turn.f0.size());
  for (std::size_t k = 0; k < turn.f0.size(); ++k) out.g[k] = turn.f0[k] + turn.A[k] * r;
  out.rate = MeanRate(out.g);
  return out;
}

std::vector<Vec3> BoardForceResidual::ForceOfImu(const Imu0Turn& turn, const Blocks& b) const {
  // IMU i, in its own frame.
  std::vector<Vec3> alpha_i(turn.alpha_b.size(), Vec3::Zero());
  if (reads_alpha_) {
    const Mat3 R_b_i = so3::Exp(model::board_mount::RotationVector(b.mount));
    for (std::size_t k = 0; k < alpha_i.size(); ++k) alpha_i[k] = R_b_i.transpose() * turn.alpha_b[k];
  }
  std::vector<Vec3> f, w;
  Correct(*model_, b.theta, b.wander, accel_wander_, false, alpha_i, f, w);
  return f;
}

void BoardForceResidual::Whiten(const Blocks& b, const ForceAtImu& g, const std::vector<Vec3>& f,
                                double* residuals) const {
  const std::vector<BoardWindow>& windows = *windows_;
  const Mat3 R_b_i = so3::Exp(model::board_mount::RotationVector(b.mount));
  const double dt = b.mount[model::board_mount::kTimeOffset];
  double* row = residuals;
  for (std::size_t k = 0; k < windows.size(); ++k) {
    if (windows[k].imu.count == 0) continue;
    const Vec3 e = R_b_i * f[k] - g.g[k] - (dt + windows[k].stamp_lag_s) * g.rate[k];
    Eigen::Map<Vec3> whitened(row);
    whitened = windows[k].sqrt_info * e;
    row += 3;
  }
}

bool BoardForceResidual::operator()(double const* const* parameters, double* residuals) const {
  const Blocks b = Split(parameters);
  const Imu0Turn turn = TurnOfImu0(b);
  Whiten(b, AtImu(turn, b), ForceOfImu(turn, b), residuals);
  return true;
}

void BoardForceResidual::Differentiate(double const* const* parameters,
                                       const std::vector<int32_t>& block_sizes,
                                       double* residuals, double** jacobians) const {
  // Ceres's central differences (ceres/internal/numeric_diff.h), step and quotient alike, so
  // the columns are the same bits as ceres::DynamicNumericDiffCostFunction's; only the stages
  // a block enters are computed again for its columns (IMU 0's turn for its own blocks, IMU
  // i's force for its blocks and, where its model reads alpha_b, IMU 0's and the rotation).
  const int rows = Rows(*windows_);
  std::vector<std::vector<double>> copy(block_sizes.size());
  std::vector<const double*> at(block_sizes.size());
  for (std::size_t i = 0; i < block_sizes.size(); ++i) {
    copy[i].assign(parameters[i], parameters[i] + block_sizes[i]);
    at[i] = copy[i].data();
  }
  const Blocks b = Split(at.data());
  const Imu0Turn turn = TurnOfImu0(b);
  const ForceAtImu g = AtImu(turn, b);
  const std::vector<Vec3> f = ForceOfImu(turn, b);
  Whiten(b, g, f, residuals);
  const std::size_t first_imu0 = 1 + static_cast<std::size_t>(model_->num_terms());
  const std::size_t first_wander = first_imu0 + static_cast<std::size_t>(model0_->num_terms());
  const std::size_t first_wander0 = first_wander + 2 * static_cast<std::size_t>(accel_wander_);
  Eigen::VectorXd plus(rows), minus(rows);
  for (std::size_t i = 0; i < block_sizes.size(); ++i) {
    if (jacobians[i] == nullptr) continue;
    const bool of_imu0 = (i >= first_imu0 && i < first_wander) || i >= first_wander0;
    const bool of_imu = i != 0 && !of_imu0;
    // The residuals with block i's value as `copy[i]` now holds it.
    auto evaluate = [&](Eigen::VectorXd& out) {
      if (of_imu) {
        Whiten(b, g, ForceOfImu(turn, b), out.data());
        return;
      }
      const Imu0Turn moved_turn = of_imu0 ? TurnOfImu0(b) : Imu0Turn{};
      const Imu0Turn& t = of_imu0 ? moved_turn : turn;
      Whiten(b, AtImu(t, b), reads_alpha_ ? ForceOfImu(t, b) : f, out.data());
    };
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(
        jacobians[i], rows, block_sizes[i]);
    const double min_step = std::sqrt(std::numeric_limits<double>::epsilon());
    for (int j = 0; j < block_sizes[i]; ++j) {
      double& x = copy[i][static_cast<std::size_t>(j)];
      const double x0 = x;
      const double delta = std::max(min_step, std::abs(x0) * kRelativeStep);
      x = x0 + delta;
      evaluate(plus);
      x = x0 - delta;
      evaluate(minus);
      x = x0;
      double one_over_delta = 1.0 / delta;
      one_over_delta /= 2;
      plus -= minus;
      plus *= one_over_delta;
      J.col(j) = plus;
    }
  }
}

}  // namespace plumb::residuals
