#include "plumb/estimation/initialization.h"

#include "plumb/core/so3.h"
#include "plumb/core/units.h"
#include "plumb/model/effects/accel_linear.h"
#include "plumb/model/effects/gyro_linear.h"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <boost/math/tools/minima.hpp>
#include <cmath>
#include <cstdint>

namespace plumb::estimation {
namespace {

/// Brent's search for the gyroscope scale: bits of log10(scale) (about 1e-4 decade at the
/// scales of raw counts), and the most evaluations (each integrates every turn).
constexpr int kScaleSearchBits = 14;
constexpr std::uintmax_t kScaleSearchEvaluations = 40;

}  // namespace

AccelGuess GuessAccel(const std::vector<Vec3>& means, double g) {
  AccelGuess guess;
  std::vector<double> norms;
  for (const auto& m : means) norms.push_back(m.norm());
  if (!norms.empty()) {
    std::nth_element(norms.begin(), norms.begin() + static_cast<std::ptrdiff_t>(norms.size() / 2), norms.end());
    guess.scale = norms[norms.size() / 2] / g;
    // Data already in m/s^2: start at the nominal F = I rather than at a noisy scale.
    if (std::abs(guess.scale - 1.0) < 0.1) guess.scale = 1.0;
  }
  if (means.size() < 4) return guess;
  // |m|^2 = 2 c.m + (r^2 - |c|^2): linear in (c, d). Centred and normalised first, so that
  // raw counts around 32768 condition the fit as well as m/s^2 do.
  Vec3 centre = Vec3::Zero();
  for (const auto& m : means) centre += m / static_cast<double>(means.size());
  double spread = 0;
  for (const auto& m : means) spread = std::max(spread, (m - centre).norm());
  if (!(spread > 0)) return guess;
  Eigen::MatrixXd A(static_cast<Eigen::Index>(means.size()), 4);
  Eigen::VectorXd b(static_cast<Eigen::Index>(means.size()));
  for (std::size_t k = 0; k < means.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    const Vec3 u = (means[k] - centre) / spread;
    A.row(i) << 2 * u.transpose(), 1.0;
    b[i] = u.squaredNorm();
  }
  // Only trust the fit when the orientations span 3-D (well-conditioned A).
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A);
  const auto s = svd.singularValues();
  if (s[3] < 1e-3 * s[0]) return guess;
  const Eigen::Vector4d x = A.colPivHouseholderQr().solve(b);
  const Vec3 c = centre + spread * x.head<3>();
  const double r2 = spread * spread * (x[3] + x.head<3>().squaredNorm());
  if (!(r2 > 0)) return guess;
  guess.scale = std::sqrt(r2) / g;
  guess.bias = c;
  guess.sphere_fit = true;
  return guess;
}

double Heading(const Quat& R_n_b) {
  const Mat3 R = R_n_b.toRotationMatrix();
  return std::atan2(R(1, 0), R(0, 0));
}

Quat AttitudeFromDown(const Vec3& down_b, double heading_rad) {
  const Quat R0 = Quat::FromTwoVectors(down_b.normalized(), Vec3::UnitZ());
  const double turn = heading_rad - Heading(R0);
  return (Eigen::AngleAxisd(turn, Vec3::UnitZ()) * R0).normalized();
}

Quat CorrectTilt(const Quat& R_n_b, const Vec3& down_b) {
  const Vec3 down_n = R_n_b * down_b.normalized();
  return (Quat::FromTwoVectors(down_n, Vec3::UnitZ()) * R_n_b).normalized();
}

