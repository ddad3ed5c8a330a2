#include "plumb/segmentation/still_detector.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>

#include "plumb/core/error.h"
#include "plumb/segmentation/block_moments.h"
#include "plumb/signal/axis_view.h"
#include "plumb/signal/chi_square.h"
#include "plumb/signal/correlation_time.h"

namespace plumb::segmentation {
namespace {

/// Blocks per moving window when the window holds at least that many samples (odd, so that a
/// window is centred on a block). Boundaries are resolved to one block.
constexpr std::size_t kBlocksPerWindow = 17;
/// float resolution: noise standard deviations are floored at 4 eps |mean|, what a float
/// sample of that size resolves, so that a perfectly constant axis does not divide by zero.
constexpr double kFloatEps = 1.1920929e-7;
/// At most this many samples of the still periods feed the correlation-time estimate (its cost
/// is O(samples x lags)); 131072 samples pin tau_int to a few percent.
constexpr std::size_t kMaxCorrelationSamples = 131072;
/// The sliding window sums are recomputed from the blocks every this many positions, so that
/// rounding in the running updates cannot accumulate over long series.
constexpr std::size_t kResyncInterval = 4096;
/// False-alarm level of the automatic mode's first pass: strict, because its noise comes from
/// the quietest stretch, biased low.
constexpr double kProvisionalFalseAlarm = 1e-6;
/// How many gyro-rejected runs the notes list by time.
constexpr std::size_t kListedRuns = 12;

/// A half-open run of samples [begin, end).
struct Run {
  std::size_t begin = 0;
  std::size_t end = 0;

  std::size_t size() const { return end - begin; }
};

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

std::string FormatVec(const Vec3& v, const char* format = "%.4g") {
  return "(" + Format(format, v.x()) + ", " + Format(format, v.y()) + ", " + Format(format, v.z()) +
         ")";
}

std::string TimeRange(const ImuSeries& series, Run run) {
  const double t0 = series.t_s.front();
  return Format("%.2f", series.t_s[run.begin] - t0) + "-" +
         Format("%.2f", series.t_s[run.end - 1] - t0) + " s";
}

/// Window layout: `blocks` (odd) blocks of `block` samples, centred on a block.
struct Geometry {
  std::size_t block = 1;
  std::size_t blocks = 5;

  std::size_t window() const { return block * blocks; }
};

Geometry MakeGeometry(double window_s, double dt_s) {
  const double target = std::max(5.0, window_s / dt_s);  // samples per window
  Geometry g;
  if (target >= static_cast<double>(kBlocksPerWindow)) {
    g.blocks = kBlocksPerWindow;
    g.block = static_cast<std::size_t>(std::llround(target / kBlocksPerWindow));
  } else {
    g.block = 1;
    g.blocks = static_cast<std::size_t>(std::llround(target)) | 1U;  // odd
  }
  return g;
}

/// Everything a window test needs, derived from the noise estimate and the options.
struct WindowTests {
  Geometry geometry;
  double max_span_s = 0.0;         ///< longest time span of a window without a gap
  double inverse_n = 0.0;          ///< 1 / samples per window
  Vec3 acc_weight = Vec3::Zero();  ///< 1 / (3 sigma^2 (n - 1)), on the scatter sums
  double acc_threshold = 0.0;
  bool gyro_variance = false;         ///< gyroscope variance test on
  Vec3 gyr_weight = Vec3::Zero();     ///< 1 / (3 sigma^2 (n - 1)), on the scatter sums
  double gyr_threshold = 0.0;
  bool rate = false;                  ///< mean-rate test on
  Vec3 rate_offset = Vec3::Zero();    ///< n (still rate - gyro reference of the block sums)
  Vec3 rate_weight = Vec3::Zero();    ///< 1 / (V n^2), on the squared offset sums
  double rate_threshold = 0.0;
};

/// Collects maximal runs of samples with a true verdict, the verdicts coming in order.
class RunBuilder {
 public:
  /// The verdict for samples from `first` on (until the next call).
  void Mark(std::size_t first, bool still) {
    if (still && !in_run_) {
      begin_ = first;
      in_run_ = true;
    } else if (!still && in_run_) {
      runs_.push_back(Run{begin_, first});
      in_run_ = false;
    }
  }
  std::vector<Run> Finish(std::size_t n_samples) {
    if (in_run_) runs_.push_back(Run{begin_, n_samples});
    in_run_ = false;
    return std::move(runs_);
  }

