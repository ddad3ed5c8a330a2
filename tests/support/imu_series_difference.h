// tests/support/imu_series_difference.h — the first difference between two IMU series, or
// none (times, accelerometer, gyroscope and temperature samples, NaN only where NaN): for the
// log differences of the readers' two-part reads (dataflash_log_difference.h,
// ulog_log_difference.h).
#pragma once

#include <cmath>
#include <string>

#include "plumb/core/imu_series.h"

namespace plumb::testing {

/// `a` and `b` the same value (NaN only where NaN).
inline bool SameFloats(float a, float b) { return a == b || (std::isnan(a) && std::isnan(b)); }
inline bool SameDoubles(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

inline std::string ImuSeriesDifference(const ImuSeries& a, const ImuSeries& b) {
  if (a.size() != b.size()) {
    return "samples " + std::to_string(a.size()) + " != " + std::to_string(b.size());
  }
  if (a.gyr.size() != b.gyr.size()) return "gyroscope samples";
  if (a.temp_c.size() != b.temp_c.size()) return "temperature samples";
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a.t_s[i] != b.t_s[i]) return "time of sample " + std::to_string(i);
    for (int k = 0; k < 3; ++k) {
      if (!SameFloats(a.acc[i][k], b.acc[i][k])) return "accelerometer sample " + std::to_string(i);
      if (!a.gyr.empty() && !SameFloats(a.gyr[i][k], b.gyr[i][k])) {
        return "gyroscope sample " + std::to_string(i);
      }
    }
    if (!a.temp_c.empty() && !SameFloats(a.temp_c[i], b.temp_c[i])) {
      return "temperature sample " + std::to_string(i);
    }
  }
  return "";
}

}  // namespace plumb::testing