namespace {

/// The rate sum of one trapezoidal step of IntegrateRaw, (y_i - b) + (y_i+1 - b), sensor units.
Vec3 RateSum(const ImuSeries& series, std::size_t i, const Vec3& bias) {
  return (series.gyr[i].cast<double>() - bias) + (series.gyr[i + 1].cast<double>() - bias);
}

/// One trapezoidal step: q Exp(0.5 s u h), `u` the step's RateSum.
Quat Step(const Quat& q, const Vec3& u, double h, double scale) {
  const Vec3 w = 0.5 * scale * u;
  return q * so3::ExpQuat(w * h);
}

/// The steps of every motion interval, kept for the scale search, which integrates them
/// again at each scale it tries: the same arithmetic as IntegrateRaw, without reading the
/// samples each time.
class TurnSteps {
 public:
  TurnSteps(const ImuSeries& series,
            const std::vector<std::pair<std::size_t, std::size_t>>& intervals, const Vec3& bias) {
    for (const auto& [first, last] : intervals) {
      begin_.push_back(u_.size());
      for (std::size_t i = first; i < last; ++i) {
        u_.push_back(RateSum(series, i, bias));
        h_.push_back(series.t_s[i + 1] - series.t_s[i]);
      }
    }
    begin_.push_back(u_.size());
  }

  /// IntegrateRaw of interval k at `scale`.
  Quat Integrate(std::size_t k, double scale) const {
    Quat q = Quat::Identity();
    for (std::size_t i = begin_[k]; i < begin_[k + 1]; ++i) q = Step(q, u_[i], h_[i], scale);
    return q.normalized();
  }

 private:
  std::vector<Vec3> u_;
  std::vector<double> h_;
  std::vector<std::size_t> begin_;
};

}  // namespace

Quat IntegrateRaw(const ImuSeries& series, std::size_t first, std::size_t last,
                  const Vec3& bias, double scale) {
  Quat q = Quat::Identity();
  for (std::size_t i = first; i < last; ++i) {
    q = Step(q, RateSum(series, i, bias), series.t_s[i + 1] - series.t_s[i], scale);
  }
  return q.normalized();
}

double GuessGyroScale(const ImuSeries& series,
                      const std::vector<std::pair<std::size_t, std::size_t>>& intervals,
                      const std::vector<Vec3>& down_before, const std::vector<Vec3>& down_after,
                      const Vec3& bias, const JobRunner& run_jobs) {
  if (intervals.empty()) return 1.0;
  // down_after = dR^T down_before, dR = R_k^T R_k+1. The intervals are integrated as jobs,
  // their terms summed in order.
  const TurnSteps steps(series, intervals, bias);
  std::vector<double> terms(intervals.size());
  auto cost = [&](double log10_s) {
    const double s = std::pow(10.0, log10_s);
    RunJobs(run_jobs, static_cast<int>(intervals.size()), [&](int job) {
      const auto k = static_cast<std::size_t>(job);
      const Quat dR = steps.Integrate(k, s);
      terms[k] = (dR.conjugate() * down_before[k] - down_after[k]).squaredNorm();
    });
    double c = 0;
    for (const double term : terms) c += term;
    return c;
  };
  // A first estimate: the angle between the down directions over the integrated raw angle,
  // from the intervals that turn the IMU by more than 20 degrees (a turn about the vertical
  // shows no change of down: such intervals count only in the refinement).
  std::vector<double> ratios;
  for (std::size_t k = 0; k < intervals.size(); ++k) {
    const double angle = std::acos(std::clamp(down_before[k].dot(down_after[k]), -1.0, 1.0));
    Vec3 raw = Vec3::Zero();
    for (std::size_t i = intervals[k].first; i < intervals[k].second; ++i) {
      raw += (series.gyr[i].cast<double>() - bias) * (series.t_s[i + 1] - series.t_s[i]);
    }
    if (angle > 0.35 && raw.norm() > 0) ratios.push_back(angle / raw.norm());
  }
  // No interval turns enough to tell the scale. In SI units (rad/s) the nominal scale 1 is
  // the right start: a search over a turn-and-back or a small bump finds a spurious minimum
  // (0.11 on pyulog's sample.ulg, whose two still poses are joined by a knock) that the fit
  // then cannot leave. Unscaled output (counts) has no nominal: search.
  if (ratios.empty() && series.gyr_unit == "rad/s") return 1.0;
  double best = 0.0;
  if (!ratios.empty()) {
    std::nth_element(ratios.begin(), ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2), ratios.end());
    best = std::log10(ratios[ratios.size() / 2]);
  } else {
    double best_cost = cost(0.0);
    for (double e = -7.0; e <= 7.0; e += 0.25) {
      const double c = cost(e);
      if (c < best_cost) {
        best_cost = c;
        best = e;
      }
    }
  }
  // Brent's refinement (Boost.Math): within 0.15 decade of the ratio estimate, or one grid
  // step either side of the grid's best, to about 1e-4 decade (kScaleSearchBits); a starting
  // value: the fit refines it.
  const double half_width = ratios.empty() ? 0.25 : 0.15;
  std::uintmax_t evaluations = kScaleSearchEvaluations;
  const auto found = boost::math::tools::brent_find_minima(cost, best - half_width,
                                                           best + half_width, kScaleSearchBits,
                                                           evaluations);
  return std::pow(10.0, found.first);
}

