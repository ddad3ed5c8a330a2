// plumb/signal/segment_stats.h — statistics of a sample range of an ImuSeries.
//
// What the still-segment residuals (SPEC section 3) need: the count, mean time, mean output,
// per-axis scatter and the temperature range. Two passes over the samples in double (the mean,
// then the squared deviations from it): exact to double rounding whatever the offset, and
// without a division per sample. NaN or infinite samples make the fields they enter non-finite.
#pragma once

#include <cstddef>
#include <limits>

#include "plumb/core/imu_series.h"
#include "plumb/core/segment.h"
#include "plumb/core/types.h"

namespace plumb::signal {

struct SegmentStats {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

  std::size_t count = 0;      ///< samples in the range, >= 1
  double t_begin_s = kNaN;    ///< time of the first sample, s
  double t_end_s = kNaN;      ///< time of the last sample, s
  double t_mid_s = kNaN;      ///< mean sample time, s
  /// Mean accelerometer output, series units (m/s^2 for SI series).
  Vec3 acc_mean = Vec3::Constant(kNaN);
  /// Per-axis sample standard deviation of the accelerometer about acc_mean (n - 1 in the
  /// denominator), series units; NaN when count < 2.
  Vec3 acc_std = Vec3::Constant(kNaN);
  bool has_gyro = false;      ///< whether the gyroscope fields below are filled
  /// Mean gyroscope output, series units (rad/s for SI series); NaN without a gyroscope.
  Vec3 gyr_mean = Vec3::Constant(kNaN);
  /// Per-axis sample standard deviation of the gyroscope, series units; NaN without a
  /// gyroscope or when count < 2.
  Vec3 gyr_std = Vec3::Constant(kNaN);
  double temp_mean_c = kNaN;  ///< mean temperature, degC; NaN when the series has none
  double temp_min_c = kNaN;   ///< lowest temperature in the range, degC; NaN when none
  double temp_max_c = kNaN;   ///< highest temperature in the range, degC; NaN when none
};

/// Statistics of the samples [begin, end). Throws plumb::Error if the range is empty, reversed
/// or outside the series, or if the series' arrays have inconsistent lengths.
SegmentStats ComputeSegmentStats(const ImuSeries& series, std::size_t begin, std::size_t end);

/// Statistics of a segment's samples [segment.begin, segment.end).
SegmentStats ComputeSegmentStats(const ImuSeries& series, const StillSegment& segment);

}  // namespace plumb::signal
