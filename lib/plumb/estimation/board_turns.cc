// plumb/estimation/board_turns.cc — see board_turns.h.
#include "plumb/estimation/board_turns.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <memory>

#include "plumb/estimation/calibration_problem.h"
#include "plumb/model/board_mount.h"

namespace plumb::estimation {
namespace {

/// Means of samples [begin, end) of `series` over a turn whose first and last samples are
/// `turn`'s, for a model referred to t_ref and temp_ref.
residuals::WindowMeans Means(const ImuSeries& series, std::size_t begin, std::size_t end,
                             const MotionInterval& turn, const model::Model& model) {
  residuals::WindowMeans m;
  double t = 0.0, temp = 0.0;
  for (std::size_t i = begin; i < end; ++i) {
    m.acc += series.acc[i].cast<double>();
    if (series.has_gyro()) m.gyr += series.gyr[i].cast<double>();
    t += series.t_s[i];
    if (series.has_temperature()) temp += series.temp_c[i];
  }
  const double n = static_cast<double>(end - begin);
  m.count = static_cast<int>(end - begin);
  m.acc /= n;
  m.gyr /= n;
  t /= n;
  m.dt_s = t - model.t_ref_s;
  m.dtemp_c = series.has_temperature() ? temp / n - model.temp_ref_c : 0.0;
  const double T = series.t_s[turn.last] - series.t_s[turn.first];
  m.line = T > 0.0 ? std::clamp((t - series.t_s[turn.first]) / T, 0.0, 1.0) : 0.0;
  return m;
}

/// The first sample of [turn.first, turn.last] of `series` stamped at or after `t_s`.
std::size_t FirstAtOrAfter(const ImuSeries& series, const MotionInterval& turn, double t_s) {
  const auto begin = series.t_s.begin() + static_cast<std::ptrdiff_t>(turn.first);
  const auto end = series.t_s.begin() + static_cast<std::ptrdiff_t>(turn.last + 1);
  return static_cast<std::size_t>(std::lower_bound(begin, end, t_s) - series.t_s.begin());
}

}  // namespace

std::vector<residuals::BoardWindow> TurnWindows(const ImuSeries& series0,
                                                const MotionInterval& turn0,
                                                const model::Model& model0,
                                                const ImuSeries& series,
                                                const MotionInterval& turn,
                                                const model::Model& model) {
  std::vector<residuals::BoardWindow> out;
  auto period_of = [](const ImuSeries& s, const MotionInterval& t) {
    return t.last > t.first
               ? (s.t_s[t.last] - s.t_s[t.first]) / static_cast<double>(t.last - t.first)
               : 0.0;
  };
  const double period = period_of(series0, turn0), period_i = period_of(series, turn);
  const double slowest = 1.0 / kMinTurnRate_hz;
  if (!(period > 0.0 && period <= slowest && period_i > 0.0 && period_i <= slowest)) return out;
  const auto per_window = static_cast<std::size_t>(
      std::max(1.0, std::round(kBoardWindow_s / period)));
  // Edges halfway between samples; the turn's first and last half a period out.
  auto edge = [&](std::size_t i) {  // before IMU 0's sample i
    return i == turn0.first      ? series0.t_s[i] - 0.5 * period
           : i == turn0.last + 1 ? series0.t_s[turn0.last] + 0.5 * period
                                 : 0.5 * (series0.t_s[i - 1] + series0.t_s[i]);
  };
  for (std::size_t a0 = turn0.first; a0 + per_window <= turn0.last + 1; a0 += per_window) {
    const std::size_t b0 = a0 + per_window;
    residuals::BoardWindow window;
    window.t_begin_s = edge(a0);
    window.t_end_s = edge(b0);
    window.imu0 = Means(series0, a0, b0, turn0, model0);
    const std::size_t ai = FirstAtOrAfter(series, turn, window.t_begin_s);
    const std::size_t bi = FirstAtOrAfter(series, turn, window.t_end_s);
    if (bi > ai) {
      window.imu = Means(series, ai, bi, turn, model);
      window.stamp_lag_s =
          (window.imu.dt_s + model.t_ref_s) - (window.imu0.dt_s + model0.t_ref_s);
    }
    for (std::size_t i = a0; i < b0; ++i) {
      const Vec3 d = series0.gyr[i].cast<double>() - window.imu0.gyr;
      window.gyr0_spread += d * d.transpose();
    }
    window.gyr0_spread /= static_cast<double>(per_window);
    out.push_back(window);
  }
  return out;
}

Vec3 Scatter(const ImuSeries& series,
             const std::vector<std::pair<std::size_t, std::size_t>>& ranges) {
  Vec3 sum = Vec3::Zero();
  int n = 0;
  for (const auto& [first, last] : ranges) {
    for (std::size_t i = first + 1; i < last; ++i) {
      const Vec3 d = (series.acc[i + 1] - 2.0f * series.acc[i] + series.acc[i - 1]).cast<double>();
      sum += d.cwiseAbs2();
      ++n;
    }
  }
  return n > 0 ? Vec3(sum / (6.0 * n)) : Vec3::Zero();
}

void WeighTurnWindows(std::vector<residuals::BoardWindow>& windows, const TurnAccelNoise& imu0,
                      const TurnAccelNoise& imu, const Mat3& R_b_i) {
  // One IMU's window mean in the body frame (`R` into it): diagonal in its output axes.
  auto covariance = [](const residuals::WindowMeans& m, const TurnAccelNoise& noise,
                       const Mat3& R) {
    Vec3 var = noise.var_sample / std::max(1, m.count);
    const double T = noise.duration_s;
    for (const Vec3& K2 : noise.walk2) var += K2 * (T * m.line * (1.0 - m.line));
    const Mat3 M = R * noise.F_inv;
    return Mat3(M * var.asDiagonal() * M.transpose());
  };
  for (residuals::BoardWindow& w : windows) {
    const Mat3 C = covariance(w.imu0, imu0, Mat3::Identity()) + covariance(w.imu, imu, R_b_i);
    const Mat3 L = Eigen::LLT<Mat3>(C).matrixL();
    w.sqrt_info = L.inverse();
  }
}

// CalibrationProblem's side (calibration_problem.h): the windows weighed and compared.

void CalibrationProblem::SetTurnWeights(std::size_t imu) {
  ProblemImu& u = imus_[imu];
  if (!u.turns_compared) return;
  // Each IMU's scatter at rest, once (the turns' are their own).
  auto at_rest = [&](const ProblemImu& v) {
    std::vector<std::pair<std::size_t, std::size_t>> still;
    for (const StillPose& pose : v.still.poses) {
      if (pose.segment.end > pose.segment.begin) {
        still.emplace_back(pose.segment.begin, pose.segment.end - 1);
      }
    }
    return Scatter(*v.series, still);
  };
  const Vec3 rest0 = at_rest(imus_[0]), rest = at_rest(u);
  auto noise_of = [&](std::size_t i, const MotionInterval& turn, const Vec3& rest_scatter) {
    const ProblemImu& v = imus_[i];
    const std::vector<const double*> blocks = TermBlocks(i);
    TurnAccelNoise out;
    out.F_inv = v.model.Predict(blocks.data(), model::SensorInput<double>()).F.inverse();
    out.var_sample = v.noise.sigma_acc.cwiseAbs2().cwiseProduct(v.noise.tau_acc);
    const Vec3 in_turn = Scatter(*v.series, {{turn.first, turn.last}});
    for (int a = 0; a < 3 && options_.turn_vibration; ++a) {
      if (rest_scatter[a] > 0.0 && in_turn[a] > 0.0) {
        out.var_sample[a] *= in_turn[a] / rest_scatter[a];
      }
    }
    for (std::size_t p : v.WanderOf(model::Sensor::kAccel)) {
      out.walk2.push_back(v.wander[p].ShortTimeWalk2());
    }
    out.duration_s = v.series->t_s[turn.last] - v.series->t_s[turn.first];
    return out;
  };
  const Mat3 R_b_i = model::board_mount::Rotation(mount(imu)).toRotationMatrix();
  for (std::size_t k = 0; k < u.turn_windows.size(); ++k) {
    auto windows = std::make_shared<std::vector<residuals::BoardWindow>>(*u.turn_windows[k]);
    WeighTurnWindows(*windows, noise_of(0, imus_[0].still.motions[k], rest0),
                     noise_of(imu, u.still.motions[k], rest), R_b_i);
    u.turn_windows[k] = std::move(windows);
  }
}

void CalibrationProblem::AddTurnComparison(BuiltProblem& built, std::size_t imu,
                                           BuiltProblem::ImuBlocks& own) {
  const ProblemImu& u = imus_[imu];
  const std::vector<std::size_t> wander_i = u.WanderOf(model::Sensor::kAccel);
  const std::vector<std::size_t> wander_0 = imus_[0].WanderOf(model::Sensor::kAccel);
  for (std::size_t k = 0; k < u.turn_windows.size(); ++k) {
    const auto& windows = *u.turn_windows[k];
    if (std::none_of(windows.begin(), windows.end(),
                     [](const residuals::BoardWindow& w) { return w.imu.count > 0; })) {
      continue;
    }
    const MotionInterval& turn = u.still.motions[k];
    std::vector<double*> blocks = {mount(imu)};
    for (int local = 0; local < u.model.num_terms(); ++local) {
      blocks.push_back(block(u.first_term + local));
    }
    for (int t = 0; t < imus_[0].model.num_terms(); ++t) blocks.push_back(block(t));
    for (std::size_t p : wander_i) {
      blocks.insert(blocks.end(),
                    {wander(imu, turn.from, p, true), wander(imu, turn.from + 1, p, false)});
    }
    for (std::size_t p : wander_0) {
      blocks.insert(blocks.end(),
                    {wander(0, turn.from, p, true), wander(0, turn.from + 1, p, false)});
    }
    own.turns.push_back(built.problem->AddResidualBlock(
        residuals::BoardForceResidual::Create(u.model, imus_[0].model, u.turn_windows[k],
                                              static_cast<int>(wander_i.size()),
                                              static_cast<int>(wander_0.size())),
        nullptr, blocks));
  }
}

}  // namespace plumb::estimation