Vec3 StartingValues::Down(const StillPose& pose) const {
  return Vec3(-(pose.stats.acc_mean - accel.bias) / accel.scale).normalized();
}

namespace {

/// The gyroscope's starting bias (mean still output) and scalar scale (GuessGyroScale over
/// the motion intervals).
void GuessGyro(const ImuSeries& series, const StillSet& set, const JobRunner& run_jobs,
               StartingValues& start) {
  const auto at_rest = set.AtRestMeans(true);
  for (const auto& m : at_rest) start.gyro_bias += m / static_cast<double>(at_rest.size());
  std::vector<std::pair<std::size_t, std::size_t>> intervals;
  std::vector<Vec3> before, after;
  for (const auto& m : set.motions) {
    intervals.emplace_back(m.first, m.last);
    before.push_back(start.Down(set.poses[m.from]));
    after.push_back(start.Down(set.poses[m.from + 1]));
  }
  start.gyro_rad_per_unit =
      GuessGyroScale(series, intervals, before, after, start.gyro_bias, run_jobs);
}

/// Starting attitudes: tilt from gravity, heading carried along each chain.
void InitialAttitudes(const ImuSeries& series, const StartingValues& start,
                      std::optional<double> first_heading_deg, StillSet& set) {
  auto& poses = set.poses;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    StillPose& s = poses[k];
    if (s.known || s.heading_only) {
      s.set_R_n_b(*s.segment.known_R_n_b);
      continue;
    }
    if (k > 0 && set.joined_to_previous[k]) {
      const MotionInterval& m = set.MotionInto(k);
      const Quat dR = IntegrateRaw(series, m.first, m.last, start.gyro_bias,
                                   start.gyro_rad_per_unit);
      s.set_R_n_b(CorrectTilt(poses[k - 1].R_n_b() * dR, start.Down(s)));
    } else {
      const double heading =
          (k == 0 && first_heading_deg) ? *first_heading_deg * units::kRadPerDeg : 0.0;
      s.set_R_n_b(AttitudeFromDown(start.Down(s), heading));
    }
  }
}

}  // namespace

StartingValues Initialize(const ImuSeries& series, const model::Model& model, double g,
                          bool has_gyro, std::optional<double> first_heading_deg, StillSet& set,
                          model::ParameterBlocks& theta, const JobRunner& run_jobs) {
  StartingValues start;
  start.accel = GuessAccel(set.AtRestMeans(false), g);
  model::accel_linear::SetIsotropic(theta[static_cast<std::size_t>(model.BaseTerm(model::Sensor::kAccel))],
                                    start.accel.scale, start.accel.bias);
  if (has_gyro) {
    GuessGyro(series, set, run_jobs, start);
    model::gyro_linear::SetIsotropic(
        theta[static_cast<std::size_t>(model.BaseTerm(model::Sensor::kGyro))],
        start.gyro_rad_per_unit, start.gyro_bias);
  }
  // Fixed parameters are held at their nominal values, whatever the guesses above say.
  for (int t = 0; t < model.num_terms(); ++t) {
    const auto& fixed = model.terms()[static_cast<std::size_t>(t)].fixed;
    for (std::size_t i = 0; i < fixed.size(); ++i) {
      if (fixed[i]) theta[static_cast<std::size_t>(t)][i] = 0.0;
    }
  }
  InitialAttitudes(series, start, first_heading_deg, set);
  return start;
}

}  // namespace plumb::estimation