 private:
  std::vector<Run> runs_;
  std::size_t begin_ = 0;
  bool in_run_ = false;
};

/// What one classification pass found.
struct Classification {
  std::vector<Run> runs;      ///< maximal runs of still samples
  std::vector<Run> acc_runs;  ///< the same by the accelerometer and time-gap tests alone
  std::size_t windows = 0;
  std::size_t failed_acc = 0;
  std::size_t failed_gyr = 0;
  std::size_t failed_rate = 0;
  std::size_t failed_gap = 0;
  std::size_t failed_nonfinite = 0;
};

void CheckOptions(const StillDetectorOptions& o) {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw Error("still detector option " + what);
  };
  require(std::isfinite(o.init_still_s) && o.init_still_s >= 0.0,
          "init_still_s = " + std::to_string(o.init_still_s) + " s must be >= 0 (0 = auto)");
  require(std::isfinite(o.window_s) && o.window_s > 0.0,
          "window_s = " + std::to_string(o.window_s) + " s must be > 0");
  require(o.false_alarm > 0.0 && o.false_alarm < 0.5,
          "false_alarm = " + std::to_string(o.false_alarm) + " must be in (0, 0.5)");
  require(std::isfinite(o.min_still_s) && o.min_still_s >= 0.0,
          "min_still_s = " + std::to_string(o.min_still_s) + " s must be >= 0");
  require(std::isfinite(o.edge_s) && o.edge_s >= 0.0,
          "edge_s = " + std::to_string(o.edge_s) + " s must be >= 0");
  require(!std::isnan(o.rate_allowance),
          "rate_allowance must be a number (negative = automatic)");
}

void CheckSeries(const ImuSeries& series) {
  const std::size_t n = series.size();
  if (n == 0) {
    throw InsufficientDataError("still detection: the series is empty; record the IMU still in "
                                "several orientations");
  }
  if (series.acc.size() != n || (series.has_gyro() && series.gyr.size() != n)) {
    throw Error("still detection: inconsistent series: " + std::to_string(n) + " times, " +
                std::to_string(series.acc.size()) + " accelerometer and " +
                std::to_string(series.gyr.size()) + " gyroscope samples");
  }
}

/// Pooled mean and within-run scatter of a triad over runs, from block moments.
struct Pooled {
  Vec3 sum = Vec3::Zero();      ///< sum of (sample - reference)
  Vec3 scatter = Vec3::Zero();  ///< sum over runs of squared deviations from the run's mean
};

/// Per-axis noise of a triad from pooled moments and the correlation time of its samples.
void FinishTriad(const ImuSeries& series, const std::vector<StillSegment>& spans,
                 signal::Sensor sensor, const Pooled& pooled, const Vec3& reference,
                 double samples, double dof, Vec3& mean, Vec3& sigma, Vec3& tau_int,
                 Vec3& tau_sq) {
  mean = reference + pooled.sum / samples;
  const double floor = 4.0 * kFloatEps * mean.cwiseAbs().maxCoeff();
  sigma = (pooled.scatter / dof).cwiseSqrt().cwiseMax(floor);
  const auto ct = signal::EstimateCorrelationTime(series, spans, sensor);
  for (std::size_t a = 0; a < 3; ++a) {
    tau_int[static_cast<int>(a)] = std::max(1.0, ct[a].tau_int);
    tau_sq[static_cast<int>(a)] = std::max(1.0, ct[a].tau_sq);
  }
}

/// Noise pooled over still runs (block-aligned; runs under 2 samples are skipped).
NoiseEstimate EstimateNoise(const ImuSeries& series, const BlockMoments& blocks,
                            const std::vector<Run>& runs, const std::string& source) {
  NoiseEstimate noise;
  noise.source = source;
  noise.has_gyro = blocks.has_gyro();
  Pooled acc;
  Pooled gyr;
  double dof = 0.0;
  std::size_t correlation_budget = kMaxCorrelationSamples;
  std::vector<StillSegment> correlation_spans;
  for (const Run& run : runs) {
    if (run.size() < 2) continue;
    StillSegment period;
    period.begin = run.begin;
    period.end = run.end;
    noise.periods.push_back(period);
    const auto n = static_cast<double>(run.size());
    noise.samples += run.size();
    dof += n - 1.0;
    const TriadMoments a = blocks.AccOver(run.begin, run.end);
    acc.sum += a.sum;
    acc.scatter += a.Scatter(n);
    if (noise.has_gyro) {
      const TriadMoments g = blocks.GyrOver(run.begin, run.end);
      gyr.sum += g.sum;
      gyr.scatter += g.Scatter(n);
    }
    if (correlation_budget >= 2) {
      period.end = std::min(run.end, run.begin + correlation_budget);
      correlation_budget -= period.count();
      correlation_spans.push_back(period);
    }
  }
  if (noise.periods.empty()) {
    throw InsufficientDataError("still detection: no still period of at least 2 samples to "
                                "estimate the noise from");
  }
  const auto samples = static_cast<double>(noise.samples);
  try {
    FinishTriad(series, correlation_spans, signal::Sensor::kAccel, acc, blocks.acc_reference(),
                samples, dof, noise.acc_mean, noise.acc_sigma, noise.acc_tau_int,
                noise.acc_tau_sq);
    if (noise.has_gyro) {
      FinishTriad(series, correlation_spans, signal::Sensor::kGyro, gyr,
                  blocks.gyr_reference(), samples, dof, noise.gyr_still_rate, noise.gyr_sigma,
                  noise.gyr_tau_int, noise.gyr_tau_sq);
    }
  } catch (const Error& e) {
    throw InsufficientDataError("still detection: the still period " +
                                TimeRange(series, runs.front()) +
                                " gives no usable noise estimate: " + e.what());
  }
  return noise;
}

/// Degrees of freedom of the mean of three chi^2(nu_a)/nu_a terms (Satterthwaite), with the
/// noise estimate's own uncertainty (nu_0 per axis) folded in.
double VarianceStatisticDof(double window, double period, const Vec3& tau_sq) {
  double inverse_sum = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double nu_window = (window - 1.0) / tau_sq[a];
    const double nu_period = (period - 1.0) / tau_sq[a];
    inverse_sum += 1.0 / nu_window + 1.0 / nu_period;
  }
  return 9.0 / inverse_sum;
}

