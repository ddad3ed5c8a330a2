// plumb/estimation/gates_internal.h — what the samples' gates (gates_samples.cc) and the
// fit's gates (gates.cc) share: counted nouns, the axes' names, SI tests and a median.
#pragma once

#include <algorithm>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"

namespace plumb::estimation::gates_internal {

inline constexpr const char* kAxis[3] = {"x", "y", "z"};

/// "N thing" or "N things".
inline std::string Count(std::size_t n, const std::string& thing) {
  return std::to_string(n) + " " + thing + (n == 1 ? "" : "s");
}

inline bool SiAccel(const ImuSeries& s) { return s.acc_unit == "m/s^2"; }
inline bool SiGyro(const ImuSeries& s) { return s.gyr_unit == "rad/s"; }

/// The median of `v` (NaN when empty).
inline double Median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace plumb::estimation::gates_internal
