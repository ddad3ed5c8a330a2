// plumb/estimation/noise_model.h — stage 2 of the backend: the noise the residuals are
// whitened with, measured on the session's own still segments.
//
// Per axis: the pooled within-segment scatter of the samples about each segment's own
// least-squares line in time (sigma per sample, sensor units, floored at options.min_sigma_*;
// a temperature change or a wander inside a hold is not white noise, so it must not inflate
// sigma) and the integrated autocorrelation time tau (Sokal's
// windowed estimate, signal/correlation_time.h; at least 1 sample). The variance of a segment
// mean of N samples is then sigma^2 tau / N. Segments turning at a stated rate are left out:
// their scatter is signal.
//
// Over the session the bias wanders: a sum of independent Markov processes per sensor and
// axis, each zero at the model's reference time t_ref (so the model's bias is the bias then):
//   walk         random walk of density K (units/sqrt(s)): var b(t) = K^2 (t - t_ref)
//   instability  first-order Gauss-Markov of steady-state sigma s and correlation time tau:
//                b(t2) = phi b(t1) + w, phi = exp(-(t2 - t1) / tau), var w = s^2 (1 - phi^2)
// Their levels come from the options, the Allan deviation of still data or the typical MEMS
// sensor (wander_levels.h), or the walk estimate (walk_estimate.h).
#pragma once

#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/types.h"
#include "plumb/core/typical_mems.h"
#include "plumb/model/effect.h"
#include "plumb/estimation/calibration.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/still_set.h"

namespace plumb::estimation {

/// One Markov process of a sensor's bias wander (file comment), per axis.
struct WanderProcess {
  enum class Kind { kWalk, kInstability };
  model::Sensor sensor = model::Sensor::kAccel;
  Kind kind = Kind::kWalk;
  Vec3 level = Vec3::Zero();  ///< walk: K, units/sqrt(s); instability: s, units (> 0)
  double tau_s = 0.0;         ///< instability: correlation time, s (> 0)

  /// The factor from the value at one instant to the value dt_s later (dt_s > 0):
  /// b_to = phi b_from + w, w ~ N(0, diag(step_sigma^2)).
  double Phi(double dt_s) const;
  Vec3 StepSigma(double dt_s) const;
  /// Over a segment of length T_s with the process known at both ends: the weight w with
  /// E[mean over the segment] = w (b_start + b_end), and the variance per axis about it.
  double BridgeMeanWeight(double T_s) const;
  Vec3 BridgeMeanVariance(double T_s) const;
  /// Per axis, the squared density of the random walk with the same short-time spread: K^2
  /// for the walk, 2 s^2 / tau for the instability (exact for intervals short against tau:
  /// turns last seconds, correlation times tens of seconds and more).
  Vec3 ShortTimeWalk2() const;
};

struct NoiseModel {
  Vec3 sigma_acc = Vec3::Zero();  ///< accelerometer noise per sample, sensor units (> 0)
  Vec3 sigma_gyr = Vec3::Zero();  ///< gyroscope noise per sample, sensor units (0: no gyro)
  Vec3 tau_acc = Vec3::Ones();    ///< integrated autocorrelation time per axis, samples (>= 1)
  Vec3 tau_gyr = Vec3::Ones();
  /// Bias random-walk densities per axis, sensor units / s / sqrt(Hz) (0: no walk).
  Vec3 walk_acc = Vec3::Zero();
  Vec3 walk_gyr = Vec3::Zero();

  /// Bias instability per axis (Gauss-Markov sigma), sensor units (0: none), and its
  /// correlation time, s.
  Vec3 instability_acc = Vec3::Zero();
  Vec3 instability_gyr = Vec3::Zero();
  double instability_time_s = typical_mems::kInstabilityTime_s;
  WanderSources from;  ///< where each wander level came from (wander_levels.h)
  /// Quantisation per axis (IEEE Q, resolved by the Allan deviation of still data,
  /// wander_levels.h), sensor units x s (0: none): the mean output over T carries 2 Q^2 / T^2
  /// more variance, an integrated angle 2 Q^2.
  Vec3 quantisation_acc = Vec3::Zero();
  Vec3 quantisation_gyr = Vec3::Zero();

  bool accel_walks() const { return walk_acc.minCoeff() > 0; }
  bool gyro_walks() const { return walk_gyr.minCoeff() > 0; }
  bool accel_unstable() const { return instability_acc.minCoeff() > 0; }
  bool gyro_unstable() const { return instability_gyr.minCoeff() > 0; }
  /// The processes the bias wanders by, in the problem's state order: accelerometer walk,
  /// accelerometer instability, gyroscope walk, gyroscope instability (those present; the
  /// gyroscope's only with `has_gyro`).
  std::vector<WanderProcess> Wander(bool has_gyro) const;

  /// As the calibration reports it: sigma per axis and the largest tau of each sensor.
  NoiseLevels Levels() const;
};

/// Stage 2 (file comment).
NoiseModel EstimateNoise(const ImuSeries& series, const StillSet& set, bool has_gyro,
                         const CalibrationOptions& options);

}  // namespace plumb::estimation