/// Per-axis allowance for the still rate changing between poses.
Vec3 RateAllowance(const NoiseEstimate& noise, const StillDetectorOptions& options) {
  return options.rate_allowance < 0.0 ? noise.gyr_sigma : Vec3::Constant(options.rate_allowance);
}

/// 1 / V per axis: the variance of a mean over n samples about a still rate known from n0
/// samples, plus the allowance squared.
Vec3 RateWeight(const NoiseEstimate& noise, const Vec3& allowance, double n, double n0) {
  Vec3 weight;
  for (int a = 0; a < 3; ++a) {
    const double var = noise.gyr_sigma[a] * noise.gyr_sigma[a];
    weight[a] = 1.0 / (var * noise.gyr_tau_int[a] * (1.0 / n + 1.0 / n0) +
                       allowance[a] * allowance[a]);
  }
  return weight;
}

/// The window tests; `with_rate_test` false leaves out the mean-rate test (first pass).
WindowTests MakeTests(const NoiseEstimate& noise, const BlockMoments& blocks,
                      const StillDetectorOptions& options, Geometry geometry, double dt_s,
                      DetectionDetail& detail, bool with_rate_test = true) {
  WindowTests tests;
  tests.geometry = geometry;
  const auto n = static_cast<double>(geometry.window());
  const auto n0 = static_cast<double>(noise.samples);
  tests.inverse_n = 1.0 / n;
  tests.max_span_s = (n - 1.0) * dt_s + 0.5 * options.window_s;
  tests.gyro_variance = noise.has_gyro && options.gyro_variance_test;
  tests.rate = noise.has_gyro && with_rate_test;
  const double num_tests = 1.0 + (tests.rate ? 1.0 : 0.0) + (tests.gyro_variance ? 1.0 : 0.0);
  // Bonferroni over the tests and the window positions (one per block) in a window length.
  const double p =
      1.0 - options.false_alarm / (num_tests * static_cast<double>(geometry.blocks));

  tests.acc_weight =
      (3.0 * (n - 1.0) * noise.acc_sigma.cwiseProduct(noise.acc_sigma)).cwiseInverse();
  detail.acc_dof = VarianceStatisticDof(n, n0, noise.acc_tau_sq);
  tests.acc_threshold = signal::ChiSquareQuantile(p, detail.acc_dof) / detail.acc_dof;
  detail.acc_threshold = tests.acc_threshold;
  if (tests.gyro_variance) {
    tests.gyr_weight =
        (3.0 * (n - 1.0) * noise.gyr_sigma.cwiseProduct(noise.gyr_sigma)).cwiseInverse();
    detail.gyr_dof = VarianceStatisticDof(n, n0, noise.gyr_tau_sq);
    tests.gyr_threshold = signal::ChiSquareQuantile(p, detail.gyr_dof) / detail.gyr_dof;
    detail.gyr_threshold = tests.gyr_threshold;
  }
  if (tests.rate) {
    tests.rate_offset = n * (noise.gyr_still_rate - blocks.gyr_reference());
    detail.rate_allowance = RateAllowance(noise, options);
    tests.rate_weight = RateWeight(noise, detail.rate_allowance, n, n0) / (n * n);
    tests.rate_threshold = signal::ChiSquareQuantile(p, 3.0);
    detail.rate_threshold = tests.rate_threshold;
  }
  detail.window_samples = geometry.window();
  detail.block_samples = geometry.block;
  return tests;
}

/// One pass over the block sums: a window of `blocks` blocks is tested at every block; its
/// verdict applies to the centre block's samples (the first and last half windows, and a short
/// last block, take the verdict of the nearest window). Returns the maximal still runs.
Classification Classify(const ImuSeries& series, const BlockMoments& blocks,
                        const WindowTests& tests) {
  Classification out;
  const std::size_t b = tests.geometry.block;
  const std::size_t m = tests.geometry.blocks;
  const std::size_t k = m / 2;
  const std::size_t full = blocks.num_full_blocks();
  const bool gyro = tests.gyro_variance || tests.rate;
  TriadMoments acc;
  TriadMoments gyr;
  std::size_t nonfinite = 0;  // non-finite blocks in the window
  RunBuilder all_tests;
  RunBuilder acc_tests;
  for (std::size_t c = k; c + k < full; ++c) {
    const std::size_t first_block = c - k;
    if (first_block % kResyncInterval == 0) {
      acc = blocks.AccOver(first_block * b, (first_block + m) * b);
      if (gyro) gyr = blocks.GyrOver(first_block * b, (first_block + m) * b);
      nonfinite = blocks.NonfiniteOver(first_block * b, (first_block + m) * b);
    } else {
      acc += blocks.acc(c + k);
      acc -= blocks.acc(first_block - 1);
      if (gyro) {
        gyr += blocks.gyr(c + k);
        gyr -= blocks.gyr(first_block - 1);
      }
      nonfinite += static_cast<std::size_t>(blocks.nonfinite(c + k));
      nonfinite -= static_cast<std::size_t>(blocks.nonfinite(first_block - 1));
    }
    ++out.windows;
    const std::size_t first_sample = c == k ? 0 : c * b;
    if (nonfinite > 0) {
      ++out.failed_nonfinite;
      acc_tests.Mark(first_sample, false);
      all_tests.Mark(first_sample, false);
      continue;
    }
    bool still = true;
    if (series.t_s[(c + k + 1) * b - 1] - series.t_s[first_block * b] > tests.max_span_s) {
      ++out.failed_gap;
      still = false;
    }
    const Vec3 acc_scatter = acc.sum_sq - acc.sum.cwiseProduct(acc.sum) * tests.inverse_n;
    if (acc_scatter.dot(tests.acc_weight) > tests.acc_threshold) {
      ++out.failed_acc;
      still = false;
    }
    acc_tests.Mark(first_sample, still);
    if (tests.gyro_variance) {
      const Vec3 gyr_scatter = gyr.sum_sq - gyr.sum.cwiseProduct(gyr.sum) * tests.inverse_n;
      if (gyr_scatter.dot(tests.gyr_weight) > tests.gyr_threshold) {
        ++out.failed_gyr;
        still = false;
      }
    }
    if (tests.rate) {
      const Vec3 offset = gyr.sum - tests.rate_offset;  // n (window mean - still rate)
      if (offset.cwiseProduct(offset).dot(tests.rate_weight) > tests.rate_threshold) {
        ++out.failed_rate;
        still = false;
      }
    }
    all_tests.Mark(first_sample, still);
  }
  out.runs = all_tests.Finish(blocks.samples());
  out.acc_runs = acc_tests.Finish(blocks.samples());
  return out;
}

