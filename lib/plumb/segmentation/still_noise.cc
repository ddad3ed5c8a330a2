// plumb/segmentation/still_noise.cc — the noise statistics of the still detector
// (still_detector.h, step 1, and the thresholds of step 2): the noise of a still period, from
// the initial still period or pooled over a first pass seeded by the quietest stretch (its
// runs screened by their mean rate), and the window tests' weights and chi^2 thresholds
// derived from it.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "plumb/core/error.h"
#include "plumb/segmentation/still_detector_internal.h"
#include "plumb/signal/axis_view.h"
#include "plumb/signal/chi_square.h"
#include "plumb/signal/correlation_time.h"

namespace plumb::segmentation::detail {
namespace {

/// float resolution: noise standard deviations are floored at 4 eps |mean|, what a float
/// sample of that size resolves, so that a perfectly constant axis does not divide by zero.
constexpr double kFloatEps = 1.1920929e-7;
/// At most this many samples of the still periods feed the correlation-time estimate (its cost
/// is O(samples x lags)); 131072 samples pin tau_int to a few percent.
constexpr std::size_t kMaxCorrelationSamples = 131072;
/// False-alarm level of the automatic mode's first pass: strict, because its noise comes from
/// the quietest stretch, biased low.
constexpr double kProvisionalFalseAlarm = 1e-6;

/// Pooled mean and within-run scatter of a triad over runs, from block moments.
struct Pooled {
  Vec3 sum = Vec3::Zero();      ///< sum of (sample - reference)
  Vec3 scatter = Vec3::Zero();  ///< sum over runs of squared deviations from the run's mean
};

/// The output's resolution on each axis of `sensor`: the smallest nonzero step between
/// consecutive samples of the whole series, 0 where the axis never changes (one pass over the
/// triads).
Vec3 QuantisationSteps(const ImuSeries& series, signal::Sensor sensor) {
  const std::vector<Vec3f>& x = sensor == signal::Sensor::kAccel ? series.acc : series.gyr;
  Vec3 step = Vec3::Zero();
  for (std::size_t i = 1; i < x.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      const double d = std::abs(static_cast<double>(x[i][a]) - static_cast<double>(x[i - 1][a]));
      if (d > 0.0 && (step[a] == 0.0 || d < step[a])) step[a] = d;
    }
  }
  return step;
}

/// Per-axis noise of a triad from pooled moments and the correlation time of its samples.
/// A quantised output (a low-rate telemetry stream in steps of 1 mG and 1 mrad/s) may read one
/// constant value through every still period: its scatter is then no measure of the noise,
/// which is below the step, and the noise is floored at the quantisation noise of the step q,
/// q / sqrt(12) (uniform rounding error); such an axis has no correlation to measure (white).
void FinishTriad(const ImuSeries& series, const std::vector<StillSegment>& spans,
                 signal::Sensor sensor, const Pooled& pooled, const Vec3& reference,
                 double samples, double dof, Vec3& mean, Vec3& sigma, Vec3& tau_int,
                 Vec3& tau_sq) {
  mean = reference + pooled.sum / samples;
  const double floor = 4.0 * kFloatEps * mean.cwiseAbs().maxCoeff();
  sigma = (pooled.scatter / dof).cwiseSqrt().cwiseMax(floor);
  const Vec3 steps = QuantisationSteps(series, sensor);
  for (int a = 0; a < 3; ++a) {
    sigma[a] = std::max(sigma[a], steps[a] / std::sqrt(12.0));
    std::vector<signal::AxisView> chunks;
    for (const StillSegment& span : spans) {
      chunks.push_back(signal::ViewAxis(series, sensor, a, span.begin, span.end));
    }
    const bool constant = std::all_of(chunks.begin(), chunks.end(), [](const signal::AxisView& c) {
      return c.size() == 0 || (c.array() == c[0]).all();
    });
    if (constant) {
      tau_int[a] = tau_sq[a] = 1.0;
      continue;
    }
    const signal::CorrelationTime ct = signal::EstimateCorrelationTime(chunks, {});
    tau_int[a] = std::max(1.0, ct.tau_int);
    tau_sq[a] = std::max(1.0, ct.tau_sq);
  }
}

/// Noise pooled over still runs (block-aligned; runs under 2 samples are skipped).
NoiseEstimate EstimateNoise(const ImuSeries& series, const BlockMoments& blocks,
                            const std::vector<Run>& runs, const std::string& source) {
  NoiseEstimate noise;
  noise.source = source;
  noise.acc_unit = series.acc_unit;
  noise.gyr_unit = series.gyr_unit;
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
  const double threshold = signal::ChiSquareQuantileExact(1.0 - options.false_alarm, 3.0);
  std::vector<Run> kept;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const auto n = static_cast<double>(runs[r].size());
    const Vec3 weight = RateWeight(seed, allowance, n, static_cast<double>(seed.samples));
    const Vec3 offset = means[r] - median;
    if (offset.cwiseProduct(offset).dot(weight) <= threshold) kept.push_back(runs[r]);
  }
  return kept.empty() ? runs : kept;
}

}  // namespace

