// plumb/residuals/measurements.h — the data a residual compares the model with.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "plumb/core/types.h"

namespace plumb::residuals {

/// Statistics of one still segment for one sensor, and how to whiten them.
struct StillMeasurement {
  Vec3 mean = Vec3::Zero();       ///< mean output over the segment, sensor units
  Vec3 sqrt_info = Vec3::Ones();  ///< 1 / sigma of the mean per axis: sqrt(N / (sigma^2 tau))
  double dt_s = 0.0;              ///< mid-segment time minus the model's t_ref, s
  double dtemp_c = 0.0;           ///< mean temperature minus the model's temp_ref, degC
};

/// The raw samples between two still segments, for integrating the gyroscope.
struct MotionSamples {
  std::vector<double> dt_s;      ///< per sample: time minus the model's t_ref, s (increasing)
  std::vector<Vec3> acc;         ///< accelerometer output, sensor units
  std::vector<Vec3> gyr;         ///< gyroscope output, sensor units
  std::vector<Vec3> alpha_b;     ///< angular acceleration, E^-1 d y_g / dt, rad/s^2 (approx.)
  std::vector<double> dtemp_c;   ///< temperature minus temp_ref, degC (0 if none)
  Vec3 sqrt_info = Vec3::Ones(); ///< 1 / sigma of the rotation residual per axis, 1/rad
  std::size_t size() const { return dt_s.size(); }
};

/// Motion samples shared by the residuals of every problem built on them (they are only read).
using SharedMotionSamples = std::shared_ptr<const MotionSamples>;

}  // namespace plumb::residuals