/// Mean and per-axis sample variance of a triad over samples [begin, end), in double.
struct SpanStats {
  Vec3 mean = Vec3::Zero();
  Vec3 variance = Vec3::Zero();
  double n = 0.0;
};

/// Mean and sample variance from a span's block moments (sums about `reference`): the runs
/// and gaps the detector produces start and end on block boundaries, so no sample is read
/// again.
SpanStats Stats(const TriadMoments& m, const Vec3& reference, std::size_t begin,
                std::size_t end) {
  SpanStats out;
  out.n = static_cast<double>(end - begin);
  if (end <= begin) return out;
  out.mean = reference + m.sum / out.n;
  if (out.n > 1.0) out.variance = m.Scatter(out.n) / (out.n - 1.0);
  return out;
}

SpanStats AccStats(const BlockMoments& blocks, std::size_t begin, std::size_t end) {
  return Stats(blocks.AccOver(begin, end), blocks.acc_reference(), begin, end);
}

SpanStats GyrStats(const BlockMoments& blocks, std::size_t begin, std::size_t end) {
  return Stats(blocks.GyrOver(begin, end), blocks.gyr_reference(), begin, end);
}

/// sum_axes (a - b)^2 / (var_a + var_b + allowance^2): chi^2(3) when a and b estimate the same
/// triad with those variances of the means.
double MeanDistance(const Vec3& a, const Vec3& var_a, const Vec3& b, const Vec3& var_b,
                    const Vec3& allowance) {
  const Vec3 d = a - b;
  return (d.cwiseProduct(d).array() /
          (var_a + var_b + allowance.cwiseProduct(allowance)).array())
      .sum();
}

/// Variance of the mean of a span: its own sample variance (the gap's vibration, or the
/// still noise for a still run) times tau_int / n.
Vec3 VarianceOfMean(const SpanStats& span, const Vec3& noise_sigma, const Vec3& tau_int,
                    bool own_variance) {
  const Vec3 var = own_variance ? span.variance.cwiseMax(noise_sigma.cwiseProduct(noise_sigma))
                                : Vec3(noise_sigma.cwiseProduct(noise_sigma));
  return var.cwiseProduct(tau_int) / std::max(span.n, 1.0);
}

/// The largest angle the gyroscope turns away from the start of samples [begin, end), rad:
/// max_k |sum_{i<k} (omega_i - still_rate) dt_i| (small-angle accumulation, enough to tell a
/// vibration, milliradians, from a turn and back, radians).
double MaxExcursion(const ImuSeries& series, std::size_t begin, std::size_t end,
                    const Vec3& still_rate) {
  Vec3 angle = Vec3::Zero();
  double largest = 0.0;
  for (std::size_t i = begin; i < end && i + 1 < series.size(); ++i) {
    angle += (series.gyr[i].cast<double>() - still_rate) * (series.t_s[i + 1] - series.t_s[i]);
    largest = std::max(largest, angle.norm());
  }
  return largest;
}

/// What a vibration of the gap's own scatter can turn by chance: five standard deviations of
/// its random walk over the gap, kept within [0.5, 3] degrees, rad. The upper bound matters:
/// a real turn has a large scatter too, and a still vehicle shaking does not turn 3 degrees.
double ExcursionLimit(const SpanStats& rate, const Vec3& tau_int, double dt_s) {
  const double walk =
      std::sqrt(rate.variance.cwiseProduct(tau_int).maxCoeff() * std::max(rate.n, 1.0)) * dt_s;
  constexpr double kDegree_rad = 3.14159265358979323846 / 180.0;
  return std::clamp(5.0 * walk, 0.5 * kDegree_rad, 3.0 * kDegree_rad);
}

