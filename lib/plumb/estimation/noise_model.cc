#include "plumb/estimation/noise_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "plumb/core/error.h"
#include "plumb/signal/correlation_time.h"

namespace plumb::estimation {

namespace {

/// Below this T / tau the Gauss-Markov bridge uses its series (the closed form cancels).
constexpr double kSeriesBelow = 1e-4;

}  // namespace

double WanderProcess::Phi(double dt_s) const {
  return kind == Kind::kWalk ? 1.0 : std::exp(-dt_s / tau_s);
}

Vec3 WanderProcess::StepSigma(double dt_s) const {
  if (kind == Kind::kWalk) return level * std::sqrt(dt_s);
  // 1 - phi^2 = -expm1(-2 dt / tau), exact also for small dt.
  return level * std::sqrt(-std::expm1(-2.0 * dt_s / tau_s));
}

// A Brownian bridge over T: E[mean] = (b_0 + b_T) / 2, variance K^2 T / 12. An
// Ornstein-Uhlenbeck bridge (stationary variance s^2, x = T / tau, u = 1 / x, phi = e^-x):
//   E[mean] = u (1 - phi) / (1 + phi) (b_0 + b_T) = u tanh(x / 2) (b_0 + b_T)
//   var     = s^2 [2 u^2 (x - 1 + phi) - 2 u^2 (1 - phi)^2 / (1 + phi)]
// (the mean's variance minus what the two ends explain); for small x: 1/2 and s^2 x / 6, the
// walk's values with K^2 = 2 s^2 / tau.
double WanderProcess::BridgeMeanWeight(double T_s) const {
  const double x = T_s / tau_s;
  if (kind == Kind::kWalk || x < kSeriesBelow) return 0.5;
  return std::tanh(0.5 * x) / x;
}

Vec3 WanderProcess::BridgeMeanVariance(double T_s) const {
  if (kind == Kind::kWalk) return level.cwiseAbs2() * (T_s / 12.0);
  const double x = T_s / tau_s;
  double unit = x / 6.0;
  if (x >= kSeriesBelow) {
    const double phi = std::exp(-x), u = 1.0 / x;
    unit = 2.0 * u * u * (x - 1.0 + phi) - 2.0 * u * u * (1.0 - phi) * (1.0 - phi) / (1.0 + phi);
  }
  return level.cwiseAbs2() * std::max(unit, 0.0);
}

Vec3 WanderProcess::ShortTimeWalk2() const {
  return kind == Kind::kWalk ? Vec3(level.cwiseAbs2()) : Vec3(level.cwiseAbs2() * (2.0 / tau_s));
}

std::vector<WanderProcess> NoiseModel::Wander(bool has_gyro) const {
  std::vector<WanderProcess> out;
  using Kind = WanderProcess::Kind;
  auto add = [&](model::Sensor sensor, Kind kind, const Vec3& level, bool on) {
    if (on) out.push_back(WanderProcess{sensor, kind, level, instability_time_s});
  };
  add(model::Sensor::kAccel, Kind::kWalk, walk_acc, accel_walks());
  add(model::Sensor::kAccel, Kind::kInstability, instability_acc, accel_unstable());
  add(model::Sensor::kGyro, Kind::kWalk, walk_gyr, has_gyro && gyro_walks());
  add(model::Sensor::kGyro, Kind::kInstability, instability_gyr, has_gyro && gyro_unstable());
  return out;
}

NoiseLevels NoiseModel::Levels() const {
  NoiseLevels out;
  out.acc = sigma_acc;
  out.gyr = sigma_gyr;
  out.tau_acc = tau_acc.maxCoeff();
  out.tau_gyr = tau_gyr.maxCoeff();
  out.walk_acc = walk_acc;
  out.walk_gyr = walk_gyr;
  out.instability_acc = instability_acc;
  out.instability_gyr = instability_gyr;
  out.instability_time_s = instability_time_s;
  out.from = from;
  out.quantisation_acc = quantisation_acc;
  out.quantisation_gyr = quantisation_gyr;
  return out;
}

NoiseModel EstimateNoise(const ImuSeries& series, const StillSet& set, bool has_gyro,
                         const CalibrationOptions& options) {
  const std::vector<StillSegment> used = set.AtRestSegments();
  // Each segment about its own line: a drift inside a hold (the board warming, the bias's
  // wander) is not white noise; the wander processes carry it (file comment).
  signal::CorrelationTimeOptions correlation;
  correlation.detrend = true;
  std::vector<signal::Sensor> sensors{signal::Sensor::kAccel};
  if (has_gyro) sensors.push_back(signal::Sensor::kGyro);
  const std::vector<signal::CorrelationTime> axes =
      signal::EstimateCorrelationTimes(series, used, sensors, correlation, options.run_jobs);
  NoiseModel noise;
  for (int i = 0; i < 3; ++i) {
    const auto acc = static_cast<std::size_t>(i);
    noise.sigma_acc[i] = std::max(std::sqrt(axes[acc].variance), options.min_sigma_acc);
    noise.tau_acc[i] = std::max(1.0, axes[acc].tau_int);
    if (has_gyro) {
      const std::size_t gyr = 3 + acc;
      noise.sigma_gyr[i] = std::max(std::sqrt(axes[gyr].variance), options.min_sigma_gyr);
      noise.tau_gyr[i] = std::max(1.0, axes[gyr].tau_int);
    }
  }
  // The levels given are in their ranges (CalibrationOptions::Validate, stage 0).
  noise.instability_time_s = options.instability_time_s;
  if (options.constant_bias) return noise;  // no walk, no instability
  // The levels given; the others are set by stage 2a (wander_levels.h).
  auto give = [](const std::optional<double>& level, Vec3& to, std::array<LevelSource, 3>& from) {
    if (!level) return;
    to = Vec3::Constant(*level);
    from.fill(*level > 0 ? LevelSource::kGiven : LevelSource::kNone);
  };
  give(options.accel_instability, noise.instability_acc, noise.from.instability_acc);
  give(options.accel_walk_density, noise.walk_acc, noise.from.walk_acc);
  if (has_gyro) {
    give(options.gyro_instability, noise.instability_gyr, noise.from.instability_gyr);
    give(options.gyro_walk_density, noise.walk_gyr, noise.from.walk_gyr);
  }
  return noise;
}

}  // namespace plumb::estimation
