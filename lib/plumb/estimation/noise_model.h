// plumb/estimation/noise_model.h — stage 2 of the backend: the noise the residuals are
// whitened with, measured on the session's own still segments.
//
// Per axis: the pooled within-segment scatter of the samples (sigma per sample, sensor units,
// floored at options.min_sigma_*) and the integrated autocorrelation time tau (Sokal's
// windowed estimate, signal/correlation_time.h; at least 1 sample). The variance of a segment
// mean of N samples is then sigma^2 tau / N. Segments turning at a stated rate are left out:
// their scatter is signal. The bias random-walk densities come from the options
// (CalibrationOptions::accel_walk_density, gyro_walk_density).
#pragma once

#include "plumb/core/imu_series.h"
#include "plumb/core/types.h"
#include "plumb/estimation/calibration.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/still_set.h"

namespace plumb::estimation {

struct NoiseModel {
  Vec3 sigma_acc = Vec3::Zero();  ///< accelerometer noise per sample, sensor units (> 0)
  Vec3 sigma_gyr = Vec3::Zero();  ///< gyroscope noise per sample, sensor units (0: no gyro)
  Vec3 tau_acc = Vec3::Ones();    ///< integrated autocorrelation time per axis, samples (>= 1)
  Vec3 tau_gyr = Vec3::Ones();
  /// Bias random-walk densities per axis, sensor units / s / sqrt(Hz) (0: no walk).
  Vec3 walk_acc = Vec3::Zero();
  Vec3 walk_gyr = Vec3::Zero();

  bool accel_walks() const { return walk_acc.minCoeff() > 0; }
  bool gyro_walks() const { return walk_gyr.minCoeff() > 0; }

  /// As the calibration reports it: sigma per axis and the largest tau of each sensor.
  NoiseLevels Levels() const;
};

/// Stage 2 (file comment).
NoiseModel EstimateNoise(const ImuSeries& series, const StillSet& set, bool has_gyro,
                         const CalibrationOptions& options);

}  // namespace plumb::estimation