/// Joins consecutive still runs whose samples in between show the same pose: a vehicle
/// standing still but vibrating (engine, wind, a hand on the airframe) fails the window
/// variance test in bursts and would otherwise be cut into several "poses" joined by
/// "motion" that holds no rotation — a problem the calibration cannot condition (issue 5:
/// plane408_centre_point.BIN, a 45 s still log, came out as 2 segments). Runs a and b with
/// the gap g between them are joined when, at the detector's chi^2(3) threshold on each:
///  - the accelerometer means of a and b agree (variance of each mean from the still noise,
///    plus the rate allowance's analogue: one per-sample noise sigma per axis);
///  - the gap's accelerometer mean agrees with theirs (the gap's own variance of its mean);
///  - the gap's mean rate is the still rate (the gap's own variance), and the angle the
///    gyroscope turns away from the first run's attitude anywhere in the gap stays within
///    what the gap's own scatter walks by chance (5 sigma, within 0.5-3 degrees): a turn, even
///    one back to the same attitude (its mean rate can be zero), fails. Without the gyroscope (none, or
///    use_gyro off) runs are never joined, and neither across a time gap (missing samples
///    over half a window).
/// A gap holding a pure translation and back also passes: its mean specific force is the
/// still one (the velocity change is zero), so the joined segment's mean is unbiased.
std::vector<Run> JoinSamePose(const ImuSeries& series, const BlockMoments& blocks,
                              const std::vector<Run>& runs,
                              const NoiseEstimate& noise, const StillDetectorOptions& options,
                              double dt_s, double max_gap_s, std::size_t& joined) {
  joined = 0;
  // Without the gyroscope a turn about the vertical keeps the accelerometer means: never join.
  const bool gyro = noise.has_gyro && blocks.has_gyro() && options.use_gyro;
  if (runs.size() < 2 || !options.join_same_pose || !gyro) return runs;
  const double threshold = signal::ChiSquareQuantile(1.0 - options.false_alarm, 3.0);
  std::vector<Run> out{runs.front()};
  SpanStats a = AccStats(blocks, runs.front().begin, runs.front().end);
  for (std::size_t k = 1; k < runs.size(); ++k) {
    const Run& next = runs[k];
    // A time gap (missing samples, over max_gap_s) between the runs is never joined.
    const double gap_s = series.t_s[next.begin] - series.t_s[out.back().end - 1];
    const double expected_s = static_cast<double>(next.begin - out.back().end + 1) * dt_s;
    if (gap_s > expected_s + max_gap_s) {
      out.push_back(next);
      a = AccStats(blocks, next.begin, next.end);
      continue;
    }
    // Runs and gaps lie on block boundaries; a gap holding a non-finite sample is not joined.
    const auto aligned = [&](std::size_t i) {
      return i % blocks.block() == 0 || i == blocks.samples();
    };
    if (!aligned(out.back().end) || !aligned(next.begin) || !aligned(next.end) ||
        blocks.NonfiniteOver(out.back().end, next.begin) > 0) {
      out.push_back(next);
      a = AccStats(blocks, next.begin, next.end);
      continue;
    }
    const SpanStats b = AccStats(blocks, next.begin, next.end);
    const SpanStats gap = AccStats(blocks, out.back().end, next.begin);
    const Vec3 var_a = VarianceOfMean(a, noise.acc_sigma, noise.acc_tau_int, false);
    const Vec3 var_b = VarianceOfMean(b, noise.acc_sigma, noise.acc_tau_int, false);
    const Vec3 var_gap = VarianceOfMean(gap, noise.acc_sigma, noise.acc_tau_int, true);
    bool same = gap.n > 0.0 &&
                MeanDistance(a.mean, var_a, b.mean, var_b, noise.acc_sigma) <= threshold &&
                MeanDistance(gap.mean, var_gap, 0.5 * (a.mean + b.mean), 0.25 * (var_a + var_b),
                             noise.acc_sigma) <= threshold;
    if (same) {
      const SpanStats rate = GyrStats(blocks, out.back().end, next.begin);
      const Vec3 var_rate = VarianceOfMean(rate, noise.gyr_sigma, noise.gyr_tau_int, true);
      same = MeanDistance(rate.mean, var_rate, noise.gyr_still_rate, Vec3::Zero(),
                          RateAllowance(noise, options)) <= threshold &&
             MaxExcursion(series, out.back().end, next.begin, noise.gyr_still_rate) <=
                 ExcursionLimit(rate, noise.gyr_tau_int, dt_s);
    }
    if (same) {
      out.back().end = next.end;
      a = AccStats(blocks, out.back().begin, out.back().end);
      ++joined;
    } else {
      out.push_back(next);
      a = b;
    }
  }
  return out;
}

/// Trims edge_s from both ends of a run; returns an empty run when nothing is left.
Run Trim(const ImuSeries& series, Run run, double edge_s) {
  const auto first = series.t_s.begin() + static_cast<std::ptrdiff_t>(run.begin);
  const auto last = series.t_s.begin() + static_cast<std::ptrdiff_t>(run.end);
  const auto begin_it = std::lower_bound(first, last, series.t_s[run.begin] + edge_s);
  const auto end_it = std::upper_bound(begin_it, last, series.t_s[run.end - 1] - edge_s);
  const Run trimmed{static_cast<std::size_t>(begin_it - series.t_s.begin()),
                    static_cast<std::size_t>(end_it - series.t_s.begin())};
  return trimmed.end > trimmed.begin ? trimmed : Run{run.begin, run.begin};
}

