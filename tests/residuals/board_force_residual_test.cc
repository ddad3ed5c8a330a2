// The comparison of another IMU's accelerometer with IMU 0's in a turn (residuals/
// board_force_residual.h): on a board turned smoothly, with ideal sensors sampled at 1 kHz, the
// residual vanishes at the true lever arm and time offset and nowhere else, and its Jacobian
// predicts the change of the residual (which is linear in both).
#include "plumb/residuals/board_force_residual.h"

#include <ceres/dynamic_numeric_diff_cost_function.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "plumb/core/so3.h"
#include "plumb/model/board_mount.h"

namespace plumb::residuals {
namespace {

constexpr double kRate_hz = 1000.0;
constexpr double kWindow_s = 0.05;
constexpr double kTurn_s = 2.0;

/// The body's motion: a rate that swings about a tilted axis, its derivative, and a specific
/// force that changes smoothly (gravity seen turning, and a hand's push).
Vec3 Omega(double t) { return Vec3(0.4, -0.3, 1.0).normalized() * 2.0 * std::sin(1.5 * t); }
Vec3 Alpha(double t) { return Vec3(0.4, -0.3, 1.0).normalized() * 3.0 * std::cos(1.5 * t); }
Vec3 Force(double t) { return Vec3(3.0 * std::sin(t), -2.0 * std::cos(0.7 * t), -9.8 + 0.5 * t); }

/// What the board's IMUs output: IMU 0 at the body's origin and frame, IMU i at R_b_i, lever
/// arm r and time offset dt (ideal sensors, model "base" at zero), in windows as
/// estimation/board_turns.h cuts them.
struct Board {
  Vec3 rho = Vec3(0.01, -0.02, 0.015);
  Vec3 r = Vec3(0.03, -0.02, 0.045);
  double dt = 0.002;
  std::vector<BoardWindow> Windows() const {
    const Mat3 R_i_b = so3::Exp(rho).transpose();
    std::vector<BoardWindow> out;
    const int per_window = static_cast<int>(kWindow_s * kRate_hz);
    const int n = static_cast<int>(kTurn_s * kRate_hz);
    for (int first = 0; first + per_window <= n; first += per_window) {
      BoardWindow w;
      for (int i = first; i < first + per_window; ++i) {
        const double t = i / kRate_hz, ti = t + dt;
        w.imu0.acc += Force(t) / per_window;
        w.imu0.gyr += Omega(t) / per_window;
        w.imu0.dt_s += t / per_window;
        const Vec3 om = Omega(ti);
        w.imu.acc += R_i_b * (Force(ti) + Alpha(ti).cross(r) + om.cross(om.cross(r))) / per_window;
        w.imu.gyr += R_i_b * om / per_window;
        w.imu.dt_s += t / per_window;
      }
      for (int i = first; i < first + per_window; ++i) {
        const Vec3 d = Omega(i / kRate_hz) - w.imu0.gyr;
        w.gyr0_spread += d * d.transpose() / per_window;
      }
      w.imu0.count = w.imu.count = per_window;
      w.t_begin_s = (first - 0.5) / kRate_hz;
      w.t_end_s = (first + per_window - 0.5) / kRate_hz;
      out.push_back(w);
    }
    return out;
  }
};

/// The residual of `windows` at a mount of rotation `rho`, lever arm `r` and time offset `dt`,
/// both IMUs' models at zero; with `jacobian`, the mount's columns (rows x 7, row-major).
std::vector<double> Evaluate(const std::vector<BoardWindow>& windows, const Vec3& rho,
                             const Vec3& r, double dt, std::vector<double>* jacobian = nullptr) {
  static const model::Model m = model::Model::Parse("base");
  std::unique_ptr<ceres::CostFunction> cost(BoardForceResidual::Create(
      m, m, std::make_shared<const std::vector<BoardWindow>>(windows), 0, 0));
  const double mount[model::board_mount::kSize] = {rho.x(), rho.y(), rho.z(), r.x(),
                                                   r.y(),   r.z(),   dt};
  const model::ParameterBlocks theta = m.ZeroParameters();
  std::vector<const double*> blocks = {mount};
  for (int pass = 0; pass < 2; ++pass) {
    for (const auto& b : theta) blocks.push_back(b.data());
  }
  std::vector<double> out(static_cast<std::size_t>(cost->num_residuals()));
  std::vector<double*> jacobians(blocks.size(), nullptr);
  if (jacobian != nullptr) {
    jacobian->assign(out.size() * model::board_mount::kSize, 0.0);
    jacobians[0] = jacobian->data();
  }
  EXPECT_TRUE(cost->Evaluate(blocks.data(), out.data(), jacobian ? jacobians.data() : nullptr));
  return out;
}

double MaxAbs(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

TEST(BoardForceResidual, VanishesAtTheTrueLeverArmAndTimeOffset) {
  const Board board;
  const std::vector<BoardWindow> windows = board.Windows();
  ASSERT_EQ(windows.size(), 40u);
  // What is left at the truth is the windows' discretisation (the edge values from 50 ms
  // means, the time offset to first order). The lever arm's and the rotation's own terms are
  // a hundred times that, the time offset's ten.
  const double at_truth = MaxAbs(Evaluate(windows, board.rho, board.r, board.dt));
  EXPECT_LT(at_truth, 5e-5);
  EXPECT_GT(MaxAbs(Evaluate(windows, board.rho, Vec3::Zero(), board.dt)), 100.0 * at_truth);
  EXPECT_GT(MaxAbs(Evaluate(windows, board.rho, board.r, 0.0)), 10.0 * at_truth);
  EXPECT_GT(MaxAbs(Evaluate(windows, Vec3::Zero(), board.r, board.dt)), 100.0 * at_truth);
}

TEST(BoardForceResidual, ItsJacobianPredictsTheMountsChange) {
  const Board board;
  const std::vector<BoardWindow> windows = board.Windows();
  std::vector<double> J;
  const std::vector<double> r0 = Evaluate(windows, board.rho, board.r, board.dt, &J);
  // The residual is linear in the lever arm and in the time offset (but for their product,
  // the lever arm's acceleration shifted in time), and nearly so in a small turn of the
  // rotation: J d predicts the change.
  const double d[model::board_mount::kSize] = {1e-4, -2e-4, 1e-4, 1e-3, -2e-3, 1.5e-3, 1e-4};
  const Vec3 rho = board.rho + Vec3(d[0], d[1], d[2]);
  const Vec3 r = board.r + Vec3(d[3], d[4], d[5]);
  const std::vector<double> r1 = Evaluate(windows, rho, r, board.dt + d[6]);
  double worst = 0.0;
  for (std::size_t row = 0; row < r0.size(); ++row) {
    double predicted = r0[row];
    for (int c = 0; c < model::board_mount::kSize; ++c) {
      predicted += J[row * model::board_mount::kSize + static_cast<std::size_t>(c)] * d[c];
    }
    worst = std::max(worst, std::abs(predicted - r1[row]));
  }
  EXPECT_LT(worst, 3e-6) << "the change itself is up to " << MaxAbs(r1);
}

/// Every block's columns, from the cost function BoardForceResidual::Create gives and from
/// ceres::DynamicNumericDiffCostFunction over the same functor, at a mount and models away from
/// zero, with `wander` accelerometer processes per IMU.
void ExpectSameColumnsAsCeres(const model::Model& model, int wander) {
  const Board board;
  std::vector<BoardWindow> turn = board.Windows();
  for (std::size_t w = 0; w < turn.size(); ++w) {  // along the wander's line
    turn[w].imu0.line = turn[w].imu.line = (w + 0.5) / static_cast<double>(turn.size());
  }
  auto windows = std::make_shared<const std::vector<BoardWindow>>(std::move(turn));
  std::unique_ptr<ceres::CostFunction> cost(
      BoardForceResidual::Create(model, model, windows, wander, wander));
  ceres::DynamicNumericDiffCostFunction<BoardForceResidual, ceres::CENTRAL> ceres_central(
      new BoardForceResidual(model, model, windows, wander, wander));
  // Values: every parameter of IMU i's and IMU 0's models moved off its start by a small
  // amount of its own, each wander block a few milli-units.
  std::vector<std::vector<double>> values;
  values.push_back({board.rho.x(), board.rho.y(), board.rho.z(), board.r.x(), board.r.y(),
                    board.r.z(), board.dt});
  double offset = 1e-4;
  for (int imu = 0; imu < 2; ++imu) {
    for (auto block : model.ZeroParameters()) {
      for (double& x : block) x += (offset += 3.7e-5);
      values.push_back(block);
    }
  }
  for (int p = 0; p < 4 * wander; ++p) values.push_back({2e-3 * p, -1e-3, 5e-4 * p});
  for (const auto& v : values) ceres_central.AddParameterBlock(static_cast<int>(v.size()));
  ceres_central.SetNumResiduals(cost->num_residuals());
  ASSERT_EQ(cost->parameter_block_sizes(), ceres_central.parameter_block_sizes());
  std::vector<const double*> blocks;
  for (const auto& v : values) blocks.push_back(v.data());
  const auto rows = static_cast<std::size_t>(cost->num_residuals());
  std::vector<std::vector<double>> ours(values.size()), theirs(values.size());
  std::vector<double*> ours_at, theirs_at;
  for (std::size_t i = 0; i < values.size(); ++i) {
    ours[i].assign(rows * values[i].size(), 0.0);
    theirs[i].assign(rows * values[i].size(), 0.0);
    ours_at.push_back(ours[i].data());
    theirs_at.push_back(theirs[i].data());
  }
  std::vector<double> r_ours(rows), r_theirs(rows);
  ASSERT_TRUE(cost->Evaluate(blocks.data(), r_ours.data(), ours_at.data()));
  ASSERT_TRUE(ceres_central.Evaluate(blocks.data(), r_theirs.data(), theirs_at.data()));
  EXPECT_EQ(r_ours, r_theirs);
  // IMU i's gyroscope columns are zero where both models act as their linear stage (and so in
  // Ceres's columns, to within its differences' rounding).
  const bool linear = model.AtLinearStage(blocks.data() + 1) &&
                      model.AtLinearStage(blocks.data() + 1 + model.num_terms());
  for (std::size_t i = 0; i < values.size(); ++i) {
    const bool gyro_of_imu_i =
        i >= 1 && i < 1 + static_cast<std::size_t>(model.num_terms()) &&
        model.terms()[i - 1].effect->info().sensor == model::Sensor::kGyro;
    if (linear && gyro_of_imu_i) {
      EXPECT_LT(MaxAbs(theirs[i]), 1e-6) << "block " << i;
      EXPECT_EQ(MaxAbs(ours[i]), 0.0) << "block " << i;
      continue;
    }
    EXPECT_EQ(ours[i], theirs[i]) << "block " << i;
    EXPECT_GT(MaxAbs(ours[i]), 0.0) << "block " << i;
  }
}

// The staged differences recompute only what a block enters, and give Ceres's columns bit for
// bit: both models at their linear stage, with wander processes, and with models that read the
// angular acceleration (the size effect) and are not linear (the g-sensitivity).
TEST(BoardForceResidual, ItsColumnsAreCeresCentralDifferences) {
  ExpectSameColumnsAsCeres(model::Model::Parse("base"), 0);
  ExpectSameColumnsAsCeres(model::Model::Parse("base"), 2);
  ExpectSameColumnsAsCeres(model::Model::Parse("base+accel_size_effect+gyro_g_sensitivity"), 1);
}

}  // namespace
}  // namespace plumb::residuals
