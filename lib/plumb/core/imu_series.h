// plumb/core/imu_series.h — a time series of accelerometer and gyroscope samples.
//
// Storage is structure-of-arrays, 36 bytes per sample (SPEC section 7 asks for under 64):
// time in double seconds, the two triads and the temperature in float. Floats hold raw 16-bit
// counts exactly and SI values to 6e-8 relative, far below any sensor's noise; every sum over
// samples is accumulated in double.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "plumb/core/types.h"

namespace plumb {

struct ImuSeries {
  /// Sample times, s, strictly increasing. Any origin (unix time or time since boot).
  std::vector<double> t_s;
  /// Accelerometer output in the reader's units (SI, m/s^2, unless the input was raw counts
  /// and no scale was given), body frame FRD.
  std::vector<Vec3f> acc;
  /// Gyroscope output, rad/s unless raw counts, same frame. May be empty (accelerometer only).
  std::vector<Vec3f> gyr;
  /// Sensor temperature, degC. Empty when the input has none.
  std::vector<float> temp_c;
  /// Units of the accelerometer and gyroscope samples: SI unless the reader was told the
  /// file holds unscaled sensor output (e.g. "counts"); calibrated matrices then map SI
  /// inputs to these units, and biases are in them.
  std::string acc_unit = "m/s^2";
  std::string gyr_unit = "rad/s";

  std::size_t size() const { return t_s.size(); }
  bool empty() const { return t_s.empty(); }
  bool has_gyro() const { return !gyr.empty(); }
  bool has_temperature() const { return !temp_c.empty(); }
  /// Duration from first to last sample, s (0 for fewer than two samples).
  double duration_s() const { return size() < 2 ? 0.0 : t_s.back() - t_s.front(); }
  /// Median sample interval, s (0 for fewer than two samples).
  double median_dt_s() const;
  void reserve(std::size_t n);
};

}  // namespace plumb
