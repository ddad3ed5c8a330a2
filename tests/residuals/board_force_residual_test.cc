// The comparison of another IMU's accelerometer with IMU 0's in a turn (residuals/
// board_force_residual.h): on a board turned smoothly, with ideal sensors sampled at 1 kHz, the
// residual vanishes at the true lever arm and time offset and nowhere else, and its Jacobian
// predicts the change of the residual (which is linear in both).
#include "plumb/residuals/board_force_residual.h"

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

}  // namespace
}  // namespace plumb::residuals