/// Per-axis allowance for the still rate changing between poses.
Vec3 RateAllowance(const NoiseEstimate& noise, const StillDetectorOptions& options) {
  return options.rate_allowance < 0.0 ? noise.gyr_sigma : Vec3::Constant(options.rate_allowance);
}

/// The window tests; `with_rate_test` false leaves out the mean-rate test (first pass).
WindowTests MakeTests(const NoiseEstimate& noise, const BlockMoments& blocks,
                      const StillDetectorOptions& options, Geometry geometry,
                      DetectionDetail& detail, bool with_rate_test) {
  WindowTests tests;
  tests.geometry = geometry;
  const auto n = static_cast<double>(geometry.window());
  const auto n0 = static_cast<double>(noise.samples);
  tests.inverse_n = 1.0 / n;
  tests.max_gap_s = 0.5 * options.window_s;
  tests.gyro_variance = noise.has_gyro && options.gyro_variance_test;
  tests.rate = noise.has_gyro && with_rate_test;
  const double num_tests = 1.0 + (tests.rate ? 1.0 : 0.0) + (tests.gyro_variance ? 1.0 : 0.0);
  // Bonferroni over the tests and the window positions (one per block) in a window length.
  const double p =
      1.0 - options.false_alarm / (num_tests * static_cast<double>(geometry.blocks));

  tests.acc_weight =
      (3.0 * (n - 1.0) * noise.acc_sigma.cwiseProduct(noise.acc_sigma)).cwiseInverse();
  detail.acc_dof = VarianceStatisticDof(n, n0, noise.acc_tau_sq);
  tests.acc_threshold = signal::ChiSquareQuantileExact(p, detail.acc_dof) / detail.acc_dof;
  detail.acc_threshold = tests.acc_threshold;
  if (tests.gyro_variance) {
    tests.gyr_weight =
        (3.0 * (n - 1.0) * noise.gyr_sigma.cwiseProduct(noise.gyr_sigma)).cwiseInverse();
    detail.gyr_dof = VarianceStatisticDof(n, n0, noise.gyr_tau_sq);
    tests.gyr_threshold = signal::ChiSquareQuantileExact(p, detail.gyr_dof) / detail.gyr_dof;
    detail.gyr_threshold = tests.gyr_threshold;
  }
  if (tests.rate) {
    tests.rate_offset = n * (noise.gyr_still_rate - blocks.gyr_reference());
    detail.rate_allowance = RateAllowance(noise, options);
    tests.rate_weight = RateWeight(noise, detail.rate_allowance, n, n0) / (n * n);
    tests.rate_threshold = signal::ChiSquareQuantileExact(p, 3.0);
    detail.rate_threshold = tests.rate_threshold;
  }
  detail.window_samples = geometry.window();
  detail.block_samples = geometry.block;
  return tests;
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
        "still detection: the initial still period of " + FormattedText("%.3g", options.init_still_s) +
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
      MakeTests(seed, blocks, strict, geometry, unused, /*with_rate_test=*/false);
  std::vector<Run> runs;
  for (const Run& run : Classify(series, blocks, first_pass).runs) {
    if (run.size() >= geometry.window()) runs.push_back(run);
  }
  if (runs.empty()) runs.push_back(stretch);
  const std::size_t first_pass_runs = runs.size();
  if (blocks.has_gyro()) runs = RunsAtTheStillRate(blocks, runs, seed, options);
  NoiseEstimate noise = EstimateNoise(series, blocks, runs, "auto");

  std::string note = "noise pooled over " + std::to_string(runs.size()) + " still runs (" +
                     FormattedText("%.1f", static_cast<double>(noise.samples) * dt_s) +
                     " s) found by a first pass seeded by the quietest " +
                     FormattedText("%.3g", static_cast<double>(stretch.size()) * dt_s) + " s stretch " +
                     TimeRange(series, stretch) + " (init_still_s = 0: automatic)";
  if (runs.size() < first_pass_runs) {
    note += "; " + std::to_string(first_pass_runs - runs.size()) +
            " first-pass runs left out for a mean rate away from the median of all runs "
            "(turning slowly)";
  }
  report.notes.push_back(note);
  return noise;
}

}  // namespace plumb::segmentation::detail
