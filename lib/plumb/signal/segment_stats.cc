#include "plumb/signal/segment_stats.h"

#include <algorithm>
#include <string>

#include "plumb/core/error.h"

namespace plumb::signal {
namespace {

/// Mean of a triad over [begin, end), in double.
Vec3 TriadMean(const std::vector<Vec3f>& samples, std::size_t begin, std::size_t end) {
  Vec3 sum = Vec3::Zero();
  for (std::size_t i = begin; i < end; ++i) sum += samples[i].cast<double>();
  return sum / static_cast<double>(end - begin);
}

/// Per-axis sample standard deviation about `mean` (n - 1 divisor); NaN for fewer than 2.
Vec3 TriadStd(const std::vector<Vec3f>& samples, std::size_t begin, std::size_t end,
              const Vec3& mean) {
  if (end - begin < 2) return Vec3::Constant(SegmentStats::kNaN);
  Vec3 sum_sq = Vec3::Zero();
  for (std::size_t i = begin; i < end; ++i) {
    const Vec3 d = samples[i].cast<double>() - mean;
    sum_sq += d.cwiseProduct(d);
  }
  return (sum_sq / static_cast<double>(end - begin - 1)).cwiseSqrt();
}

void CheckRange(const ImuSeries& series, std::size_t begin, std::size_t end) {
  const std::size_t n = series.size();
  if (series.acc.size() != n || (series.has_gyro() && series.gyr.size() != n) ||
      (series.has_temperature() && series.temp_c.size() != n)) {
    throw Error("inconsistent series: " + std::to_string(n) + " times, " +
                std::to_string(series.acc.size()) + " accelerometer, " +
                std::to_string(series.gyr.size()) + " gyroscope and " +
                std::to_string(series.temp_c.size()) + " temperature samples");
  }
  if (begin >= end || end > n) {
    throw Error("segment statistics: sample range [" + std::to_string(begin) + ", " +
                std::to_string(end) + ") is empty or outside the series of " +
                std::to_string(n) + " samples");
  }
}

}  // namespace

SegmentStats ComputeSegmentStats(const ImuSeries& series, std::size_t begin, std::size_t end) {
  CheckRange(series, begin, end);
  SegmentStats stats;
  stats.count = end - begin;
  stats.t_begin_s = series.t_s[begin];
  stats.t_end_s = series.t_s[end - 1];
  stats.has_gyro = series.has_gyro();

  // Times relative to the first sample keep full precision with unix-epoch time stamps.
  double t_sum = 0.0;
  for (std::size_t i = begin; i < end; ++i) t_sum += series.t_s[i] - stats.t_begin_s;
  const double count = static_cast<double>(stats.count);
  stats.t_mid_s = stats.t_begin_s + t_sum / count;
  stats.acc_mean = TriadMean(series.acc, begin, end);
  stats.acc_std = TriadStd(series.acc, begin, end, stats.acc_mean);
  if (stats.has_gyro) {
    stats.gyr_mean = TriadMean(series.gyr, begin, end);
    stats.gyr_std = TriadStd(series.gyr, begin, end, stats.gyr_mean);
  }
  if (series.has_temperature()) {
    double temp_sum = 0.0;
    stats.temp_min_c = series.temp_c[begin];
    stats.temp_max_c = series.temp_c[begin];
    for (std::size_t i = begin; i < end; ++i) {
      const double temp = series.temp_c[i];
      temp_sum += temp;
      stats.temp_min_c = std::min(stats.temp_min_c, temp);
      stats.temp_max_c = std::max(stats.temp_max_c, temp);
    }
    stats.temp_mean_c = temp_sum / count;
  }
  return stats;
}

SegmentStats ComputeSegmentStats(const ImuSeries& series, const StillSegment& segment) {
  return ComputeSegmentStats(series, segment.begin, segment.end);
}

}  // namespace plumb::signal