/// The stretch of `length` blocks minimising the product of the per-axis variances of the
/// tested triads (equivalently the sum of their logarithms): scale-free across axes and
/// sensors; stretches holding a non-finite sample are skipped. O(blocks) with running sums.
Run QuietestStretch(const BlockMoments& blocks, std::size_t length) {
  const std::size_t b = blocks.block();
  const double n = static_cast<double>(length * b);
  const bool gyro = blocks.has_gyro();
  const double floor = 1e-300;
  TriadMoments acc;
  TriadMoments gyr;
  std::size_t nonfinite = 0;
  Run best{0, length * b};
  double best_cost = std::numeric_limits<double>::infinity();
  for (std::size_t s = 0; s + length <= blocks.num_full_blocks(); ++s) {
    if (s % kResyncInterval == 0) {
      acc = blocks.AccOver(s * b, (s + length) * b);
      if (gyro) gyr = blocks.GyrOver(s * b, (s + length) * b);
      nonfinite = blocks.NonfiniteOver(s * b, (s + length) * b);
    } else {
      acc += blocks.acc(s + length - 1);
      acc -= blocks.acc(s - 1);
      if (gyro) {
        gyr += blocks.gyr(s + length - 1);
        gyr -= blocks.gyr(s - 1);
      }
      nonfinite += static_cast<std::size_t>(blocks.nonfinite(s + length - 1));
      nonfinite -= static_cast<std::size_t>(blocks.nonfinite(s - 1));
    }
    if (nonfinite > 0) continue;
    double cost = acc.Scatter(n).cwiseMax(floor).prod();
    if (gyro) cost *= gyr.Scatter(n).cwiseMax(floor).prod();
    if (cost < best_cost) {
      best_cost = cost;
      best = Run{s * b, (s + length) * b};
    }
  }
  return best;
}

/// Median of values with weights (the smallest value with half the weight at or below it).
double WeightedMedian(std::vector<std::pair<double, double>> value_weight) {
  std::sort(value_weight.begin(), value_weight.end());
  double total = 0.0;
  for (const auto& vw : value_weight) total += vw.second;
  double cumulative = 0.0;
  for (const auto& vw : value_weight) {
    cumulative += vw.second;
    if (cumulative >= 0.5 * total) return vw.first;
  }
  return value_weight.back().first;
}

/// The runs whose mean gyroscope output agrees, by the mean-rate test, with the
/// length-weighted median of all runs' means: a slow steady turn is as quiet as a still pose,
/// so the first pass's runs are screened by their rate before the noise is pooled over them.
std::vector<Run> RunsAtTheStillRate(const BlockMoments& blocks, const std::vector<Run>& runs,
                                    const NoiseEstimate& seed,
                                    const StillDetectorOptions& options) {
  std::vector<Vec3> means;
  std::array<std::vector<std::pair<double, double>>, 3> per_axis;
  for (const Run& run : runs) {
    const auto n = static_cast<double>(run.size());
    means.push_back(blocks.gyr_reference() + blocks.GyrOver(run.begin, run.end).sum / n);
    for (std::size_t a = 0; a < 3; ++a) {
      per_axis[a].emplace_back(means.back()[static_cast<int>(a)], n);
    }
  }
  Vec3 median;
  for (std::size_t a = 0; a < 3; ++a) median[static_cast<int>(a)] = WeightedMedian(per_axis[a]);
  const Vec3 allowance = RateAllowance(seed, options);
  const double threshold = signal::ChiSquareQuantile(1.0 - options.false_alarm, 3.0);
  std::vector<Run> kept;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const auto n = static_cast<double>(runs[r].size());
    const Vec3 weight = RateWeight(seed, allowance, n, static_cast<double>(seed.samples));
    const Vec3 offset = means[r] - median;
    if (offset.cwiseProduct(offset).dot(weight) <= threshold) kept.push_back(runs[r]);
  }
  return kept.empty() ? runs : kept;
}

/// Whether any segment overlaps the run.
bool Overlaps(const std::vector<StillSegment>& segments, Run run) {
  for (const StillSegment& segment : segments) {
    if (segment.begin < run.end && run.begin < segment.end) return true;
  }
  return false;
}

/// Noise from the first init_still_s seconds, rounded down to whole blocks.
NoiseEstimate InitialNoise(const ImuSeries& series, const BlockMoments& blocks,
                           const StillDetectorOptions& options, Geometry geometry,
                           SegmentationReport& report) {
  const double t_end = series.t_s.front() + options.init_still_s;
  const auto end = static_cast<std::size_t>(
      std::lower_bound(series.t_s.begin(), series.t_s.end(), t_end) - series.t_s.begin());
  const Run period{0, end / geometry.block * geometry.block};
  if (period.size() < geometry.window()) {
    throw InsufficientDataError(
        "still detection: the initial still period of " + Format("%.3g", options.init_still_s) +
        " s holds " + std::to_string(end) + " samples, fewer than one " +
        std::to_string(geometry.window()) + "-sample window");
  }
  if (blocks.NonfiniteOver(period.begin, period.end) > 0) {
    throw InsufficientDataError("still detection: the initial still period " +
                                TimeRange(series, period) +
                                " holds NaN or infinite samples; no noise estimate from it");
  }
  report.notes.push_back("noise from the initial still period " + TimeRange(series, period) +
                         " (init_still_s, " + std::to_string(period.size()) + " samples)");
  return EstimateNoise(series, blocks, {period}, "initial");
}

