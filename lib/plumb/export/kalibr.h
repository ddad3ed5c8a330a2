// plumb/export/kalibr.h — the session's noise as Kalibr's imu.yaml.
//
// Kalibr's imu.yaml carries the noise model only (ethz-asl/kalibr wiki "IMU Noise Model"):
//   accelerometer_noise_density  N_a, m/s^2/sqrt(Hz)   (white noise, continuous time)
//   accelerometer_random_walk    K_a, m/s^3/sqrt(Hz)   (bias random walk)
//   gyroscope_noise_density      N_g, rad/s/sqrt(Hz)
//   gyroscope_random_walk        K_g, rad/s^2/sqrt(Hz)
//   rostopic, update_rate (Hz)
// It has no place for scale, misalignment, biases or any plumb effect: Kalibr estimates its
// own IMU intrinsics (its scale-misalignment models) in the camera-IMU calibration.
//
// From the session:
// - N, from two measurements, the larger written (an understated noise misleads a filter
//   more than an overstated one):
//   * the per-sample noise sigma (the still-segment scatter plumb whitened with):
//     N_sample = sigma sqrt(dt), Kalibr's own conversion between its continuous density and
//     the discrete per-sample sigma (sigma_d = N / sqrt(dt));
//   * the low-frequency level: the Allan deviation of the longest still segment at 1 s
//     (white noise: ADEV(t) = N / sqrt(t)) when that segment lasts at least 3 s, otherwise
//     sigma sqrt(tau dt) with tau plumb's integrated autocorrelation time (samples): the
//     density near zero frequency of a (possibly low-pass filtered) output.
// - K: a random walk adds K^2 t / 3 to the Allan variance, so every cluster time t bounds
//   K <= ADEV(t) sqrt(3 / t); the smallest bound over t (up to a third of the longest still
//   segment) is written. It is an estimate only when the Allan deviation rises with slope
//   close to +1/2 at the longest times; otherwise (short still segments, the usual case) it is
//   an upper bound and marked so.
// Kalibr takes one value per sensor: the largest over the three axes.
#pragma once

#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/estimation/calibration.h"
#include "plumb/estimation/fit_report.h"
#include "plumb/export/firmware.h"

namespace plumb::exporter {

struct SensorNoise {
  Vec3 white = Vec3::Zero();         ///< N per axis (the larger of the two below), unit/sqrt(Hz)
  Vec3 white_sample = Vec3::Zero();  ///< sigma sqrt(dt) per axis, unit/sqrt(Hz)
  /// Low-frequency level per axis: ADEV(1 s), or sigma sqrt(tau dt) when not measurable.
  Vec3 white_low = Vec3::Zero();
  bool low_from_allan = false;       ///< white_low is ADEV(1 s) (on every axis)
  Vec3 walk = Vec3::Zero();         ///< K per axis (estimate or upper bound), unit/s/sqrt(Hz)
  bool walk_resolved = false;       ///< true: the +1/2 slope was seen on every axis
};

struct KalibrImu {
  std::string rostopic = "/imu0";  ///< ROS topic of the IMU messages
  double update_rate_hz = 0;       ///< 1 / median sample interval, Hz
  SensorNoise accel, gyro;
  bool has_gyro = false;
  double longest_still_s = 0;      ///< length of the segment the Allan deviation used, s
  std::vector<std::string> notes;  ///< what the file cannot carry and how K was found

  double accelerometer_noise_density() const { return accel.white.maxCoeff(); }
  double accelerometer_random_walk() const { return accel.walk.maxCoeff(); }
  double gyroscope_noise_density() const { return gyro.white.maxCoeff(); }
  double gyroscope_random_walk() const { return gyro.walk.maxCoeff(); }
};

/// The noise of the session (file comment): the calibration's noise levels, checked with the
/// Allan deviation of the longest of the session's still segments `still` that is not
/// turning. Throws plumb::Error when the outputs are not in SI or the series has fewer than
/// two samples.
KalibrImu KalibrNoise(const estimation::Calibration& calibration, const ImuSeries& series,
                      const std::vector<estimation::StillSegmentFit>& still,
                      const std::string& rostopic);

/// Kalibr's imu.yaml text (comments say which values are upper bounds).
std::string KalibrYaml(const KalibrImu& imu);

}  // namespace plumb::exporter
