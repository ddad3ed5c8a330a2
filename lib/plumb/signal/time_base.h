// plumb/signal/time_base.h — what a series' time stamps are (issue 34 item 3, SPEC 6 "The time
// base"): the sensor's own uniform sample clock, or a host's arrival clock with jitter; where
// samples were dropped; and the uniform clock that fits them.
//
// Model: sample k was taken at a + T n_k, n_k its sample index (n_0 = 0; n_k - n_{k-1} - 1
// samples were dropped before it), and stamped t_k = a + T n_k + e_k, e_k the stamping error
// (none for a sensor clock; the host's latency for an arrival clock). T is the sample clock's
// interval as the stamps' clock measures it, so a sensor whose rate is off its nominal value
// keeps that rate (a real drift is not fitted away); only the jitter e_k is.
//
// The indices: first each interval in steps of the median interval (at least one); then, where an interval is longer than 1.5 T and the stamps after
// it stay later than the line by about T or more (the median of the next kLevelWindow residuals
// against that of the previous ones), round(shift / T) samples were dropped there. A host's
// bunching (a late stamp followed by an early one) shifts no level and drops nothing. a and T
// are the least-squares line of t against n, refitted once the drops are placed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace plumb::signal {

/// What the stamps are.
enum class ClockKind {
  kTooShort,    ///< fewer than kMinTimeBaseSamples stamps: not judged
  kUniform,     ///< a uniform sample clock: jitter below kUniformJitterFraction of T
  kHostArrival,  ///< stamped on arrival by a host: jitter from that fraction to a quarter of T
  /// No sample clock fits: jitter of a quarter of T or more (telemetry streamed at an
  /// irregular rate); no uniform clock is put in its place.
  kIrregular
};

/// Stamps needed to judge a time base (two windows of level on each side of a gap and more).
inline constexpr std::size_t kMinTimeBaseSamples = 32;
/// A sensor's own clock stamps to far better than 1 % of its interval (crystal-timed
/// counters: ppm); a host's arrival time carries scheduling and bus latency of 1-10 % or more.
inline constexpr double kUniformJitterFraction = 0.01;
/// Beyond a quarter of an interval, stamps no longer tell one sample from the next.
inline constexpr double kIrregularJitterFraction = 0.25;
/// Residuals on each side of a long interval whose medians decide whether samples were
/// dropped there (a level shift) or only stamped late (no shift).
inline constexpr std::size_t kLevelWindow = 8;

struct TimeBase {
  ClockKind kind = ClockKind::kTooShort;
  std::size_t samples = 0;
  double offset_s = 0.0;    ///< a: the fitted clock at sample index 0, s
  double interval_s = 0.0;  ///< T: the fitted sample interval, s
  /// The sample index of every stamp (n_0 = 0, strictly increasing; gaps where dropped).
  std::vector<std::int64_t> index;
  double jitter_rms_s = 0.0;  ///< RMS of t_k - (a + T n_k), s
  double jitter_max_s = 0.0;  ///< largest |t_k - (a + T n_k)|, s
  double median_interval_s = 0.0;  ///< median of t_k - t_{k-1}, s (biased by jitter patterns)
  std::size_t dropped = 0;   ///< samples missing (sum of n_k - n_{k-1} - 1)
  std::size_t drop_places = 0;  ///< intervals where some were dropped
  double first_drop_s = 0.0;  ///< stamp of the first sample after the first drop, s
  std::size_t long_intervals = 0;   ///< intervals above 1.25 T that dropped nothing
  std::size_t short_intervals = 0;  ///< intervals below 0.75 T

  /// The fitted rate, Hz (0 when not judged).
  double rate_hz() const { return interval_s > 0.0 ? 1.0 / interval_s : 0.0; }
  /// The uniform clock's time of stamp k: a + T n_k.
  double UniformTime(std::size_t k) const {
    return offset_s + interval_s * static_cast<double>(index[k]);
  }
};

/// Reads the stamps `t_s` (strictly increasing, s) for what they are (see the file comment).
TimeBase AnalyseTimeBase(const std::vector<double>& t_s);

/// Replaces every stamp by the uniform clock of `base` (AnalyseTimeBase of the same stamps),
/// keeping the gaps where samples were dropped. Nothing changes when it was not judged or is
/// irregular.
void ApplyUniformClock(const TimeBase& base, std::vector<double>& t_s);

}  // namespace plumb::signal