/// Noise pooled over the still runs of a first pass seeded by the quietest stretch.
NoiseEstimate AutomaticNoise(const ImuSeries& series, const BlockMoments& blocks,
                             const StillDetectorOptions& options, Geometry geometry,
                             double dt_s, SegmentationReport& report) {
  const auto min_still_blocks = static_cast<std::size_t>(
      std::ceil(options.min_still_s / (dt_s * static_cast<double>(geometry.block))));
  const std::size_t length = std::min(blocks.num_full_blocks(),
                                      std::max(2 * geometry.blocks, min_still_blocks));
  const Run stretch = QuietestStretch(blocks, length);
  const NoiseEstimate seed = EstimateNoise(series, blocks, {stretch}, "auto");

  StillDetectorOptions strict = options;
  strict.false_alarm = std::min(options.false_alarm, kProvisionalFalseAlarm);
  DetectionDetail unused;
  const WindowTests first_pass =
      MakeTests(seed, blocks, strict, geometry, dt_s, unused, /*with_rate_test=*/false);
  std::vector<Run> runs;
  for (const Run& run : Classify(series, blocks, first_pass).runs) {
    if (run.size() >= geometry.window()) runs.push_back(run);
  }
  if (runs.empty()) runs.push_back(stretch);
  const std::size_t first_pass_runs = runs.size();
  if (blocks.has_gyro()) runs = RunsAtTheStillRate(blocks, runs, seed, options);
  NoiseEstimate noise = EstimateNoise(series, blocks, runs, "auto");

  std::string note = "noise pooled over " + std::to_string(runs.size()) + " still runs (" +
                     Format("%.1f", static_cast<double>(noise.samples) * dt_s) +
                     " s) found by a first pass seeded by the quietest " +
                     Format("%.3g", static_cast<double>(stretch.size()) * dt_s) + " s stretch " +
                     TimeRange(series, stretch) + " (init_still_s = 0: automatic)";
  if (runs.size() < first_pass_runs) {
    note += "; " + std::to_string(first_pass_runs - runs.size()) +
            " first-pass runs left out for a mean rate away from the median of all runs "
            "(turning slowly)";
  }
  report.notes.push_back(note);
  return noise;
}

std::string NoiseNote(const NoiseEstimate& noise, const StillDetectorOptions& options) {
  std::string note = "accel noise sigma " + FormatVec(noise.acc_sigma) + " " + options.acc_unit +
                     ", tau_int " + FormatVec(noise.acc_tau_int, "%.2f") + " samples";
  if (noise.has_gyro) {
    note += "; gyro noise sigma " + FormatVec(noise.gyr_sigma) + " " + options.gyr_unit +
            ", tau_int " + FormatVec(noise.gyr_tau_int, "%.2f") + " samples, still rate " +
            FormatVec(noise.gyr_still_rate, "%.6g") + " " + options.gyr_unit;
  }
  return note;
}

std::string ThresholdNote(const DetectionDetail& d, const StillDetectorOptions& options,
                          double dt_s) {
  std::string note =
      "window " + Format("%.3g", static_cast<double>(d.window_samples) * dt_s) + " s (" +
      std::to_string(d.window_samples) + " samples at dt " + Format("%.4g", dt_s) +
      " s, tested every " + std::to_string(d.block_samples) + " samples); false alarm " +
      Format("%.3g", options.false_alarm) +
      " per window length; thresholds: accel variance ratio " + Format("%.3f", d.acc_threshold) +
      " (chi^2 dof " + Format("%.0f", d.acc_dof) + ")";
  if (d.gyr_threshold > 0.0) {
    note += ", gyro variance ratio " + Format("%.3f", d.gyr_threshold) + " (chi^2 dof " +
            Format("%.0f", d.gyr_dof) + ")";
  }
  if (d.rate_threshold > 0.0) {
    note += ", gyro mean rate chi^2(3) " + Format("%.2f", d.rate_threshold) +
            " with allowance " + FormatVec(d.rate_allowance) + " " + options.gyr_unit;
  }
  return note;
}

std::string FailureNote(const Classification& found, const WindowTests& tests) {
  std::string note = "of " + std::to_string(found.windows) + " window positions, " +
                     std::to_string(found.failed_acc) + " fail the accel variance test";
  if (tests.gyro_variance) {
    note += ", " + std::to_string(found.failed_gyr) + " the gyro variance test";
  }
  if (tests.rate) note += ", " + std::to_string(found.failed_rate) + " the gyro mean-rate test";
  note += ", " + std::to_string(found.failed_gap) + " span a time gap";
  if (found.failed_nonfinite > 0) {
    note += ", " + std::to_string(found.failed_nonfinite) + " hold a NaN or infinite sample";
  }
  return note;
}

/// Lists the accelerometer-still runs, long enough, that no kept segment overlaps.
void NoteGyroRejections(const ImuSeries& series, const Classification& found,
                        const StillDetectorOptions& options, double dt_s,
                        SegmentationResult& result) {
  std::string listed;
  std::size_t& count = result.detail.rejected_by_gyro;
  for (const Run& run : found.acc_runs) {
    const Run trimmed = Trim(series, run, options.edge_s);
    const double length_s = static_cast<double>(trimmed.size()) * dt_s;
    if (trimmed.size() == 0 || length_s < options.min_still_s ||
        Overlaps(result.segments, run)) {
      continue;
    }
    if (++count <= kListedRuns) listed += (listed.empty() ? "" : ", ") + TimeRange(series, trimmed);
  }
  if (count > 0) {
    result.report.notes.push_back(
        std::to_string(count) +
        " accelerometer-still runs rejected only by the gyroscope tests (rotation jitter or a "
        "drifting rate; gyro_variance_test = false or use_gyro = false would keep them): " +
        listed + (count > kListedRuns ? ", ..." : ""));
  }
}

