#include "plumb/estimation/noise_model.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "plumb/core/error.h"
#include "plumb/signal/correlation_time.h"

namespace plumb::estimation {

NoiseLevels NoiseModel::Levels() const {
  NoiseLevels out;
  out.acc = sigma_acc;
  out.gyr = sigma_gyr;
  out.tau_acc = tau_acc.maxCoeff();
  out.tau_gyr = tau_gyr.maxCoeff();
  out.walk_acc = walk_acc;
  out.walk_gyr = walk_gyr;
  return out;
}

NoiseModel EstimateNoise(const ImuSeries& series, const StillSet& set, bool has_gyro,
                         const CalibrationOptions& options) {
  const std::vector<StillSegment> used = set.AtRestSegments();
  const auto acc = signal::EstimateCorrelationTime(series, used, signal::Sensor::kAccel);
  std::array<signal::CorrelationTime, 3> gyr{};
  if (has_gyro) gyr = signal::EstimateCorrelationTime(series, used, signal::Sensor::kGyro);
  NoiseModel noise;
  for (int i = 0; i < 3; ++i) {
    const auto axis = static_cast<std::size_t>(i);
    noise.sigma_acc[i] = std::max(std::sqrt(acc[axis].variance), options.min_sigma_acc);
    noise.tau_acc[i] = std::max(1.0, acc[axis].tau_int);
    if (has_gyro) {
      noise.sigma_gyr[i] = std::max(std::sqrt(gyr[axis].variance), options.min_sigma_gyr);
      noise.tau_gyr[i] = std::max(1.0, gyr[axis].tau_int);
    }
  }
  for (const auto& density : {options.accel_walk_density, options.gyro_walk_density}) {
    if (density && !(std::isfinite(*density) && *density >= 0)) {
      throw Error("a bias random-walk density must be finite and >= 0 (got " +
                  std::to_string(*density) + ")");
    }
  }
  if (options.accel_walk_density) noise.walk_acc = Vec3::Constant(*options.accel_walk_density);
  if (options.gyro_walk_density && has_gyro) {
    noise.walk_gyr = Vec3::Constant(*options.gyro_walk_density);
  }
  return noise;
}

}  // namespace plumb::estimation