/// Warns when the stated initial still period is not still throughout.
void NoteInitialCoverage(const Classification& found, const NoiseEstimate& noise,
                         SegmentationReport& report) {
  std::size_t covered = 0;
  for (const Run& run : found.runs) {
    const std::size_t hi = std::min(run.end, noise.samples);
    if (hi > run.begin) covered += hi - run.begin;
  }
  if (covered < noise.samples) {
    report.notes.push_back("warning: the initial still period is not still throughout: " +
                           std::to_string(noise.samples - covered) + " of its " +
                           std::to_string(noise.samples) +
                           " samples fail a test; check init_still_s");
  }
}

}  // namespace

SegmentationResult DetectStillSegments(const ImuSeries& series,
                                       const StillDetectorOptions& options) {
  CheckOptions(options);
  CheckSeries(series);
  const double dt_s = series.median_dt_s();
  if (!(dt_s > 0.0)) {
    throw InsufficientDataError("still detection: the series has " +
                                std::to_string(series.size()) +
                                " samples without a positive sample interval");
  }
  const Geometry geometry = MakeGeometry(options.window_s, dt_s);
  if (series.size() < geometry.window()) {
    throw InsufficientDataError(
        "still detection: the series has " + std::to_string(series.size()) + " samples (" +
        Format("%.3g", series.duration_s()) + " s), fewer than one " +
        std::to_string(geometry.window()) + "-sample window of " +
        Format("%.3g", options.window_s) + " s; record longer still periods");
  }
  const bool use_gyro = options.use_gyro && series.has_gyro();
  const BlockMoments blocks(series, geometry.block, use_gyro);

  SegmentationResult result;
  SegmentationReport& report = result.report;
  report.method = "detected";
  report.window_s = static_cast<double>(geometry.window()) * dt_s;
  report.min_still_s = options.min_still_s;

  // 1. Noise of a still period.
  result.noise = options.init_still_s > 0.0
                     ? InitialNoise(series, blocks, options, geometry, report)
                     : AutomaticNoise(series, blocks, options, geometry, dt_s, report);
  const NoiseEstimate& noise = result.noise;
  report.init_still_s = static_cast<double>(noise.samples) * dt_s;
  report.notes.push_back(NoiseNote(noise, options));
  if (!use_gyro) {
    report.notes.push_back(series.has_gyro()
                               ? "gyroscope not tested (use_gyro off)"
                               : "no gyroscope: accelerometer test only; a slow turn about the "
                                 "vertical cannot be seen");
  }

  // 2. The window tests over the whole series.
  DetectionDetail& detail = result.detail;
  const WindowTests tests = MakeTests(noise, blocks, options, geometry, dt_s, detail);
  const Classification found = Classify(series, blocks, tests);
  report.threshold = detail.acc_threshold;
  detail.windows = found.windows;
  detail.failed_acc = found.failed_acc;
  detail.failed_gyr = found.failed_gyr;
  detail.failed_rate = found.failed_rate;
  detail.failed_gap = found.failed_gap;
  detail.failed_nonfinite = found.failed_nonfinite;
  detail.still_runs = found.runs.size();
  report.notes.push_back(ThresholdNote(detail, options, dt_s));
  report.notes.push_back(FailureNote(found, tests));
  if (blocks.nonfinite_samples() > 0) {
    report.notes.push_back(std::to_string(blocks.nonfinite_samples()) +
                           " samples hold NaN or infinite values; no window over them is "
                           "called still");
  }

  // 3. Still runs: runs showing the same pose joined, trimmed, then kept when long enough.
  std::size_t joined = 0;
  const std::vector<Run> runs = JoinSamePose(series, blocks, found.runs, noise, options, dt_s, 0.5 * options.window_s, joined);
  if (joined > 0) {
    report.notes.push_back(
        "joined " + std::to_string(joined) + " pairs of still runs: the samples between them "
        "vibrate but hold the same pose (accelerometer means agree, no rotation)");
  }
  double still_s = 0.0;
  for (const Run& run : runs) {
    const Run trimmed = Trim(series, run, options.edge_s);
    const double length_s = static_cast<double>(trimmed.size()) * dt_s;
    if (trimmed.size() == 0 || length_s < options.min_still_s) {
      ++report.rejected_short;
      continue;
    }
    StillSegment segment;
    segment.begin = trimmed.begin;
    segment.end = trimmed.end;
    segment.label = "still #" + std::to_string(result.segments.size() + 1);
    result.segments.push_back(std::move(segment));
    still_s += length_s;
  }
  report.notes.push_back(
      "found " + std::to_string(result.segments.size()) + " still segments totalling " +
      Format("%.1f", still_s) + " s of " + Format("%.1f", series.duration_s() + dt_s) + " s; " +
      std::to_string(report.rejected_short) + " still runs shorter than " +
      Format("%.3g", options.min_still_s) + " s after trimming " + Format("%.3g", options.edge_s) +
      " s at each end dropped");
  if (use_gyro) NoteGyroRejections(series, found, options, dt_s, result);
  if (options.init_still_s > 0.0) NoteInitialCoverage(found, noise, report);
  return result;
}

}  // namespace plumb::segmentation
